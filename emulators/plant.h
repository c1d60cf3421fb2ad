#pragma once
// The plant: vehicle on the A-B line, boom geometry, land wheel. It is the single
// source of truth; emulators sample it (ArduPilot-SITL style, in process) and the
// PlantNode publishes it on truth/vehicle for the harness and the trace.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "emulators/field_frame.h"
#include "emulators/guidance/guided_path.h"
#include "emulators/land_wheel.h"
#include "emulators/vehicle_plant.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/node.h"

namespace rig::emulators {

struct PlantParams {
    double origin_lat_deg = 40.18;
    double origin_lon_deg = 116.44;
    double origin_height_m = 50.0;
    double heading_deg = 90.0;
    BoomGeometry boom{};  // linkage_rise_m: h at t = 0
    std::vector<BoomLift> boom_lifts;  // the push rod's moves (none: h stays)
    std::vector<RoutePhase> route;
    double start_nozzle_line_along_m = 0.0;
    LandWheelParams wheel{};
    std::uint64_t seed = 1;
    // Autosteer along the A-B line over a rough ground (docs/guidance.md);
    // absent: the vehicle drives the line exactly, as before.
    std::optional<guidance::GuidanceParams> guidance;
    guidance::AntennaMount antenna{};
};

class Plant {
public:
    explicit Plant(const PlantParams& params);

    const FieldFrame& field() const { return field_; }
    const VehiclePlant& vehicle() const { return vehicle_; }
    const BoomGeometry& boom() const { return params_.boom; }  // at t = 0; h(t) in truth_at
    const LandWheel& land_wheel() const { return wheel_; }
    // Complete truth at time t (a pure function of t and the seed). With
    // guidance, the antenna (along_m, cross_m, lat/lon/height) is the tilted
    // body's, the heading the body's, and the nozzle line moves with the yaw;
    // the route's along position and speed stay the route's (the guided rear
    // axle's along lag, cross-track^2 / 2L, is micrometres).
    msg::VehicleTruth truth_at(TimeNs t) const;
    // The guided pass driven at t_s (nullptr without guidance): one per pass,
    // each starting at the pass's start (a headland turn brings the vehicle
    // back start_cross_track_m / start_heading_error_deg off the line).
    const guidance::GuidedPath* guided_at(double t_s) const;
    // truth_at(t).wheel_travel_m() alone, for emulators that search in time.
    double wheel_travel_m_at(TimeNs t) const;

private:
    PlantParams params_;
    FieldFrame field_;
    VehiclePlant vehicle_;
    LandWheel wheel_;
    std::vector<guidance::GuidedPath> guided_passes_;
};

// Publishes truth/vehicle at a fixed rate for the trace and the report.
class PlantNode final : public Node {
public:
    PlantNode(const Plant& plant, double truth_rate_hz);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;

private:
    std::string name_ = "plant";
    const Plant& plant_;
    TimeNs period_ns_;
    std::unique_ptr<Writer<msg::VehicleTruth>> truth_writer_;
};

}  // namespace rig::emulators
