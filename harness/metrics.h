#pragma once
// Metrics computed from truth (DESIGN.md "What the harness measures"). Only the
// harness computes metrics; the controller never sees truth. Each family is a
// pure function of plain data, so tests can hand it a truth trace with a known
// answer; harness/case_runner.cpp extracts that data from the recorded trace
// and the plant.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "emulators/plant.h"
#include "harness/trace_recorder.h"
#include "rig/clock.h"

namespace rig::harness {

// ---------------------------------------------------------------- breakpoint identification

// Breakpoint identification (seed 000 sec. 2.5.1, Tables 3-4):
//   breakpoint_error_m         |nozzle line - true breakpoint| when the controller
//                              declares "reached" (the paper's distance from the mark)
//   breakpoint_error_signed_m  + = declared after the nozzle line passed it
//   breakpoint_store_error_m   how far the stored breakpoint lies from the true one
//   breakpoint_reached_count   number of "reached" events (1 expected)
// A metric the run could not produce (no "reached" event) is absent: the judge
// then reports it as missing, which fails a limit on it.
std::map<std::string, double> breakpoint_metrics(const TraceRecorder& trace, const emulators::Plant& plant,
                                                 double breakpoint_along_m);

// ---------------------------------------------------------------- flow control

struct MainFlowSample {
    TimeNs t_ns = 0;
    double main_flow_l_min = 0.0;  // truth
};

// The regulation episode to judge: from the section-open command to the next
// close command (or the end of the run).
struct FlowEpisode {
    TimeNs open_command_ns = 0;
    TimeNs end_ns = 0;
};

// DESIGN.md: flow adjust time = from the section-valve open command until the
// main flow enters +-band_pct of the target and stays there (to the episode's
// end); flow error = mean |Q - target| / target after settling. When the flow
// never settles, flow_adjust_time_s is the episode's length (a lower bound, over
// any sane limit) and the error is taken after open + never_settled_after_s.
//   flow_adjust_time_s, flow_error_pct, flow_mean_l_min (after settling),
//   flow_settled (1 or 0)
std::map<std::string, double> flow_metrics(const std::vector<MainFlowSample>& samples, const FlowEpisode& episode,
                                           double target_l_min, double band_pct = 3.0,
                                           double never_settled_after_s = 1.7);

// ---------------------------------------------------------------- deposition

// Dose per row along the track, one vector per pass (same rows), uL/cm^2 averaged
// across the boom (emulators/deposition_grid.h).
struct DoseProfile {
    double first_row_centre_m = 0.0;
    double row_m = 0.05;
    std::vector<double> first_pass;
    std::vector<double> continuation;
    double row_centre_m(std::size_t row) const { return first_row_centre_m + static_cast<double>(row) * row_m; }
};

struct DepositionJudging {
    double nominal_dose_ul_cm2 = 0.0;   // target flow / (cruise speed x boom width)
    double sprayed_fraction = 0.5;      // a row is sprayed at or above this share of nominal
    double cv_row_m = 0.3;              // rows of Eq. 10-12
    double cv_window_m = 6.0;
};

// A stretch of the track, for the CV areas and the report's shading.
struct AreaSpan {
    std::string name;  // operational, repeated, continuation, missed
    double from_along_m = 0.0;
    double to_along_m = 0.0;
};

struct DepositionResult {
    std::map<std::string, double> metrics;
    std::vector<AreaSpan> areas;
};

// overlap_m: along-track length sprayed by both passes; missed_m: length between
// the first and the last sprayed row sprayed by neither. cv_*_pct: Eq. 10-12 over
// the operational area (first pass only, up to cv_window_m before the repeated
// one), the repeated area, and the continuation area (second pass only, cv_window_m
// after it), the outer two cut at the first and last sprayed row;
// repeated_from_m / repeated_to_m relative to the breakpoint.
DepositionResult deposition_metrics(const DoseProfile& profile, const DepositionJudging& judging,
                                    double breakpoint_along_m);

// Eq. 9-12 of seed 000 on row sums x_i: CV = S / mean with S = sqrt(sum (x_i - mean)^2 / n).
double coefficient_of_variation_pct(const std::vector<double>& rows);

}  // namespace rig::harness
