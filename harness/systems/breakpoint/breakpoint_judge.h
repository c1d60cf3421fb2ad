#pragma once
// Seed 000's judge: the breakpoint, flow, Fig. 11, spray-timing and
// deposition metrics (harness/systems/breakpoint/breakpoint_metrics.h) of a
// seed-000 case from its recorded trace alone, with its figures (Fig. 14's
// flow, Fig. 15's dose). What to judge is the plan the run wrote from the
// case file and its route into meta `judging`.
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/judge/judge_trace.h"
#include "harness/systems/breakpoint/breakpoint_metrics.h"
#include "harness/trace/trace_reader.h"
#include "rig/papers/seed000.h"

namespace rig::harness {

// Seed 000's part of meta `judging` (its keys stand beside the common ones,
// harness/judge/judge_trace.h JudgingPlan, which this carries too). Everything
// here is a number the case or its route gave, never something the controller did.
struct BreakpointJudgingPlan : JudgingPlan {
    double breakpoint_along_m = 0.0;
    double field_origin_lat_deg = 0.0;
    double field_origin_lon_deg = 0.0;
    double field_origin_height_m = 0.0;
    double field_heading_deg = 0.0;
    bool judge_breakpoint = false;
    bool judge_flow = false;
    FlowJudging flow;
    FlowWindow flow_window;
    double kf11_pulses_per_l = papers::seed000::kFlowMeterPulsesPerLitre;  // the meter's nameplate k (Eq. 3)
    double kf11_window_s = 0.25;
    // Fig. 11 from truth (valve_calibration), over flow_window (the switch on).
    bool judge_fig11 = false;
    bool judge_deposition = false;
    DepositionJudging deposition;
    // With `guidance:`: the antenna's offset from the A-B line and the heading
    // error from truth/vehicle (harness/judge/guidance_metrics.h). The key is
    // only written when true, so plans without guidance stay byte for byte.
    bool judge_guidance = false;
};
// Seed 000's keys, added to `json` (the common ones are JudgingPlan's).
void add_breakpoint_keys(const BreakpointJudgingPlan& plan, nlohmann::json& json);
// The whole meta `judging` of a seed-000 run: the common keys and seed 000's.
nlohmann::json to_json(const BreakpointJudgingPlan& plan);
// Throws std::runtime_error naming the missing or malformed key.
BreakpointJudgingPlan breakpoint_judging_plan_from_json(const nlohmann::json& json);

// Every seed-000 metric and figure of a trace against its plan.
SystemJudgement judge_breakpoint_trace(const RecordedTrace& trace, const BreakpointJudgingPlan& plan);

// The deposition table of a trace as rows along the track, one vector per
// pass, averaged across the boom in nozzle order as emulators::DepositionGrid
// sums them (so the numbers match it exactly). Empty without meta
// `deposition_grid`. Throws std::runtime_error naming a cell outside the grid.
DoseProfile dose_profile(const RecordedTrace& trace);

}  // namespace rig::harness
