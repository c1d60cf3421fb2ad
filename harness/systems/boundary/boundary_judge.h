#pragma once
// Seed 001's judge: the boundary metrics (Tables 7, 8) and flow per duty
// (Table 3) of a boundary case, from its recorded trace alone. The ground is
// rebuilt from the truth the plant recorded (truth/nozzles, truth/vehicle2d;
// harness/systems/boundary/boundary_world.h says what each sample holds): each step's volume,
// the difference of a nozzle's delivered_l, laid as that nozzle's fan band
// where the nozzle was, turned with the heading, as wide as the fan at the boom
// height of that instant. The metrics are then harness/systems/boundary/boundary_metrics.h's.
// What to measure (the ground grid, the edges, the flow table) is the plan the
// run wrote from the case file into meta `judging`, key `boundary`.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "emulators/field2d/deposition_grid2d.h"
#include "emulators/field2d/nozzle_flow_table.h"
#include "harness/systems/boundary/boundary_case.h"
#include "harness/systems/boundary/boundary_metrics.h"
#include "harness/judge/judge_trace.h"
#include "harness/judge/metric_set.h"
#include "harness/trace/trace_reader.h"
#include "rig/papers/seed001.h"
#include "harness/systems/boundary/vision_metrics.h"

namespace rig::harness {

struct BoundaryEdgePlan {
    std::string metric;   // boundary_overrun | drive_out_excess | drive_in_excess
    BoundaryEdge edge;    // local frame, the area on its left
    EdgeProbe probe;
};

struct BoundaryJudgingPlan {
    field2d::DepositionGrid2dParams ground;
    double fan_angle_deg = 110.0;
    double band_thickness_m = 0.10;
    std::vector<BoundaryEdgePlan> edges;
    bool flow_per_duty = false;
    double flow_settle_s = 0.5;
    double pwm_period_s = 1.0 / papers::seed001::kPwmFrequencyHz;
    std::vector<std::vector<field2d::FlowPoint>> flow_table;  // what the plant was given (Table 3)
    bool centre_rule = false;
    std::vector<field2d::Vec2> area;       // local frame, counter-clockwise; the centre rule's area
    VisionJudging vision;                  // seed 001's vision half (harness/systems/boundary/vision_metrics.h)
    std::vector<field2d::Vec2> papers;     // Tables 4-6's papers (centres), local frame
    std::optional<GroundRect> dose_strip;  // dose per area judged over it
    CoverageModel coverage;
    // With `guidance:`: the route the autosteer followed, its rear-axle pose
    // every kGuidanceRouteSpacingM or so (east, north, heading), for the
    // guidance_* metrics (harness/judge/guidance_metrics.h); empty without.
    std::vector<std::array<double, 3>> guidance_route;
};
inline constexpr double kGuidanceRouteSpacingM = 0.05;
inline constexpr std::size_t kGuidanceRouteMaxPoints = 100000;

// From the case: the area's edges in the local frame (its corners through the
// case's ENU origin), each edge the one nearest the case's `near` point.
BoundaryJudgingPlan plan_boundary_judging(const BoundarySections& spec);
nlohmann::json to_json(const BoundaryJudgingPlan& plan);
// Throws std::runtime_error naming the missing or malformed key.
BoundaryJudgingPlan boundary_judging_plan_from_json(const nlohmann::json& json);

// One sample of truth/nozzles with the vehicle truth of the same instant.
struct NozzleStepTruth {
    TimeNs t_ns = 0;
    double heading_deg = 0.0;
    double boom_height_m = 0.0;
    std::vector<field2d::Vec2> position;   // per nozzle
    std::vector<double> duty_pct;          // per nozzle, the running PWM period's
    std::vector<double> delivered_l;       // per nozzle, cumulative
};
// The samples of a trace, in time order. Throws std::runtime_error naming a
// nozzles sample without a vehicle2d sample at its instant, a malformed one,
// or one whose delivered_l went back.
std::vector<NozzleStepTruth> nozzle_step_truth(const RecordedTrace& trace);

// The ground per nozzle, rebuilt from the truth samples. Throws
// std::runtime_error naming the sample where a nozzle's delivered_l went back.
std::vector<DoseRaster> ground_from_truth(const std::vector<NozzleStepTruth>& steps, const BoundaryJudgingPlan& plan);
// What each nozzle delivered at each duty it held (after flow_settle_s, over a
// whole number of PWM periods).
std::vector<FlowRecord> flow_records_from_truth(const std::vector<NozzleStepTruth>& steps, const BoundaryJudgingPlan& plan);

// Every ROI of every frame whose true centre lies in the plan's vision zone:
// truth/camera_view against controller/vision/density and the duty of
// actuator/nozzle_pwm/duty decision_delay_s after the exposure. Throws
// std::runtime_error naming a malformed sample.
std::vector<RoiJudged> rois_from_trace(const RecordedTrace& trace, const VisionJudging& judging);
// The cells of `total` whose centres lie in `rect`; a rectangle reaching off
// the raster throws std::runtime_error naming `what`.
DoseCells dose_cells(const DoseRaster& total, const GroundRect& rect, const std::string& what);

// Every boundary metric of the plan from the trace.
MetricSet boundary_trace_metrics(const RecordedTrace& trace, const BoundaryJudgingPlan& plan);

// Seed 001's judge: the metrics above and the vision figures (every ROI's true
// and measured cover, the frames the run kept for the report).
SystemJudgement judge_boundary_trace(const RecordedTrace& trace, const BoundaryJudgingPlan& plan);

}  // namespace rig::harness
