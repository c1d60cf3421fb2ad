#include "emulators/ad300_receiver.h"

#include <cctype>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "emulators/param_check.h"

namespace rig::emulators {

Ad300Receiver::Ad300Receiver(const field2d::SprayerKinematics& kinematics, Ad300Params params)
    : kinematics_(kinematics), params_(std::move(params)), noise_(params_.seed, "ad300.noise") {
    if (params_.talker.size() != 2 || !std::isupper(static_cast<unsigned char>(params_.talker[0])) ||
        !std::isupper(static_cast<unsigned char>(params_.talker[1]))) {
        throw std::invalid_argument("ad300.talker: must be two upper-case letters, got '" + params_.talker + "'");
    }
    if (!std::isfinite(params_.rate_hz) || params_.rate_hz <= 0.0 || params_.rate_hz > 100.0) {
        throw std::invalid_argument("ad300.rate_hz: must be in (0, 100], got " + std::to_string(params_.rate_hz));
    }
    const double period_s = 1.0 / params_.rate_hz;
    check_range("ad300", "latency_s", params_.latency_s, 0.0, 1.0);
    check_range("ad300", "noise_base_m", params_.noise_base_m, 0.0, 100.0);
    check_range("ad300", "noise_ppm", params_.noise_ppm, 0.0, 1000.0);
    check_range("ad300", "baseline_km", params_.baseline_km, 0.0, 1000.0);
    check_range("ad300", "velocity_noise_m_s", params_.velocity_noise_m_s, 0.0, 10.0);
    check_range("ad300", "min_course_speed_m_s", params_.min_course_speed_m_s, 0.0, 10.0);
    check_range("ad300", "utc_start_seconds_of_day", params_.utc_start_seconds_of_day, 0.0, 86400.0, true);
    if (params_.utc_month < 1 || params_.utc_month > 12 || params_.utc_day < 1 || params_.utc_day > 28) {
        throw std::invalid_argument("ad300.utc_month/utc_day: month 1-12 and day 1-28 (runs do not cross a month)");
    }
    if (params_.epoch_phase_s) {
        check_range("ad300", "epoch_phase_s", *params_.epoch_phase_s, 0.0, period_s, true);
        phase_s_ = *params_.epoch_phase_s;
    } else {
        SeededRandom phase_draw(params_.seed, "ad300.epoch_phase");
        phase_s_ = phase_draw.uniform01() * period_s;
    }
    period_ns_ = seconds_to_ns(period_s);
    phase_ns_ = seconds_to_ns(phase_s_);
    latency_ns_ = seconds_to_ns(params_.latency_s);
}

TimeNs Ad300Receiver::epoch_ns(std::int64_t k) const { return phase_ns_ + k * period_ns_; }

TimeNs Ad300Receiver::next_due_ns() const { return epoch_ns(next_epoch_) + latency_ns_; }

nmea::GnssFix Ad300Receiver::solve_epoch(TimeNs epoch_ns) {
    // Four draws per epoch, always in this order.
    const double east_noise = noise_.gaussian();
    const double north_noise = noise_.gaussian();
    const double ve_noise = noise_.gaussian();
    const double vn_noise = noise_.gaussian();

    const double t_s = ns_to_seconds(epoch_ns);
    const field2d::SprayerTruth truth = kinematics_.truth_at(t_s);
    const double sigma_m = params_.noise_base_m + params_.noise_ppm * 1e-6 * params_.baseline_km * 1000.0;
    const field2d::Vec2 measured{truth.antenna.east_m + sigma_m * east_noise,
                                 truth.antenna.north_m + sigma_m * north_noise};
    const field2d::GeodeticPoint position =
        kinematics_.frame().to_geodetic(measured, kinematics_.mounting().antenna_height_m);
    const field2d::Vec2 velocity{truth.antenna_velocity_m_s.east_m + params_.velocity_noise_m_s * ve_noise,
                                 truth.antenna_velocity_m_s.north_m + params_.velocity_noise_m_s * vn_noise};
    const double speed = field2d::norm(velocity);

    nmea::GnssFix fix{};
    const double utc = params_.utc_start_seconds_of_day + t_s;
    const int day_offset = static_cast<int>(std::floor(utc / 86400.0));
    fix.year = params_.utc_year;
    fix.month = params_.utc_month;
    fix.day = params_.utc_day + day_offset;
    fix.utc_seconds_of_day = utc - 86400.0 * day_offset;
    fix.lat_deg = position.lat_deg;
    fix.lon_deg = position.lon_deg;
    fix.altitude_msl_m = position.height_m;
    fix.fix_quality = 4;  // RTK fixed: RMC mode 'R'
    fix.satellites = 20;
    fix.hdop = 0.7;
    fix.speed_m_s = speed;
    fix.course_deg = speed >= params_.min_course_speed_m_s ? field2d::bearing_deg(velocity)
                                                           : std::numeric_limits<double>::quiet_NaN();
    fix.differential_age_s = 1.0;
    fix.station_id = 1;
    return fix;
}

std::vector<TimedLine> Ad300Receiver::poll(TimeNs now_ns) {
    std::vector<TimedLine> lines;
    while (next_due_ns() <= now_ns) {
        const TimeNs epoch = epoch_ns(next_epoch_);
        ++next_epoch_;
        lines.push_back(TimedLine{epoch + latency_ns_, nmea::encode_rmc(params_.talker, solve_epoch(epoch))});
    }
    return lines;
}

}  // namespace rig::emulators
