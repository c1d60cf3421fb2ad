#pragma once
// Seed 000's figures for the report (report.html): the main-pipeline flow
// around the section-open command against distance and time (the paper's
// Fig. 14), and the dose per row across the breakpoint with the areas the
// judge classified (Fig. 15), made by the judge from the trace alone.
#include <optional>
#include <string>
#include <vector>

#include "harness/judge/case_figures.h"
#include "harness/systems/breakpoint/breakpoint_metrics.h"

namespace rig::harness {

// One sample of the main-pipeline flow around the section-open command.
struct FlowSample {
    double t_s = kNotMeasured;                       // simulated time
    double distance_to_breakpoint_m = kNotMeasured;  // nozzle line minus breakpoint along the track: negative before it
    double main_flow_l_min = kNotMeasured;           // truth (plant)
    double measured_flow_l_min = kNotMeasured;       // what the controller computed (Eq. 3); NaN if unknown
};

// One row of the deposition grid, summed across the boom (the paper's row of filter papers).
struct DoseSample {
    double along_m = kNotMeasured;
    double first_pass_dose = kNotMeasured;    // sprayed before the breakpoint stop
    double continuation_dose = kNotMeasured;  // sprayed after the resume; same unit (the rig: uL/cm^2, mean across the boom)
};

class BreakpointFigures final : public SystemFigures {
public:
    std::string html(FigurePage& page, const FigureContext& where, const CaseResult& result) const override;

    double target_flow_l_min = kNotMeasured;  // NaN: no flow control in this case
    double breakpoint_along_m = 0.0;
    // Where the controller opened the sections (distance to breakpoint, m) ...
    std::optional<double> section_open_command_distance_m;
    // ... and when (s). Without it the time is interpolated from the flow samples'
    // distances; without either, the flow-time panel counts from the first sample.
    std::optional<double> section_open_command_t_s;
    std::vector<FlowSample> flow;
    std::vector<DoseSample> dose;
    // Stretches of track the judge classified: "operational", "repeated",
    // "continuation" or "missed" (other names are drawn in grey).
    std::vector<AreaSpan> areas;
};

}  // namespace rig::harness
