#pragma once
// The robustness margin of a run (issue 30): how far each judged metric is
// from its limit, scaled by the limit, negative when the limit is broken.
//
// A limit is the largest value the judge allows (harness/judge/verdict.h: a
// metric over its limit fails, equal passes; harness/judge/metric_direction.h:
// every limited metric is worse upwards), so a metric's margin is
//   (limit - value) / |limit|,
// 0.1 meaning 10 % of the limit to spare and -0.05 a limit broken by 5 % of
// itself. A limit of 0 (nothing missed) has no scale: a metric over it
// breaks it by its value in its own unit (-0.4 for 0.4 m missed), and one on
// it (nothing missed) says nothing of how near the point is to breaking, so
// it does not enter the minimum (else every passing point of a case with
// such a limit would have margin 0, and a search nothing to follow).
// The run's margin is the smallest over the metrics asked for; a point's, the
// smallest over its seeds. A margin is never made up: a run whose asked
// metric was not measured, or that the controller ended early, has none and
// is broken; a run the rig could not judge (its own error) is invalid.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "harness/judge/case_result.h"

namespace rig::harness {

// (limit - value) / |limit| (or / 1 for a zero limit).
double limit_margin(double value, double limit);
// Whether the metric's margin enters a run's minimum: not a metric on a zero limit.
bool margin_counts(double value, double limit);

struct RunMargin {
    std::optional<double> margin;  // none when broken without a number, or invalid
    std::string limiting_metric;   // the metric the margin (or the break) is of
    std::string broken;            // non-empty: the limit is broken without a margin (why)
    std::string invalid;           // non-empty: the rig could not judge the run (why)
    // The run broke a limit: a margin below 0, or broken.
    bool falsifying() const { return broken.empty() == false || (margin && *margin < 0.0); }
};

// Of one run, over `metrics` (each must have a limit in the result; a metric
// without one is reported as invalid).
RunMargin run_margin(const CaseResult& result, const std::vector<std::string>& metrics);

// The worst of a point's runs: an invalid run makes the point invalid; else a
// broken one makes it broken; else the smallest margin.
RunMargin worst_margin(const std::vector<RunMargin>& runs);

// The metrics a search judges by default: every metric with a finite limit.
std::vector<std::string> limited_metrics(const std::map<std::string, double>& limits);

}  // namespace rig::harness
