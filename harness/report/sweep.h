#pragma once
// `rig sweep CASE... --seeds N` (issue 15, Monte Carlo): each case run once per
// seed, and every metric's spread over the seeds against its limit and the
// paper's number. A single seed says whether a controller passed once; the
// band says how much of a limit is margin and how much is luck, and whether
// the paper's number lies where the rig puts its runs.
//
// Percentiles interpolate linearly between order statistics (Hyndman and Fan's
// type 7, numpy's and R's default): with 100 seeds p95 lies between the 95th
// and 96th smallest values; with 20 it is no better than the second largest.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/run/case_runner.h"
#include "harness/spec/case_spec.h"
#include "harness/report/results_writer.h"

namespace rig::harness {

// The p-th percentile (p in [0, 100]) of values sorted ascending; NaN when empty.
double percentile_of_sorted(const std::vector<double>& sorted, double p);

// One metric of one case over every seed of the sweep.
struct MetricBand {
    std::string metric;
    std::size_t measured = 0;      // runs that gave a value
    std::size_t not_measured = 0;  // runs that gave none (what the controller did, or the run ended early)
    // Over the measured runs; NaN when none was.
    double min = 0.0, p5 = 0.0, p50 = 0.0, p95 = 0.0, max = 0.0, mean = 0.0;
    std::optional<double> limit;  // the effective limit (an upper bound), if the case has one
    // Runs that broke the limit: measured above it, or limited and not measured.
    std::size_t over_limit = 0;
    std::optional<double> paper;  // the case file's `paper:` value for this metric
};

// One case file over every seed of the sweep.
struct CaseSweep {
    std::string name;
    std::string file;
    std::string paper_source;
    std::size_t runs = 0;
    std::size_t passed = 0;   // verdict pass (a negative case's expected failure counts as a pass)
    std::size_t invalid = 0;  // the rig could not judge (real time only: cannot happen in a sweep)
    std::size_t errors = 0;   // runs that ended early with an error the case does not expect
    std::vector<std::uint64_t> failed_seeds;  // seeds whose run did not pass, ascending
    std::vector<MetricBand> bands;            // every metric any run gave, or limited, or in `paper:`, by name
    // Paper values for metrics no run gave (a paper number the rig does not measure here).
    std::vector<std::string> paper_unmatched;
};

// Groups the runs (results[i] is the run runs[i] of specs[runs[i].spec_index])
// by case file, in the order of specs.
std::vector<CaseSweep> summarize_sweep(const std::vector<CaseSpec>& specs, const std::vector<CaseInstance>& runs,
                                       const std::vector<CaseResult>& results);

struct SweepInfo {
    std::vector<std::uint64_t> seeds;
    std::string started_utc;
    double wall_seconds = 0.0;
    double sim_seconds = 0.0;     // summed over runs
    std::string keep_traces;      // "failed", "all" or "none"
    std::string controller_mode;  // "process" or "in_process" as asked (results.json per run says what ran)
};

// A table for the terminal: per case the pass rate, then per metric
// p5 / p50 / p95 / max against the limit and the paper.
std::string sweep_table(const std::vector<CaseSweep>& cases, const SweepInfo& info);
// sweep.json: the bands, and every run's seed, verdict, metrics and failures.
nlohmann::json sweep_json(const std::vector<CaseSweep>& cases, const std::vector<CaseInstance>& runs,
                          const std::vector<CaseResult>& results, const SweepInfo& info);
// sweep.html: one self-contained page (inline SVG, no script): per case a
// band per metric (p5-p95 box, p50 tick, min-max whisker), the limit as a red
// line and the paper's number as a black diamond.
std::string sweep_html(const std::vector<CaseSweep>& cases, const SweepInfo& info);

}  // namespace rig::harness
