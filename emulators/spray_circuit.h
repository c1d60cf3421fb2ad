#pragma once
// The spray circuit of seed 000 Fig. 1 (plant truth): plunger pump -> pump-outlet
// sensor -> unloading valve -> proportional ball valve -> main-pipeline meter ->
// section switch valves -> 22 nozzles -> the ground. Unlike the vehicle (a
// closed-form function of time), it has state driven by the controller's
// actuators, so it is advanced in fixed steps.
//
// Determinism: advance_to(t) integrates whole steps of step_s on a fixed grid
// (k * step_s), never a partial one, so the state at any instant is the same
// whatever sequence of instants it was queried at; an actuator change at t acts
// from the grid step that contains t.
//
// What is modelled, and from where:
//   pump        output set by the throttle (36-81 L/min rated; the
//               calibration ran 31.1-57.3 L/min, sec. 2.4.2) with plunger
//               pulsation (pulsation_pct at pulsation_hz); the operator may
//               move the throttle during a run (throttle_steps: "the throttle
//               size of the sprayer corresponds linearly to the output flow
//               rate of the pump", sec. 2.4.2), the flow then ramps to the new
//               value over throttle_ramp_s (the engine's speed change);
//   unloading   open: the pump flow returns to the tank, the boom line is dry;
//   ball valve  emulators/ball_valve.h (11 s travel, backlash, start delay);
//   flow map    emulators/flow_map.h (Fig. 11 lines, Table 2, drift, bulge);
//   pipeline    the main flow follows the flow map's value with a first-order
//               lag (pressure build-up in hose and boom), and stops at once
//               when no nozzle can flow. The lag is pipeline_time_constant_s
//               plus what air trapped in the boom adds (pipeline_air_l, see
//               pipeline_lag_s()): a gas cushion is a hydraulic capacitance
//               that holds more at low pressure, so a low flow settles slower;
//   sections    switch valves open section_valve_open_s after the command and
//               close section_valve_close_s after it (Table 1: t3 = 0.200 s);
//               every command edge acts after its delay (a pure dead time), so
//               a valve told to close and to open again 50 ms later does close,
//               for 50 ms, 0.2 s later: a chattering output reaches the boom;
//   nozzles     the flow splits evenly over the open nozzles; each needs
//               min_nozzle_flow_l_min to spray, so at low flow the nozzles
//               farthest from the boom centre stop first (sec. 2.4.1: "an
//               opening degree >= 87 % ensured full spraying of all nozzles");
//   droplets    land droplet_fall_s after leaving the nozzle (Table 1: t5 =
//               0.067 s), under the nozzle's position at landing time, and are
//               booked in the deposition grid under the vehicle's current pass.
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "emulators/ball_valve.h"
#include "emulators/deposition_grid.h"
#include "emulators/flow_map.h"
#include "emulators/plant.h"
#include "emulators/spray_circuit_params.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/node.h"

namespace rig::emulators {

// Instants at which spray started and stopped landing, for Table 1's timing.
struct LandingEdge {
    TimeNs at_ns = 0;
    bool landing = false;   // true: the first droplets touch the ground; false: the last did
};

// Advanced by the master (rig/runtime/node.h TruthModel), once per instant;
// the device nodes (flow meters, the actuator node) only read it at the instant
// it was advanced to, and say so if it was not (require_advanced_to).
class SprayCircuit final : public TruthModel {
public:
    // Throws std::invalid_argument naming the bad parameter.
    SprayCircuit(const Plant& plant, SprayCircuitParams params);

    // Integrates up to t (whole steps); an earlier t than the last changes nothing.
    void advance_to(TimeNs t) override;
    // The last instant advance_to() was given (0 before the first).
    TimeNs advanced_to_ns() const { return advanced_to_ns_; }
    // For a device node sampling the circuit at now_ns: throws std::logic_error,
    // naming `device`, unless the circuit was advanced to exactly that instant
    // (a node stepped by something that does not advance the plant would read
    // the past).
    void require_advanced_to(TimeNs now_ns, const std::string& device) const;

    // Actuators, effective from the current instant (call advance_to first).
    void set_valve_drive(BallValve::Drive drive);
    void set_sections_commanded(std::uint16_t open_mask);
    void set_unloading_open(bool open);

    int nozzle_count() const { return nozzle_count_; }
    int section_count() const { return static_cast<int>(params_.section_nozzles.size()); }
    double pump_flow_l_min() const { return pump_flow_l_min_; }
    double main_flow_l_min() const { return main_flow_l_min_; }
    double main_volume_l() const { return main_volume_l_; }
    double valve_opening_pct() const { return valve_.opening_pct(); }
    std::uint16_t sections_commanded() const { return sections_commanded_; }
    std::uint16_t sections_open() const { return sections_open_; }
    int nozzles_spraying() const { return nozzles_spraying_; }
    bool unloading_open() const { return unloading_open_; }
    const BallValve& valve() const { return valve_; }
    const DepositionGrid& deposition() const { return deposition_; }
    const std::vector<LandingEdge>& landing_edges() const { return landing_edges_; }
    const SprayCircuitParams& params() const { return params_; }
    // Everything above as the truth/hydraulics sample at the current instant.
    msg::HydraulicsTruth truth() const;
    // The pipeline's time constant when main_flow_l_min settles through
    // open_nozzles: pipeline_time_constant_s plus the trapped air's R C (above).
    double pipeline_lag_s(double main_flow_l_min, int open_nozzles) const;

private:
    void step_once();
    int open_nozzle_count() const;
    // The pump's mean output at t_s (throttle steps and their ramps, no pulsation).
    double throttle_flow_l_min(double t_s) const;

    const Plant& plant_;
    TimeNs advanced_to_ns_ = 0;
    SprayCircuitParams params_;
    BallValve valve_;
    FlowMap flow_map_;
    DepositionGrid deposition_;
    int nozzle_count_ = 0;
    std::vector<int> nozzle_section_;     // section of each nozzle, left to right
    std::vector<int> nozzles_by_feed_;    // nozzle indices, nearest the boom centre first
    TimeNs step_ns_;
    std::int64_t steps_done_ = 0;         // state holds at steps_done_ * step_ns_

    double pump_flow_l_min_ = 0.0;
    double main_flow_l_min_ = 0.0;
    double main_volume_l_ = 0.0;
    std::uint16_t sections_commanded_ = 0;
    std::uint16_t sections_open_ = 0;
    // Per section, the commanded states still on their way: (when it acts, open).
    std::vector<std::deque<std::pair<TimeNs, bool>>> section_pending_;
    bool unloading_open_ = true;          // at power-on the circuit is unloaded
    int nozzles_spraying_ = 0;
    bool landing_ = false;
    std::vector<LandingEdge> landing_edges_;
};

}  // namespace rig::emulators
