#pragma once
// The world a seed-000 case describes, built before anything runs: the plant
// (route, boom, land wheel), the spray circuit's parameters, the operator's
// script, the receiver's parameters, and what the judge will hold the
// controller to. A pure function of the case's sections and the seed; `rig
// run` and the bench tools (`rig emulate gnss`) build it the same way.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "emulators/gnss_g970.h"
#include "emulators/panel_switch.h"
#include "emulators/plant.h"
#include "emulators/spray_circuit.h"
#include "harness/systems/breakpoint/breakpoint_case.h"
#include "harness/systems/breakpoint/breakpoint_judge.h"
#include "harness/trace/trace_file.h"

namespace rig::harness {

// What the case's vehicle does and its operator presses.
struct ScenarioPlan {
    std::vector<emulators::RoutePhase> route;
    double start_along_m = 0.0;  // nozzle line at t = 0
    std::vector<emulators::SwitchClosure> button;
    std::vector<emulators::SwitchClosure> spray_switch;
    double approach_starts_s = 0.0;
};

struct BreakpointWorld {
    emulators::Plant plant;
    ScenarioPlan scenario;
    emulators::G970Params gnss;
    emulators::SprayCircuitParams circuit;  // its deposition grid spans all the boom can reach
    double breakpoint_crossing_s = 0.0;     // on the approach; NaN in a static test
    // Where the spray stopped: the nozzle line when the operator pressed the
    // button. breakpoint.along_m, unless the boom moved before the button (the
    // route is the nozzle line's path at the initial h: emulators/vehicle_plant.h).
    double breakpoint_along_m = 0.0;
    TimeNs end_ns = 0;
};
BreakpointWorld build_case_world(const BreakpointSections& own, std::uint64_t seed);

// What the judge holds the controller to (harness/systems/breakpoint/breakpoint_judge.h),
// from the case file and its route only: the flow window, the strip that must
// be sprayed, the nominal dose. `limits`: the case's effective limits (the flow
// is due to be steady by flow_adjust_time_s). The common part of the plan
// (limits, expectations) is the run's.
BreakpointJudgingPlan plan_judging(const BreakpointSections& own, const BreakpointWorld& world,
                                   const std::map<std::string, double>& limits);

// The grid's non-empty cells into the trace's `deposition` table, in the
// digest's order (pass, row, nozzle), with its layout (meta `deposition_grid`).
void record_deposition(TraceFile& trace, const emulators::DepositionGrid& grid);

}  // namespace rig::harness
