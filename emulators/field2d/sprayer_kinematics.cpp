#include "emulators/field2d/sprayer_kinematics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace rig::field2d {

void validate(const SprayerMounting& m) {
    if (!std::isfinite(m.antenna_forward_of_axle_m)) {
        throw std::invalid_argument("mounting.antenna_forward_of_axle_m: must be finite");
    }
    if (!std::isfinite(m.antenna_right_m)) throw std::invalid_argument("mounting.antenna_right_m: must be finite");
    if (!std::isfinite(m.antenna_height_m) || m.antenna_height_m <= 0.0) {
        throw std::invalid_argument("mounting.antenna_height_m: must be finite and > 0, got " +
                                    std::to_string(m.antenna_height_m));
    }
    validate(m.lift, "mounting.lift");
    if (m.nozzle_count < 1 || m.nozzle_count > 32) {
        throw std::invalid_argument("mounting.nozzle_count: must be in [1, 32], got " + std::to_string(m.nozzle_count));
    }
    if (!std::isfinite(m.nozzle_spacing_m) || m.nozzle_spacing_m <= 0.0) {
        throw std::invalid_argument("mounting.nozzle_spacing_m: must be finite and > 0, got " +
                                    std::to_string(m.nozzle_spacing_m));
    }
}

double nozzle_right_m(const SprayerMounting& mounting, int nozzle) {
    if (nozzle < 0 || nozzle >= mounting.nozzle_count) {
        throw std::out_of_range("nozzle " + std::to_string(nozzle) + " out of range [0, " +
                                std::to_string(mounting.nozzle_count) + ")");
    }
    return (nozzle - 0.5 * (mounting.nozzle_count - 1)) * mounting.nozzle_spacing_m;
}

emulators::guidance::ReferencePath reference_path_of(const Route2d& route) {
    return [route](double distance_m) {
        const double total_m = route.total_distance_m();
        const VehiclePose2d at = route.state_at(route.time_at_distance(std::clamp(distance_m, 0.0, total_m)));
        const double beyond_m = std::max(0.0, distance_m - total_m);
        return emulators::guidance::PathPose{at.position + beyond_m * forward_of(at.heading_deg), at.heading_deg};
    };
}

SprayerKinematics::SprayerKinematics(LocalFrame frame, Route2d route, SprayerMounting mounting,
                                     BoomHeightProfile height, std::optional<emulators::guidance::GuidanceParams> guidance,
                                     std::uint64_t seed)
    : frame_(std::move(frame)), route_(std::move(route)), mounting_(mounting), height_(std::move(height)) {
    validate(mounting_);
    if (guidance) {
        // By value: the kinematics may be moved, the functions must not dangle.
        guided_.emplace(*guidance, reference_path_of(route_),
                        [driven = route_](double t_s) { return driven.state_at(t_s).speed_m_s; }, 0.0, route_.end_time_s(), 0.0,
                        emulators::guidance::BodyPoint{mounting_.antenna_right_m, mounting_.antenna_forward_of_axle_m,
                                                       mounting_.antenna_height_m},
                        seed);
    }
    // Every height the profile passes through must be reachable (Eq. 18's square root).
    for (const double h : {height_.min_height_m(), height_.max_height_m()}) {
        if (h < mounting_.lift.min_height_m() || h > mounting_.lift.max_height_m()) {
            throw std::invalid_argument("boom height " + std::to_string(h) + " m is out of the lift's reach [" +
                                        std::to_string(mounting_.lift.min_height_m()) + ", " +
                                        std::to_string(mounting_.lift.max_height_m()) + "] m (Eq. 18)");
        }
    }
}

SprayerTruth SprayerKinematics::truth_at(double t_s) const {
    SprayerTruth truth;
    truth.pose = route_.state_at(t_s);
    const double x = mounting_.antenna_right_m;
    const double y = mounting_.antenna_forward_of_axle_m;
    if (guided_) {
        // The guided vehicle's pose; the route keeps its time, acceleration and segment.
        const emulators::guidance::GuidedState guided = guided_->state_at(t_s);
        truth.pose.position = guided.position;
        truth.pose.heading_deg = guided.heading_deg;
        truth.pose.speed_m_s = guided.speed_m_s;
        truth.pose.yaw_rate_deg_s = guided.yaw_rate_deg_s;
        truth.pose.distance_m = guided.distance_m;
        truth.antenna = guided.antenna;
        truth.antenna_geodetic = frame_.to_geodetic(guided.antenna, guided.antenna_up_m);
        truth.antenna_velocity_m_s = guided.antenna_velocity_m_s;
    } else {
        const VehiclePose2d& pose = truth.pose;
        truth.antenna = body_to_field(pose.position, pose.heading_deg, x, y);
        truth.antenna_geodetic = frame_.to_geodetic(truth.antenna, mounting_.antenna_height_m);
        // Rigid body: the point (x, y) moves at (v - x w) forward + (y w) right, with
        // w the yaw rate in rad/s (clockwise positive, as the heading).
        const double w = pose.yaw_rate_deg_s * M_PI / 180.0;
        truth.antenna_velocity_m_s = (pose.speed_m_s - x * w) * forward_of(pose.heading_deg) +
                                     (y * w) * right_of(pose.heading_deg);
    }
    const VehiclePose2d& pose = truth.pose;
    truth.boom_height_m = height_.height_at(t_s);
    truth.boom_offset_m = eq18_boom_offset_m(mounting_.lift, truth.boom_height_m);
    const double boom_forward_m = y + truth.boom_offset_m;
    truth.boom_centre = body_to_field(pose.position, pose.heading_deg, x, boom_forward_m);
    truth.nozzles.reserve(static_cast<std::size_t>(mounting_.nozzle_count));
    for (int i = 0; i < mounting_.nozzle_count; ++i) {
        truth.nozzles.push_back(
            body_to_field(pose.position, pose.heading_deg, x + nozzle_right_m(mounting_, i), boom_forward_m));
    }
    return truth;
}

}  // namespace rig::field2d
