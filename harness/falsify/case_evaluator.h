#pragma once
// The points of a search run as cases (issue 30): the base case file with
// each point's values set (harness/spec/case_settings.h), read and checked
// by the loader, run through the machinery of `rig run` and `rig sweep`
// (harness/run/case_runner.h run_cases: `jobs` runs at once, in process with
// --in-process) on each of the search's seeds, judged from the plant's truth,
// and each run's margin taken (harness/falsify/robustness.h).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "harness/falsify/falsify_search.h"
#include "harness/judge/case_result.h"
#include "harness/run/case_runner.h"

namespace rig::harness {

struct FalsifyCase {
    std::filesystem::path file;        // the base case
    std::vector<KeySetting> settings;  // --set on the base case
    std::vector<VaryRange> ranges;
    std::vector<std::string> metrics;  // judged (each limited in the case)
    std::vector<std::uint64_t> seeds;  // every point runs on each
};

// What the runs of one point gave.
struct PointRuns {
    std::vector<KeySetting> settings;  // the base's and the point's
    std::vector<CaseResult> runs;      // one per seed, in the order of FalsifyCase::seeds
    std::vector<RunMargin> margins;    // of each run
    std::string invalid;               // the case at this point is not a valid case: why (nothing ran)
};

class CaseEvaluator final : public PointEvaluator {
public:
    // `options`: how the runs run (jobs, in process, controller files); their
    // traces go under options.out_dir and are removed once judged (a search
    // keeps each run's digest, and worst.yaml reruns the worst one).
    CaseEvaluator(FalsifyCase search_case, RunOptions options, const std::string& run_name_stem);
    std::vector<RunMargin> evaluate(const std::vector<std::vector<double>>& points) override;
    // After SIGINT / SIGTERM (harness/run/run_interrupt.h).
    bool stopped() const override;
    // Every point evaluated, in order.
    const std::vector<PointRuns>& points() const { return points_; }

private:
    FalsifyCase case_;
    RunOptions options_;
    std::string stem_;
    std::vector<PointRuns> points_;
};

// The seeds a search runs on: `count` from the case's own seed on (1: its own
// seed; a case with `seeds:` and no count: its list).
std::vector<std::uint64_t> search_seeds(const CaseSpec& base, std::uint64_t count);

}  // namespace rig::harness
