#pragma once
// The metrics in Bencher's Metric Format (BMF, bencher.dev "Bencher Metric
// Format"): a JSON object of benchmarks, each an object of measures, each
// {"value", "lower_value", "upper_value"}; what `bencher run --adapter json`
// reads. Here a benchmark is a case and a measure is one of its metrics: the
// value is the median over the case's runs (the one run's value for a single
// run), the bounds the smallest and largest run. A metric no run measured is
// left out (BMF has no "not measured"); docs/regression.md says so.
#include <nlohmann/json.hpp>

#include "harness/regression/run_samples.h"

namespace rig::harness {

nlohmann::json bencher_metric_format(const RunSamples& samples);

}  // namespace rig::harness
