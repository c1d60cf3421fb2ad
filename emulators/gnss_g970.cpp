#include "emulators/gnss_g970.h"

#include <cmath>

#include "idl/topics.h"

namespace rig::emulators {

namespace {

bool inside(const std::vector<GnssEpisode>& episodes, double t_s, const GnssEpisode** which = nullptr) {
    for (const GnssEpisode& episode : episodes) {
        if (t_s >= episode.at_s && t_s < episode.at_s + episode.for_s) {
            if (which != nullptr) *which = &episode;
            return true;
        }
    }
    return false;
}

}  // namespace

int gga_quality(GnssFixKind kind) {
    switch (kind) {
        case GnssFixKind::rtk_fixed: return 4;
        case GnssFixKind::rtk_float: return 5;
        case GnssFixKind::dgps: return 2;
        case GnssFixKind::autonomous: return 1;
    }
    return 0;
}

GnssG970::GnssG970(const Plant& plant, G970Params params)
    : plant_(plant), params_(std::move(params)), noise_(params_.seed, "gnss_g970"),
      wire_faults_(params_.wire_faults, params_.seed) {}

void GnssG970::configure(DdsContext& dds) {
    nmea_writer_ = std::make_unique<Writer<msg::NmeaSentence>>(dds, topics::kGnssNmea);
}

TimeNs GnssG970::epoch_period_ns() const { return seconds_to_ns(1.0 / params_.rate_hz); }

std::optional<nmea::GnssFix> GnssG970::solve_epoch(TimeNs epoch_ns) {
    const double epoch_s = ns_to_seconds(epoch_ns);
    // Draw the noise for every epoch, even in a dropout, so a fault in one place
    // does not shift the random sequence of every later epoch.
    const double east_noise = noise_.gaussian();
    const double north_noise = noise_.gaussian();
    if (inside(params_.dropouts, epoch_s)) return std::nullopt;

    GnssFixKind kind = params_.fix;
    // 1-sigma per horizontal axis: base + ppm x baseline (RTK 8 mm + 1 ppm).
    double sigma_m = params_.noise_base_m + params_.noise_ppm * 1e-6 * params_.baseline_km * 1000.0;
    const GnssEpisode* episode = nullptr;
    if (inside(params_.degraded, epoch_s, &episode)) {
        kind = episode->fix;
        sigma_m = episode->sigma_m;
    }

    const msg::VehicleTruth truth = plant_.truth_at(epoch_ns);
    const double heading_rad = truth.heading_deg() * M_PI / 180.0;
    // Noise is isotropic in east/north; the field frame works along/cross the line.
    const double east_m = east_noise * sigma_m;
    const double north_m = north_noise * sigma_m;
    const double along_noise_m = east_m * std::sin(heading_rad) + north_m * std::cos(heading_rad);
    const double cross_noise_m = east_m * std::cos(heading_rad) - north_m * std::sin(heading_rad);
    const GeoPoint position =
        plant_.field().to_geodetic(truth.along_m() + along_noise_m, truth.cross_m() + cross_noise_m);

    nmea::GnssFix fix{};
    const double utc = params_.utc_start_seconds_of_day + epoch_s;
    const int day_offset = static_cast<int>(std::floor(utc / 86400.0));
    fix.year = params_.utc_year;
    fix.month = params_.utc_month;
    fix.day = params_.utc_day + day_offset;  // cases are minutes long; no month rollover handled
    fix.utc_seconds_of_day = utc - 86400.0 * day_offset;
    fix.lat_deg = position.lat_deg;
    fix.lon_deg = position.lon_deg;
    fix.altitude_msl_m = position.height_m;
    fix.geoid_separation_m = 0.0;
    fix.fix_quality = gga_quality(kind);
    fix.satellites = kind == GnssFixKind::rtk_fixed ? 18 : 12;
    fix.hdop = kind == GnssFixKind::rtk_fixed ? 0.7 : 1.4;
    fix.speed_m_s = truth.speed_m_s();
    fix.course_deg = truth.heading_deg();
    fix.differential_age_s = kind == GnssFixKind::autonomous ? 0.0 : 1.0;
    fix.station_id = kind == GnssFixKind::autonomous ? 0 : 1;
    return fix;
}

TimeNs GnssG970::step(TimeNs now_ns) {
    const TimeNs period = epoch_period_ns();
    const TimeNs phase = seconds_to_ns(params_.epoch_phase_s);
    const TimeNs latency = seconds_to_ns(params_.latency_s);
    // Emit every epoch whose sentences are due on the wire by now.
    while (phase + next_epoch_index_ * period + latency <= now_ns) {
        const TimeNs epoch_ns = phase + next_epoch_index_ * period;
        ++next_epoch_index_;
        if (auto fix = solve_epoch(epoch_ns)) {
            for (const std::string& sentence :
                 {nmea::encode_gga(params_.talker, *fix), nmea::encode_rmc(params_.talker, *fix)}) {
                // The fix is solved and encoded as ever; only the bytes that
                // leave the receiver are damaged (nothing at all: not sent).
                const std::string bytes = wire_faults_.apply(sentence);
                if (bytes.empty()) continue;
                msg::NmeaSentence wire;
                wire.sentence(bytes);
                nmea_writer_->publish(wire);
            }
        }
    }
    return phase + next_epoch_index_ * period + latency;
}

}  // namespace rig::emulators
