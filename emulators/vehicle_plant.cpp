#include "emulators/vehicle_plant.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace rig::emulators {

namespace {

[[noreturn]] void reject_phase(std::size_t index, const std::string& problem) {
    throw std::invalid_argument("route phase " + std::to_string(index) + ": " + problem);
}

}  // namespace

double BoomGeometry::l4_m() const {
    // Eq. 6, the plant's own copy (see the header for why it is not shared).
    return l1_m + std::cos(std::atan2(linkage_rise_m, l2_m)) * l2_m + l3_m;
}

VehiclePlant::Segment VehiclePlant::make_drive(const DrivePhase& drive, double start_s, double start_along_m) {
    Segment segment;
    segment.kind = Segment::Kind::drive;
    segment.start_s = start_s;
    segment.start_along_m = start_along_m;
    segment.end_along_m = drive.to_along_m;
    segment.accel_m_s2 = drive.accel_m_s2;
    const double length_m = drive.to_along_m - start_along_m;
    const double accel = drive.accel_m_s2;
    // Reaching cruise speed v and braking from it takes v^2 / (2a) each way; if the
    // drive is shorter than v^2 / a the profile is a triangle with peak sqrt(a L).
    const double peak_speed_m_s = std::min(drive.cruise_speed_m_s, std::sqrt(accel * length_m));
    segment.peak_speed_m_s = peak_speed_m_s;
    segment.ramp_s = peak_speed_m_s / accel;
    segment.ramp_m = 0.5 * accel * segment.ramp_s * segment.ramp_s;
    segment.cruise_s =
        peak_speed_m_s > 0.0 ? std::max(0.0, (length_m - 2.0 * segment.ramp_m) / peak_speed_m_s) : 0.0;
    segment.duration_s = 2.0 * segment.ramp_s + segment.cruise_s;
    return segment;
}

VehiclePlant::VehiclePlant(std::vector<RoutePhase> route, BoomGeometry boom, double start_nozzle_line_along_m)
    : boom_(boom), l4_m_(boom.l4_m()), start_nozzle_line_along_m_(start_nozzle_line_along_m) {
    if (!std::isfinite(start_nozzle_line_along_m)) {
        throw std::invalid_argument("route: start position must be finite");
    }
    double now_s = 0.0;
    double along_m = start_nozzle_line_along_m;
    double odometer_m = 0.0;
    for (std::size_t index = 0; index < route.size(); ++index) {
        Segment segment = std::visit(
            [&](const auto& phase) -> Segment {
                using Phase = std::decay_t<decltype(phase)>;
                Segment built;
                if constexpr (std::is_same_v<Phase, StandPhase>) {
                    if (!std::isfinite(phase.duration_s) || phase.duration_s < 0.0) {
                        reject_phase(index, "stand duration_s must be finite and >= 0");
                    }
                    built.kind = Segment::Kind::stand;
                    built.start_s = now_s;
                    built.duration_s = phase.duration_s;
                    built.start_along_m = along_m;
                    built.end_along_m = along_m;
                } else if constexpr (std::is_same_v<Phase, RepositionPhase>) {
                    if (!std::isfinite(phase.to_along_m)) reject_phase(index, "reposition to_along_m must be finite");
                    built.kind = Segment::Kind::reposition;
                    built.start_s = now_s;
                    built.start_along_m = phase.to_along_m;
                    built.end_along_m = phase.to_along_m;
                } else {
                    if (!std::isfinite(phase.to_along_m)) reject_phase(index, "drive to_along_m must be finite");
                    if (!(phase.cruise_speed_m_s > 0.0) || !std::isfinite(phase.cruise_speed_m_s)) {
                        reject_phase(index, "drive cruise_speed_m_s must be > 0");
                    }
                    if (!(phase.accel_m_s2 > 0.0) || !std::isfinite(phase.accel_m_s2)) {
                        reject_phase(index, "drive accel_m_s2 must be > 0");
                    }
                    if (phase.to_along_m < along_m) {
                        reject_phase(index, "drive to_along_m " + std::to_string(phase.to_along_m) +
                                                " is behind the vehicle at " + std::to_string(along_m) +
                                                " (driving backwards is not modelled)");
                    }
                    built = make_drive(phase, now_s, along_m);
                }
                return built;
            },
            route[index]);
        segment.odometer_start_m = odometer_m;
        if (segment.kind == Segment::Kind::drive) odometer_m += segment.end_along_m - segment.start_along_m;
        now_s += segment.duration_s;
        along_m = segment.end_along_m;
        segments_.push_back(segment);
    }
}

