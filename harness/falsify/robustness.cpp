#include "harness/falsify/robustness.h"

#include <cmath>
#include <optional>

#include "rig/runtime/failure_kind.h"

namespace rig::harness {

namespace {

// Errors that are the rig's, not the controller's: the run says nothing of
// the controller at this point (rig/runtime/failure_kind.h).
bool rig_error(const std::string& kind) {
    const std::optional<rig::FailureKind> known = rig::failure_kind_from_string(kind);
    return known && rig::is_rigs_own_failure(*known);
}

}  // namespace

double limit_margin(double value, double limit) {
    const double scale = limit == 0.0 ? 1.0 : std::fabs(limit);
    return (limit - value) / scale;
}

bool margin_counts(double value, double limit) { return !(limit == 0.0 && value == 0.0); }

RunMargin run_margin(const CaseResult& result, const std::vector<std::string>& metrics) {
    RunMargin run;
    bool held_on_zero_limit = false;
    if (!result.error.empty()) {
        if (rig_error(result.error_kind)) {
            run.invalid = result.error_kind + ": " + result.error;
        } else {
            run.broken = "the run ended in " + result.error_kind + ": " + result.error;
        }
        return run;
    }
    for (const std::string& metric : metrics) {
        const auto limit = result.limits.find(metric);
        if (limit == result.limits.end() || !std::isfinite(limit->second)) {
            run.invalid = metric + " has no limit in this case";
            return run;
        }
        if (const auto why = result.not_measured.find(metric); why != result.not_measured.end()) {
            if (run.broken.empty()) {
                run.broken = metric + " not measured: " + why->second;
                run.limiting_metric = metric;
            }
            continue;
        }
        const auto value = result.metrics.find(metric);
        if (value == result.metrics.end() || !std::isfinite(value->second)) {
            if (run.broken.empty()) {
                run.broken = metric + " missing";
                run.limiting_metric = metric;
            }
            continue;
        }
        if (!margin_counts(value->second, limit->second)) {
            held_on_zero_limit = true;
            continue;
        }
        const double margin = limit_margin(value->second, limit->second);
        if (!run.margin || margin < *run.margin) {
            run.margin = margin;
            if (run.broken.empty()) run.limiting_metric = metric;
        }
    }
    // A break without a number is worse than any margin: the run has none.
    if (!run.broken.empty()) run.margin.reset();
    // Every metric asked for held on a zero limit: the run is on its limits.
    if (run.broken.empty() && !run.margin && held_on_zero_limit) run.margin = 0.0;
    return run;
}

RunMargin worst_margin(const std::vector<RunMargin>& runs) {
    RunMargin worst;
    for (const RunMargin& run : runs) {
        if (!run.invalid.empty()) return run;
    }
    for (const RunMargin& run : runs) {
        if (!run.broken.empty()) return run;
    }
    for (const RunMargin& run : runs) {
        if (run.margin && (!worst.margin || *run.margin < *worst.margin)) worst = run;
    }
    return worst;
}

std::vector<std::string> limited_metrics(const std::map<std::string, double>& limits) {
    std::vector<std::string> metrics;
    for (const auto& [name, limit] : limits) {
        if (std::isfinite(limit)) metrics.push_back(name);
    }
    return metrics;
}

}  // namespace rig::harness
