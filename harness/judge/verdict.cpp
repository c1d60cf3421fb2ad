#include "harness/judge/verdict.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string_view>

#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

constexpr std::string_view kMissingSuffix = " missing";

// The metric a judge() failure is about: the text before its first space.
std::string failure_metric(const std::string& failure) { return failure.substr(0, failure.find(' ')); }

bool is_missing_failure(const std::string& failure) { return failure.ends_with(kMissingSuffix); }

}  // namespace

std::vector<std::string> judge(const std::map<std::string, double>& metrics,
                               const std::map<std::string, double>& limits) {
    return judge(metrics, {}, limits);
}

std::vector<std::string> judge(const std::map<std::string, double>& metrics,
                               const std::map<std::string, std::string>& not_measured,
                               const std::map<std::string, double>& limits) {
    std::vector<std::string> failures;
    for (const auto& [name, limit] : limits) {
        const auto metric = metrics.find(name);
        if (metric == metrics.end() || std::isnan(metric->second)) {
            if (const auto why = not_measured.find(name); why != not_measured.end()) {
                failures.push_back(name + " not measured: " + why->second);
            } else {
                failures.push_back(name + std::string(kMissingSuffix));
            }
        } else if (std::isnan(limit)) {
            // Case files cannot say this; a harness bug must not pass silently.
            failures.push_back(name + ' ' + significant_text(metric->second, 6) + " > nan (limit is not a number)");
        } else if (metric->second > limit) {
            failures.push_back(name + ' ' + significant_text_against(metric->second, limit, 6) + " > " +
                               significant_text_against(limit, metric->second, 6));
        }
    }
    return failures;
}

bool passes_with_expectation(const std::vector<std::string>& failures, const std::vector<std::string>& expect_fail) {
    return unmet_expectations(failures, expect_fail).empty();
}

std::vector<std::string> unmet_expectations(const std::vector<std::string>& failures,
                                            const std::vector<std::string>& expect_fail) {
    if (expect_fail.empty()) return failures;
    const std::set<std::string> expected(expect_fail.begin(), expect_fail.end());
    std::set<std::string> broken;
    std::vector<std::string> reasons;
    for (const std::string& failure : failures) {
        const std::string metric = failure_metric(failure);
        if (expected.contains(metric) && !is_missing_failure(failure)) {
            broken.insert(metric);
        } else {
            reasons.push_back(failure + (expected.contains(metric) ? " (expected a limit break)" : " (not expected)"));
        }
    }
    for (const std::string& metric : expected) {
        if (broken.contains(metric)) continue;
        const bool missing = std::any_of(failures.begin(), failures.end(), [&](const std::string& failure) {
            return failure_metric(failure) == metric;
        });
        if (!missing) reasons.push_back("expected " + metric + " to break its limit, but it held");
    }
    return reasons;
}

CaseVerdict judge_case(const std::map<std::string, double>& metrics, const std::map<std::string, double>& limits,
                       const std::vector<std::string>& expect_fail) {
    CaseVerdict verdict;
    verdict.expected_failure = !expect_fail.empty();
    verdict.failures = judge(metrics, limits);
    verdict.passed = passes_with_expectation(verdict.failures, expect_fail);
    if (verdict.expected_failure && !verdict.passed) {
        // The limit breaks alone would not say why a negative case failed.
        for (std::string& reason : unmet_expectations(verdict.failures, expect_fail)) {
            if (reason.starts_with("expected ")) verdict.failures.push_back(std::move(reason));
        }
    }
    return verdict;
}

CaseVerdict judge_case(const VerdictInputs& inputs) {
    if (inputs.error_kind.empty()) {
        CaseVerdict verdict;
        if (!inputs.expect_error.empty()) {
            verdict.expected_failure = true;
            verdict.failures = judge(inputs.metrics, inputs.not_measured, inputs.limits);
            verdict.failures.push_back("expected the run to end in " + inputs.expect_error +
                                       ", but it ran to its end");
            verdict.passed = false;
            return verdict;
        }
        const bool expects_breaks = !inputs.expect_fail.empty();
        verdict.expected_failure = expects_breaks;
        verdict.failures = judge(inputs.metrics, inputs.not_measured, inputs.limits);
        verdict.passed = passes_with_expectation(verdict.failures, inputs.expect_fail);
        if (expects_breaks && !verdict.passed) {
            for (std::string& reason : unmet_expectations(verdict.failures, inputs.expect_fail)) {
                if (reason.starts_with("expected ")) verdict.failures.push_back(std::move(reason));
            }
        }
        return verdict;
    }
    CaseVerdict verdict;
    verdict.expected_failure = !inputs.expect_error.empty();
    verdict.failures.push_back("error: " + inputs.error_kind + ": " + inputs.error);
    if (inputs.expect_error == inputs.error_kind) {
        verdict.passed = true;
    } else if (!inputs.expect_error.empty()) {
        verdict.failures.push_back("expected the run to end in " + inputs.expect_error + ", got " + inputs.error_kind);
    }
    return verdict;
}

bool case_passed(const CaseResult& result) {
    // An error fails a case, unless the case exists to show that exact error.
    if (!result.error.empty()) return result.passed && !result.expected_error.empty() &&
                                      result.expected_error == result.error_kind;
    return result.passed;
}

bool case_invalid(const CaseResult& result) {
    return result.error_kind == "rig_overloaded" && !case_passed(result);
}

std::string verdict_word(const CaseResult& result) {
    if (case_invalid(result)) return "INVALID";
    if (!case_passed(result)) return "FAIL";
    return result.expected_failure ? "XFAIL-OK" : "PASS";
}

}  // namespace rig::harness