double VehiclePlant::end_time_s() const {
    if (segments_.empty()) return 0.0;
    const Segment& last = segments_.back();
    return last.start_s + last.duration_s;
}

VehiclePlant::Kinematics VehiclePlant::drive_kinematics(const Segment& drive, double into_s) {
    const double accel = drive.accel_m_s2;
    const double brake_from_s = drive.ramp_s + drive.cruise_s;
    if (into_s <= 0.0) return {drive.start_along_m, 0.0, drive.ramp_s > 0.0 ? accel : 0.0};
    if (into_s < drive.ramp_s) {
        return {drive.start_along_m + 0.5 * accel * into_s * into_s, accel * into_s, accel};
    }
    if (into_s < brake_from_s) {
        return {drive.start_along_m + drive.ramp_m + drive.peak_speed_m_s * (into_s - drive.ramp_s),
                drive.peak_speed_m_s, 0.0};
    }
    if (into_s < drive.duration_s) {
        // Measured back from the end, so the stop lands exactly on the target.
        const double to_stop_s = drive.duration_s - into_s;
        return {drive.end_along_m - 0.5 * accel * to_stop_s * to_stop_s, accel * to_stop_s, -accel};
    }
    return {drive.end_along_m, 0.0, 0.0};
}

int VehiclePlant::pass_index_at(double t_s) const {
    int pass = 0;
    for (const Segment& segment : segments_) {
        if (segment.start_s > t_s) break;
        if (segment.kind == Segment::Kind::reposition) ++pass;
    }
    return pass;
}

double VehiclePlant::pass_start_s(int pass) const {
    if (pass == 0) return 0.0;
    int seen = 0;
    for (const Segment& segment : segments_) {
        if (segment.kind == Segment::Kind::reposition && ++seen == pass) return segment.start_s;
    }
    return std::numeric_limits<double>::quiet_NaN();
}

double VehiclePlant::drive_time_for(const Segment& drive, double covered_m) {
    const double accel = drive.accel_m_s2;
    const double length_m = drive.end_along_m - drive.start_along_m;
    if (covered_m <= 0.0) return 0.0;
    if (covered_m >= length_m) return drive.duration_s;
    // Inverse of drive_kinematics, piece by piece.
    if (covered_m <= drive.ramp_m) return std::sqrt(2.0 * covered_m / accel);
    if (covered_m <= length_m - drive.ramp_m) {
        return drive.ramp_s + (covered_m - drive.ramp_m) / drive.peak_speed_m_s;
    }
    const double remaining_m = std::max(0.0, length_m - covered_m);
    return drive.duration_s - std::sqrt(2.0 * remaining_m / accel);
}

VehicleState VehiclePlant::state_at(double t_s) const {
    VehicleState state;
    state.time_s = t_s;
    double nozzle_line_along_m = start_nozzle_line_along_m_;
    // The last segment starting at or before t_s holds; after a zero-length
    // reposition the next segment starts at the same instant and takes over.
    const auto after = std::upper_bound(segments_.begin(), segments_.end(), t_s,
                                        [](double t, const Segment& segment) { return t < segment.start_s; });
    if (after != segments_.begin()) {
        const Segment& segment = *std::prev(after);
        if (segment.kind == Segment::Kind::drive) {
            const Kinematics kinematics = drive_kinematics(segment, t_s - segment.start_s);
            nozzle_line_along_m = kinematics.along_m;
            state.speed_m_s = kinematics.speed_m_s;
            state.accel_m_s2 = kinematics.accel_m_s2;
            state.odometer_distance_m = segment.odometer_start_m + (kinematics.along_m - segment.start_along_m);
        } else {
            nozzle_line_along_m = segment.end_along_m;
            state.odometer_distance_m = segment.odometer_start_m;
        }
    }
    state.nozzle_line_along_m = nozzle_line_along_m;
    state.antenna_along_m = nozzle_line_along_m + l4_m_;
    return state;
}

double VehiclePlant::time_when_nozzle_line_reaches(double along_m, double after_s) const {
    for (const Segment& segment : segments_) {
        if (segment.kind != Segment::Kind::drive) continue;
        if (segment.start_s + segment.duration_s < after_s) continue;
        if (along_m < segment.start_along_m || along_m > segment.end_along_m) continue;
        const double t_s = segment.start_s + drive_time_for(segment, along_m - segment.start_along_m);
        // Within one drive the nozzle line only moves forward, so if it was there
        // before after_s it is not there again in this drive.
        if (t_s >= after_s) return t_s;
    }
    return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace rig::emulators
