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

[[noreturn]] void reject_lift(std::size_t index, const std::string& problem) {
    throw std::invalid_argument("boom lift " + std::to_string(index) + ": " + problem);
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

VehiclePlant::VehiclePlant(std::vector<RoutePhase> route, BoomGeometry boom, double start_nozzle_line_along_m,
                           std::vector<BoomLift> lifts)
    : boom_(boom), l4_m_(boom.l4_m()), start_nozzle_line_along_m_(start_nozzle_line_along_m) {
    if (!lifts.empty() && !(boom.linkage_rise_m >= 0.0 && boom.linkage_rise_m <= kMaxLinkageRiseM)) {
        throw std::invalid_argument("boom lift: the initial linkage rise must be in [0, " +
                                    std::to_string(kMaxLinkageRiseM) + "] m when the boom moves");
    }
    double rise_m = boom.linkage_rise_m;
    double push_rod_free_s = 0.0;
    for (std::size_t index = 0; index < lifts.size(); ++index) {
        const BoomLift& lift = lifts[index];
        if (!std::isfinite(lift.at_s) || lift.at_s < 0.0) reject_lift(index, "at_s must be finite and >= 0");
        if (!(lift.to_m >= 0.0 && lift.to_m <= kMaxLinkageRiseM)) {
            reject_lift(index, "to_m must be in [0, " + std::to_string(kMaxLinkageRiseM) + "] m");
        }
        if (!(lift.rate_m_s >= kMinLiftRateMS) || !std::isfinite(lift.rate_m_s)) {
            reject_lift(index, "rate_m_s must be finite and >= " + std::to_string(kMinLiftRateMS));
        }
        if (lift.at_s < push_rod_free_s) {
            reject_lift(index, "starts at " + std::to_string(lift.at_s) + " s, before the previous lift arrives at " +
                                   std::to_string(push_rod_free_s) + " s");
        }
        const double end_s = lift.at_s + std::abs(lift.to_m - rise_m) / lift.rate_m_s;
        lift_segments_.push_back(LiftSegment{lift.at_s, end_s, rise_m, lift.to_m});
        rise_m = lift.to_m;
        push_rod_free_s = end_s;
    }
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

double VehiclePlant::linkage_rise_m_at(double t_s) const {
    const auto after = std::upper_bound(lift_segments_.begin(), lift_segments_.end(), t_s,
                                        [](double t, const LiftSegment& lift) { return t < lift.start_s; });
    if (after == lift_segments_.begin()) return boom_.linkage_rise_m;
    const LiftSegment& lift = *std::prev(after);
    if (t_s >= lift.end_s) return lift.to_m;
    return lift.from_m + (lift.to_m - lift.from_m) * (t_s - lift.start_s) / (lift.end_s - lift.start_s);
}

double VehiclePlant::route_along_m(const Segment& segment, double t_s) {
    if (segment.kind != Segment::Kind::drive) return segment.end_along_m;
    return drive_kinematics(segment, t_s - segment.start_s).along_m;
}

double VehiclePlant::nozzle_line_from_route_m(double route_along_m, double t_s) const {
    const double rise_m = linkage_rise_m_at(t_s);
    // At the initial h the route position is the nozzle line itself: no
    // round trip through the antenna, so a case without lifts keeps its digests.
    if (rise_m == boom_.linkage_rise_m) return route_along_m;
    BoomGeometry now = boom_;
    now.linkage_rise_m = rise_m;
    return (route_along_m + l4_m_) - now.l4_m();
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
    // The antenna follows the route (the nozzle line's path at the initial h).
    state.antenna_along_m = nozzle_line_along_m + l4_m_;
    state.nozzle_line_along_m = nozzle_line_from_route_m(nozzle_line_along_m, t_s);
    state.linkage_rise_m = linkage_rise_m_at(t_s);
    if (state.linkage_rise_m == boom_.linkage_rise_m) {
        state.l4_m = l4_m_;
    } else {
        BoomGeometry now = boom_;
        now.linkage_rise_m = state.linkage_rise_m;
        state.l4_m = now.l4_m();
    }
    return state;
}

double VehiclePlant::first_crossing_while_boom_moves(const Segment& segment, double along_m, double from_s,
                                                     double to_s, bool lowering) const {
    const auto gap_m = [&](double t_s) { return nozzle_line_from_route_m(route_along_m(segment, t_s), t_s) - along_m; };
    // Between lo (gap of one sign) and hi (the other sign or 0): the first instant at or past along_m.
    const auto bisect = [&](double lo_s, double hi_s, double gap_lo_m) {
        for (int iteration = 0; iteration < 200; ++iteration) {
            const double mid_s = 0.5 * (lo_s + hi_s);
            if (!(mid_s > lo_s && mid_s < hi_s)) break;
            const double gap_mid_m = gap_m(mid_s);
            if (gap_mid_m == 0.0) return mid_s;
            if ((gap_mid_m < 0.0) == (gap_lo_m < 0.0)) {
                lo_s = mid_s;
                gap_lo_m = gap_mid_m;
            } else {
                hi_s = mid_s;
            }
        }
        return hi_s;
    };
    double previous_s = from_s;
    double previous_gap_m = gap_m(from_s);
    if (previous_gap_m == 0.0) return from_s;
    // Lifting with the vehicle still or driving forward, the nozzle line only goes
    // forward: one look at the end tells whether it crosses. Lowering it may go
    // back and forth: sample (see the header for what that can miss).
    const double span_s = to_s - from_s;
    const std::size_t samples =
        lowering ? std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(span_s / kLoweringSampleS))) : 1;
    for (std::size_t k = 1; k <= samples; ++k) {
        const double t_s = k == samples ? to_s : from_s + span_s * static_cast<double>(k) / static_cast<double>(samples);
        const double gap_now_m = gap_m(t_s);
        if (gap_now_m == 0.0) return t_s;
        if ((gap_now_m < 0.0) != (previous_gap_m < 0.0)) return bisect(previous_s, t_s, previous_gap_m);
        previous_s = t_s;
        previous_gap_m = gap_now_m;
    }
    return std::numeric_limits<double>::quiet_NaN();
}

