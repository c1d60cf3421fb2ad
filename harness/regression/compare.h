#pragma once
// `rig compare BASE HEAD`: did this controller change make a metric worse
// (docs/regression.md)? Two outputs of `rig run` or `rig sweep`, case by case
// and metric by metric:
//   - one run a side at the same seed: a lockstep run is deterministic, so
//     equal trace digests are the same behaviour and any difference is real;
//     a metric that moved the worse way by at least its minimum effect regressed;
//   - many seeds a side: the U test per case and metric, Holm's correction
//     over every test of the comparison, and the Hodges-Lehmann shift: a
//     metric regressed when the shift is the worse way, significant at alpha
//     after the correction, and at least its minimum effect.
// Which way is worse and the default minimum effect come from the metric's
// declaration (harness/judge/metric_direction.h).
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "harness/judge/metric_direction.h"
#include "harness/regression/rank_statistics.h"
#include "harness/regression/run_samples.h"

namespace rig::harness {

enum class CompareVerdict { regressed, improved, unchanged, not_comparable };
std::string_view compare_verdict_name(CompareVerdict verdict);

struct CompareSettings {
    double alpha = 0.01;
    // Minimum effects from the command line (--min-effect METRIC=SHIFT): over
    // the case file's and the declared ones.
    std::map<std::string, double> min_effects;
    // Sweeps over different seed sets are compared as independent samples
    // (--any-seeds); by default a comparison wants the same seeds on both sides.
    bool any_seeds = false;
};

// One side of a metric: its values over the seeds that measured it.
struct MetricSide {
    std::size_t runs = 0;
    std::size_t measured = 0;
    std::vector<double> values;         // the measured values, by seed
    std::optional<double> median;       // of the measured values
    std::optional<double> min, max;     // of the measured values
    std::string not_measured_reason;    // the first run's reason, when some run gave none
};

struct MetricComparison {
    std::string metric;
    WorseDirection worse = WorseDirection::none;
    bool declared = false;
    double min_effect = 0.0;
    std::string min_effect_from;  // "declared", "case file" or "command line"
    std::optional<double> limit;  // the head's (an upper bound)
    MetricSide base, head;
    // One run a side: head - base; many: the Hodges-Lehmann shift (of |value|
    // for a signed error) with its interval at 1 - alpha.
    std::optional<double> difference;
    std::optional<double> ratio;           // head / base (medians); none when base is 0
    std::optional<double> shift_low, shift_high;
    std::optional<double> p_value;         // two-sided U test, before correction
    std::optional<double> p_adjusted;      // after Holm's correction over the comparison
    std::optional<double> head_of_limit;   // head (median) / limit
    CompareVerdict verdict = CompareVerdict::unchanged;
    std::string reason;
};

struct CaseComparison {
    std::string name;
    std::string base_file, head_file;
    std::string method;  // "exact" (one run a side at one seed) or "u_test" (many seeds)
    std::vector<std::uint64_t> base_seeds, head_seeds;
    // Runs at a seed both sides ran whose traces are the same, bit for bit, of those seeds.
    std::size_t same_traces = 0, paired_seeds = 0;
    // What differs between the sides' runs: "case", "controller", "controller configuration".
    std::vector<std::string> changed;
    CompareVerdict verdict = CompareVerdict::unchanged;
    std::string reason;
    std::vector<MetricComparison> metrics;
};

struct Comparison {
    std::string base_source, head_source, base_kind, head_kind;
    std::string base_rig, head_rig;  // "version (commit)"
    bool rig_differs = false;
    CompareSettings settings;
    std::size_t tests = 0;  // U tests in Holm's family
    std::vector<CaseComparison> cases;
    std::map<CompareVerdict, std::size_t> metric_counts;  // metric verdicts, over every case
    std::map<CompareVerdict, std::size_t> case_counts;
    std::size_t regressions() const;
};

Comparison compare_runs(const RunSamples& base, const RunSamples& head, const CompareSettings& settings);

}  // namespace rig::harness
