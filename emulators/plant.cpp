#include "emulators/plant.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "idl/topics.h"

namespace rig::emulators {

namespace {

// The guided rear axle works in the A-B line's own plane frame: east = right of
// the line, north = along it (heading 0), with the route distance measured from
// `line_origin_m` along the line (the ground's roughness is a function of it,
// so every pass crosses the same bumps at the same place).
guidance::ReferencePath line_reference(double line_origin_m) {
    return [line_origin_m](double distance_m) {
        return guidance::PathPose{guidance::Vec2{0.0, line_origin_m + distance_m}, 0.0};
    };
}

}  // namespace

Plant::Plant(const PlantParams& params)
    : params_(params),
      field_(params.origin_lat_deg, params.origin_lon_deg, params.origin_height_m, params.heading_deg),
      vehicle_(params.route, params.boom, params.start_nozzle_line_along_m, params.boom_lifts),
      wheel_(params.wheel, params.seed) {
    if (!params_.guidance) return;
    validate(params_.antenna, "guidance");
    // The rear axle's along position is the antenna's less its mounting; the
    // line's route distance starts well behind anywhere the axle can be.
    const double axle_behind_antenna_m = params_.antenna.forward_of_rear_axle_m;
    // Drives only go forward: each pass's lowest position is its start.
    double lowest_antenna_m = std::numeric_limits<double>::infinity();
    for (int pass = 0; std::isfinite(vehicle_.pass_start_s(pass)); ++pass) {
        lowest_antenna_m = std::min(lowest_antenna_m, vehicle_.state_at(vehicle_.pass_start_s(pass)).antenna_along_m);
    }
    const double line_origin_m = lowest_antenna_m - axle_behind_antenna_m - 100.0;
    const VehiclePlant route = vehicle_;
    const guidance::SpeedProfile speed = [route](double t_s) { return route.state_at(t_s).speed_m_s; };
    const guidance::BodyPoint antenna{0.0, params_.antenna.forward_of_rear_axle_m, params_.antenna.height_m};
    for (int pass = 0; std::isfinite(vehicle_.pass_start_s(pass)); ++pass) {
        const double start_s = vehicle_.pass_start_s(pass);
        const double next_s = vehicle_.pass_start_s(pass + 1);
        const double end_s = std::isfinite(next_s) ? next_s : vehicle_.end_time_s();
        const double axle_m = vehicle_.state_at(start_s).antenna_along_m - axle_behind_antenna_m;
        guided_passes_.emplace_back(*params_.guidance, line_reference(line_origin_m), speed, start_s,
                                    std::max(start_s, end_s), axle_m - line_origin_m, antenna, params_.seed);
    }
}

const guidance::GuidedPath* Plant::guided_at(double t_s) const {
    if (guided_passes_.empty()) return nullptr;
    const auto pass = static_cast<std::size_t>(std::max(0, vehicle_.pass_index_at(t_s)));
    return &guided_passes_[std::min(pass, guided_passes_.size() - 1)];
}

msg::VehicleTruth Plant::truth_at(TimeNs t) const {
    const VehicleState state = vehicle_.state_at(ns_to_seconds(t));
    double antenna_along_m = state.antenna_along_m;
    double antenna_cross_m = 0.0;
    double antenna_up_m = 0.0;
    // Driving backwards is not modelled; unguided, the vehicle always faces along the line.
    double heading_deg = field_.heading_deg();
    double nozzle_line_along_m = state.nozzle_line_along_m;
    if (const guidance::GuidedPath* guided = guided_at(ns_to_seconds(t))) {
        const guidance::GuidedState body = guided->state_at(ns_to_seconds(t));
        const double forward_m = params_.antenna.forward_of_rear_axle_m;
        // The antenna relative to the rear axle, tilted and yawed, against the
        // level, straight body's `forward_m` the route is written for.
        antenna_along_m += (body.antenna.north_m - body.position.north_m) - forward_m;
        antenna_cross_m = body.antenna.east_m;
        antenna_up_m = body.antenna_up_m - params_.antenna.height_m;
        heading_deg = std::fmod(heading_deg + body.heading_deg, 360.0);
        // The nozzle line, (forward_m - L4) ahead of the axle on the body, yawed.
        const double yaw_rad = body.heading_deg * M_PI / 180.0;
        nozzle_line_along_m += (forward_m - state.l4_m) * (std::cos(yaw_rad) - 1.0);
    }
    const GeoPoint antenna = field_.to_geodetic(antenna_along_m, antenna_cross_m, antenna_up_m);
    msg::VehicleTruth truth;
    truth.time_ns(t);
    truth.along_m(antenna_along_m);
    truth.cross_m(antenna_cross_m);
    truth.lat_deg(antenna.lat_deg);
    truth.lon_deg(antenna.lon_deg);
    truth.height_m(antenna.height_m);
    truth.heading_deg(heading_deg);
    truth.speed_m_s(state.speed_m_s);
    truth.nozzle_line_along_m(nozzle_line_along_m);
    truth.l4_m(state.l4_m);
    truth.boom_height_m(state.linkage_rise_m);
    truth.wheel_travel_m(wheel_.wheel_travel_m(state.odometer_distance_m));
    truth.pass_index(static_cast<std::uint16_t>(vehicle_.pass_index_at(ns_to_seconds(t))));
    return truth;
}

double Plant::wheel_travel_m_at(TimeNs t) const {
    return wheel_.wheel_travel_m(vehicle_.state_at(ns_to_seconds(t)).odometer_distance_m);
}

PlantNode::PlantNode(const Plant& plant, double truth_rate_hz)
    : plant_(plant), period_ns_(seconds_to_ns(1.0 / truth_rate_hz)) {}

void PlantNode::configure(DdsContext& dds) {
    truth_writer_ = std::make_unique<Writer<msg::VehicleTruth>>(dds, topics::kVehicleTruth);
}

TimeNs PlantNode::step(TimeNs now_ns) {
    truth_writer_->publish(plant_.truth_at(now_ns));
    return next_period_boundary(now_ns, period_ns_);
}

}  // namespace rig::emulators