double VehiclePlant::time_when_nozzle_line_reaches(double along_m, double after_s) const {
    if (!lift_segments_.empty()) {
        for (const Segment& segment : segments_) {
            const double end_s = segment.start_s + segment.duration_s;
            if (end_s < after_s) continue;
            if (segment.duration_s <= 0.0) {
                // A zero-length drive at along_m counts, as without lifts; a reposition is a jump, not a passage.
                if (segment.kind == Segment::Kind::drive &&
                    nozzle_line_from_route_m(segment.end_along_m, segment.start_s) == along_m) {
                    return segment.start_s;
                }
                continue;
            }
            // Cut the segment where either motion changes law: its own speed
            // profile's joints and the push rod's starts and stops.
            std::vector<double> cuts{std::max(segment.start_s, after_s), end_s};
            if (segment.kind == Segment::Kind::drive) {
                cuts.push_back(segment.start_s + segment.ramp_s);
                cuts.push_back(segment.start_s + segment.ramp_s + segment.cruise_s);
            }
            for (const LiftSegment& lift : lift_segments_) {
                cuts.push_back(lift.start_s);
                cuts.push_back(lift.end_s);
            }
            std::sort(cuts.begin(), cuts.end());
            cuts.erase(std::remove_if(cuts.begin(), cuts.end(),
                                      [&](double t) { return t < std::max(segment.start_s, after_s) || t > end_s; }),
                       cuts.end());
            cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
            for (std::size_t piece = 0; piece + 1 < cuts.size(); ++piece) {
                const double from_s = cuts[piece];
                const double to_s = cuts[piece + 1];
                const double middle_s = 0.5 * (from_s + to_s);
                const LiftSegment* moving = nullptr;
                for (const LiftSegment& lift : lift_segments_) {
                    if (lift.start_s < middle_s && middle_s < lift.end_s) moving = &lift;
                }
                if (moving != nullptr) {
                    const double t_s =
                        first_crossing_while_boom_moves(segment, along_m, from_s, to_s, moving->to_m < moving->from_m);
                    if (std::isfinite(t_s)) return t_s;
                    continue;
                }
                if (segment.kind != Segment::Kind::drive) continue;  // standing with the boom still
                // The boom holds h here: the nozzle line is the route shifted by
                // L4(h0) - L4(h), and the route is inverted exactly.
                const double rise_m = linkage_rise_m_at(middle_s);
                double route_target_m = along_m;
                if (rise_m != boom_.linkage_rise_m) {
                    BoomGeometry now = boom_;
                    now.linkage_rise_m = rise_m;
                    route_target_m = along_m + now.l4_m() - l4_m_;
                }
                if (route_target_m < segment.start_along_m || route_target_m > segment.end_along_m) continue;
                const double t_s = segment.start_s + drive_time_for(segment, route_target_m - segment.start_along_m);
                if (t_s >= from_s && t_s <= to_s) return t_s;
            }
        }
        return std::numeric_limits<double>::quiet_NaN();
    }
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
