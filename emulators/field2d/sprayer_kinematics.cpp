#include "emulators/field2d/sprayer_kinematics.h"

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

SprayerKinematics::SprayerKinematics(LocalFrame frame, Route2d route, SprayerMounting mounting,
                                     BoomHeightProfile height)
    : frame_(std::move(frame)), route_(std::move(route)), mounting_(mounting), height_(std::move(height)) {
    validate(mounting_);
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
    const VehiclePose2d& pose = truth.pose;
    const double x = mounting_.antenna_right_m;
    const double y = mounting_.antenna_forward_of_axle_m;
    truth.antenna = body_to_field(pose.position, pose.heading_deg, x, y);
    truth.antenna_geodetic = frame_.to_geodetic(truth.antenna, mounting_.antenna_height_m);
    // Rigid body: the point (x, y) moves at (v - x w) forward + (y w) right, with
    // w the yaw rate in rad/s (clockwise positive, as the heading).
    const double w = pose.yaw_rate_deg_s * M_PI / 180.0;
    truth.antenna_velocity_m_s = (pose.speed_m_s - x * w) * forward_of(pose.heading_deg) +
                                 (y * w) * right_of(pose.heading_deg);
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
