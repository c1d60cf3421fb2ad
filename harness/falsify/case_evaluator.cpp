#include "harness/falsify/case_evaluator.h"

#include <exception>
#include <mutex>

#include "harness/run/run_interrupt.h"
#include "harness/systems/systems.h"

namespace rig::harness {

namespace {

// Says nothing (the command prints a line per point), and removes each run's
// trace once judged: a search of hundreds of runs keeps their numbers.
class TraceRemover final : public RunObserver {
public:
    void runs_planned(const std::vector<CaseInstance>&, const std::vector<CaseSpec>&) override {}
    void case_started(std::size_t) override {}
    void case_finished(std::size_t, const CaseResult& result) override {
        if (result.trace_path.empty()) return;
        std::error_code ignored;
        std::filesystem::remove(result.trace_path, ignored);
    }
    CaseClock* case_clock(std::size_t) override { return nullptr; }
};

std::string point_number(std::size_t index) {
    std::string digits = std::to_string(index + 1);
    return std::string(digits.size() < 4 ? 4 - digits.size() : 0, '0') + digits;
}

}  // namespace

std::vector<std::uint64_t> search_seeds(const CaseSpec& base, std::uint64_t count) {
    if (count == 0) return base.seeds.empty() ? std::vector<std::uint64_t>{base.seed} : base.seeds;
    std::vector<std::uint64_t> seeds;
    for (std::uint64_t k = 0; k < count; ++k) seeds.push_back(base.seed + k);
    return seeds;
}

CaseEvaluator::CaseEvaluator(FalsifyCase search_case, RunOptions options, const std::string& run_name_stem)
    : case_(std::move(search_case)), options_(std::move(options)), stem_(run_name_stem) {
    options_.seed_sweep = case_.seeds;
    options_.keep_figures = false;
}

bool CaseEvaluator::stopped() const { return run_interrupt_signal() != 0; }

std::vector<RunMargin> CaseEvaluator::evaluate(const std::vector<std::vector<double>>& points) {
    const std::size_t first = points_.size();
    std::vector<CaseSpec> specs;
    std::vector<std::size_t> spec_of_point(points.size(), points.size());
    for (std::size_t index = 0; index < points.size(); ++index) {
        PointRuns point;
        point.settings = point_settings(case_.settings, case_.ranges, points[index]);
        try {
            CaseSpec spec = load_case_file(case_.file, point.settings);
            validate_for_run(spec, options_);
            // Each point's runs under a name of their own (cases/NAME-pNNNN-seedS/).
            spec.name = stem_ + "-p" + point_number(first + index);
            spec_of_point[index] = specs.size();
            specs.push_back(std::move(spec));
        } catch (const std::exception& error) {
            point.invalid = error.what();
        }
        points_.push_back(std::move(point));
    }
    TraceRemover observer;
    const std::vector<CaseRun> runs = specs.empty() ? std::vector<CaseRun>{} : run_cases(specs, options_, observer);
    // run_cases gives the runs case by case, each case's seeds in order.
    const std::size_t seeds = case_.seeds.size();
    std::vector<RunMargin> margins;
    for (std::size_t index = 0; index < points.size(); ++index) {
        PointRuns& point = points_[first + index];
        if (!point.invalid.empty()) {
            RunMargin invalid;
            invalid.invalid = "not a valid case: " + point.invalid;
            margins.push_back(invalid);
            continue;
        }
        for (std::size_t seed = 0; seed < seeds; ++seed) {
            const CaseResult& result = runs.at(spec_of_point[index] * seeds + seed).result;
            point.runs.push_back(result);
            point.margins.push_back(run_margin(result, case_.metrics));
        }
        margins.push_back(worst_margin(point.margins));
    }
    return margins;
}

}  // namespace rig::harness
