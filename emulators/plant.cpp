#include "emulators/plant.h"

#include <cmath>

#include "idl/topics.h"

namespace rig::emulators {

Plant::Plant(const PlantParams& params)
    : params_(params),
      field_(params.origin_lat_deg, params.origin_lon_deg, params.origin_height_m, params.heading_deg),
      vehicle_(params.route, params.boom, params.start_nozzle_line_along_m, params.boom_lifts),
      wheel_(params.wheel, params.seed) {}

msg::VehicleTruth Plant::truth_at(TimeNs t) const {
    const VehicleState state = vehicle_.state_at(ns_to_seconds(t));
    const GeoPoint antenna = field_.to_geodetic(state.antenna_along_m, 0.0);
    msg::VehicleTruth truth;
    truth.time_ns(t);
    truth.along_m(state.antenna_along_m);
    truth.cross_m(0.0);
    truth.lat_deg(antenna.lat_deg);
    truth.lon_deg(antenna.lon_deg);
    truth.height_m(antenna.height_m);
    // Driving backwards is not modelled; the vehicle always faces along the line.
    truth.heading_deg(field_.heading_deg());
    truth.speed_m_s(state.speed_m_s);
    truth.nozzle_line_along_m(state.nozzle_line_along_m);
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
