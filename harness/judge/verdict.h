#pragma once
// The verdict: metrics against limits, and the case's expectations
// (docs/metrics.md "Verdicts"). Pure functions of plain data.
#include <map>
#include <string>
#include <vector>

#include "harness/judge/case_result.h"

namespace rig::harness {

// One failure per limited metric that is over its limit ("overlap_m 3.61 > 3.3";
// equal to the limit passes) or that is missing or NaN ("breakpoint_error_m
// missing"), in metric-name order. Numbers are printed with just enough digits
// that value and limit differ on screen. Unlimited metrics are never failures.
std::vector<std::string> judge(const std::map<std::string, double>& metrics,
                               const std::map<std::string, double>& limits);
// The same, where a limited metric in `not_measured` fails as
// "flow_adjust_time_s not measured: never settled ..." (a break a case may
// expect) instead of "missing" (the harness did not measure it).
std::vector<std::string> judge(const std::map<std::string, double>& metrics,
                               const std::map<std::string, std::string>& not_measured,
                               const std::map<std::string, double>& limits);

// Without expectations: passes when nothing failed. With expect.fail: passes
// only when exactly those metrics broke their limits (a missing metric never
// counts as an expected break: it means the harness did not measure it).
bool passes_with_expectation(const std::vector<std::string>& failures, const std::vector<std::string>& expect_fail);

// Why passes_with_expectation() said no, one line per reason; empty when it passes.
std::vector<std::string> unmet_expectations(const std::vector<std::string>& failures,
                                            const std::vector<std::string>& expect_fail);

struct CaseVerdict {
    bool passed = false;
    bool expected_failure = false;
    // judge()'s failures, then any unmet expectations: what CaseResult::failures should hold.
    std::vector<std::string> failures;
};
CaseVerdict judge_case(const std::map<std::string, double>& metrics, const std::map<std::string, double>& limits,
                       const std::vector<std::string>& expect_fail);

// The whole verdict of a case: metrics (with what was not measured) against
// limits and expect.fail when the run went to its end; when it ended in an
// error, only whether that error is the one expect.error names. An errored
// case's metrics (from its partial trace) are reported, never judged.
struct VerdictInputs {
    std::map<std::string, double> metrics;
    std::map<std::string, std::string> not_measured;
    std::map<std::string, double> limits;
    std::vector<std::string> expect_fail;
    std::string expect_error;  // FailureKind name, or empty
    std::string error_kind;    // of the run, or empty when it went to its end
    std::string error;         // its text
};
CaseVerdict judge_case(const VerdictInputs& inputs);

// A case counts as passed only when `passed` is set and there is no error.
bool case_passed(const CaseResult& result);
// A case whose run cannot judge the controller: the rig's own lateness passed
// the case's bound (error_kind rig_overloaded), and the case did not expect it.
// Counted apart from passed and failed; `rig run` exits 3 when the rest passed.
bool case_invalid(const CaseResult& result);

// The verdict as one word: PASS, FAIL, XFAIL-OK (a negative case that broke
// exactly what it expects) or INVALID (case_invalid).
std::string verdict_word(const CaseResult& result);

}  // namespace rig::harness
