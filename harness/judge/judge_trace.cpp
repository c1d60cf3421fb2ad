#include "harness/judge/judge_trace.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <stdexcept>
#include <utility>

#include "harness/judge/verdict.h"
#include "harness/trace/run_facts.h"
#include "harness/trace/topic_roles.h"
#include "rig/runtime/failure_kind.h"

namespace rig::harness {

// ---------------------------------------------------------------- the plan

void add_to_json(const JudgingPlan& plan, nlohmann::json& json) {
    json["scenario"] = plan.scenario;
    json["limits"] = plan.limits;
    json["expect"] = {{"fail", plan.expect_fail}, {"error", plan.expect_error}, {"set_aside", plan.expect_set_aside}};
    if (!plan.min_effects.empty()) json["min_effects"] = plan.min_effects;
}

const nlohmann::json& plan_key(const nlohmann::json& node, const std::string& key, const std::string& path) {
    if (!node.is_object() || !node.contains(key)) throw std::runtime_error("judging plan: no key " + path + key);
    return node.at(key);
}

JudgingPlan judging_plan_from_json(const nlohmann::json& json) {
    const auto& at = plan_key;
    try {
        JudgingPlan plan;
        plan.scenario = at(json, "scenario", "").get<std::string>();
        plan.limits = at(json, "limits", "").get<std::map<std::string, double>>();
        const nlohmann::json& expect = at(json, "expect", "");
        plan.expect_fail = at(expect, "fail", "expect.").get<std::vector<std::string>>();
        plan.expect_error = at(expect, "error", "expect.").get<std::string>();
        // Traces from before expectations could be set aside have no reason.
        if (expect.contains("set_aside")) plan.expect_set_aside = at(expect, "set_aside", "expect.").get<std::string>();
        if (json.contains("min_effects")) plan.min_effects = json.at("min_effects").get<std::map<std::string, double>>();
        return plan;
    } catch (const nlohmann::json::exception& error) {
        throw std::runtime_error(std::string("judging plan: ") + error.what());
    }
}

// ---------------------------------------------------------------- judging

namespace {

// The first role broken in the trace: an endpoint discovery saw, or a forged sample.
std::optional<std::pair<std::string, std::string>> first_role_violation(const RecordedTrace& trace) {
    for (const RecordedDiscovery& endpoint : trace.discovery) {
        if (endpoint.event != "discovered") continue;
        if (const auto why = topic_role_violation(endpoint.endpoint, endpoint.topic)) {
            return std::make_pair(endpoint.participant, *why + " (participant '" + endpoint.participant + "', GUID prefix " +
                                                            endpoint.guid_prefix + ", seen by discovery)");
        }
    }
    if (!trace.foreign_samples.empty()) {
        const RecordedForeignSample& first = trace.foreign_samples.front();
        const auto count = std::count_if(trace.foreign_samples.begin(), trace.foreign_samples.end(),
                                         [&](const auto& sample) { return sample.topic == first.topic; });
        return std::make_pair(first.participant, "wrote " + std::to_string(count) + " sample(s) on " + first.topic +
                                                     " (participant '" + first.participant +
                                                     "'): forged data, never judged as truth");
    }
    return std::nullopt;
}

void read_run_facts(const RecordedTrace& trace, CaseResult& result, CaseFigures& figures) {
    const std::string text = trace.meta_or("run");
    if (text.empty()) return;
    RunFacts facts;
    try {
        facts = run_facts_from_json(nlohmann::json::parse(text));
    } catch (const std::exception& error) {
        throw std::runtime_error("trace " + trace.file.string() + ": meta run: " + error.what());
    }
    result.wall_seconds = facts.wall_seconds;
    result.startup_wall_seconds = facts.startup_wall_seconds;
    result.instants = facts.instants;
    result.rounds = facts.rounds;
    result.stepping_wall_seconds = facts.stepping_wall_seconds;
    result.controller_mode = facts.controller_mode;
    result.in_process_refused = facts.in_process_refused;
    result.realtime_scheduling = facts.realtime_scheduling;
    if (!facts.board_io.is_null()) result.board_io = facts.board_io;
    if (!facts.lateness.is_null()) result.rig_lateness = facts.lateness;
    for (const EmissionJitter& jitter : facts.emission_jitter) {
        result.emission_jitter.push_back(jitter);
        figures.jitter.push_back(JitterRow{jitter.device, jitter.p50_ms, jitter.p99_ms, jitter.max_ms, jitter.step_max_ms});
    }
}

// A real-time run whose own emissions passed the case's lateness bound cannot
// judge the controller: its verdict is invalid (rig_overloaded), whatever the
// controller did, unless the run already ended in something the lateness does
// not explain (a stop signal, the rig's own error, a broken topic role, a
// malformed actuator command: late inputs change a command's timing, never
// its shape).
void apply_rig_overload(CaseResult& result) {
    if (!result.rig_lateness.is_object()) return;
    const std::string overloaded = result.rig_lateness.value("overloaded", std::string());
    if (overloaded.empty()) return;
    for (const char* kept : {"interrupted", "harness_error", "topic_role_violation", "malformed_command"}) {
        if (result.error_kind == kept) return;
    }
    std::string error = "the rig was overloaded: " + overloaded +
                        "; the run cannot judge the controller (its metrics are reported, not judged)";
    if (!result.error.empty()) error += "; the run also ended in " + result.error_kind + ": " + result.error;
    result.error_kind = std::string(to_string(FailureKind::rig_overloaded));
    result.error = std::move(error);
}

}  // namespace

CaseRun judge_trace(const RecordedTrace& trace, const SystemJudge& system) {
    CaseRun run;
    CaseResult& result = run.result;
    CaseFigures& figures = run.figures;
    result.name = trace.meta_or("case", trace.file.parent_path().filename().string());
    result.file = trace.meta_or("case_file");
    result.case_name = trace.meta_or("case_name");
    result.mode = trace.meta_or("mode", "lockstep");
    result.wiring = trace.meta_or("wiring");
    result.trace_sha256 = trace.meta_or("trace_sha256");
    result.trace_path = trace.file.string();
    result.case_sha256 = trace.meta_or("case_sha256");
    result.controller_sha256 = trace.meta_or("controller_sha256");
    result.controller_config_sha256 = trace.meta_or("controller_config_sha256");
    try {
        const nlohmann::json settings = nlohmann::json::parse(trace.meta_or("case_settings", "{}"));
        for (const auto& [key, value] : settings.items()) result.settings[key] = value.get<std::string>();
    } catch (const nlohmann::json::exception&) {
        result.error_kind = "harness_error";
        result.error = "trace " + trace.file.string() + ": meta case_settings is not an object of texts";
    }
    try {
        result.seed = std::stoull(trace.meta_or("seed", "0"));
        result.sim_seconds = ns_to_seconds(std::stoll(trace.meta_or("end_ns", "0")));
    } catch (const std::exception&) {
        result.error_kind = "harness_error";
        result.error = "trace " + trace.file.string() + ": meta seed or end_ns is not a number";
    }
    // The rows must be those the run wrote: a trace edited afterwards is not judged as the run's.
    const std::string recorded_sha256 = trace.meta_or("trace_sha256");
    if (!recorded_sha256.empty() && recorded_sha256 != trace.recomputed_sha256) {
        result.error_kind = "harness_error";
        result.error = "trace " + trace.file.string() + ": its rows give digest " + trace.recomputed_sha256 +
                       ", not the " + recorded_sha256 + " recorded when it was written (changed after the run?)";
    }
    // The same for the samples' bytes, which are what the judge reads (format 3).
    const std::string recorded_cdr_sha256 = trace.meta_or("cdr_sha256");
    if (result.error.empty() && !recorded_cdr_sha256.empty() && recorded_cdr_sha256 != trace.recomputed_cdr_sha256) {
        result.error_kind = "harness_error";
        result.error = "trace " + trace.file.string() + ": its samples' bytes give digest " +
                       trace.recomputed_cdr_sha256 + ", not the " + recorded_cdr_sha256 +
                       " recorded when it was written (changed after the run?)";
    }
    const std::string outcome = trace.meta_or("outcome", "running");
    if (outcome != "completed" && result.error.empty()) {
        result.error_kind = trace.meta_or("error_kind", "interrupted");
        result.error = trace.meta_or("error", "the run ended before its trace was finished (outcome: " + outcome + ")");
    }
    try {
        read_run_facts(trace, result, figures);
        const nlohmann::json judging = nlohmann::json::parse(trace.meta_or("judging", "null"));
        const JudgingPlan plan = judging_plan_from_json(judging);
        result.limits = plan.limits;
        result.min_effects = plan.min_effects;
        result.expected_error = plan.expect_error;
        result.expectation_set_aside = plan.expect_set_aside;
        // The trace says who touched what, whatever the run noticed live.
        if (result.error.empty()) {
            if (const auto violation = first_role_violation(trace)) {
                result.error_kind = "topic_role_violation";
                result.error = "node '" + violation->first + "': " + violation->second;
            }
        }

        apply_rig_overload(result);

        SystemJudgement judged = system.judge(trace, judging);
        figures.system = std::move(judged.figures);
        result.metrics = judged.metrics.values;
        result.not_measured = judged.metrics.not_measured;

        VerdictInputs inputs{judged.metrics.values, judged.metrics.not_measured, plan.limits, plan.expect_fail,
                             plan.expect_error,     result.error_kind,          result.error};
        const CaseVerdict verdict = judge_case(inputs);
        result.failures = verdict.failures;
        result.expected_failure = verdict.expected_failure;
        result.passed = verdict.passed;
    } catch (const std::exception& error) {
        // A trace read_trace accepted but whose content does not hold together.
        if (result.error.empty()) {
            result.error_kind = "harness_error";
            result.error = std::string("judging ") + trace.file.string() + ": " + error.what();
        }
        result.failures = {"error: " + result.error_kind + ": " + result.error};
        result.passed = false;
    }
    return run;
}

std::optional<double> finite_metric(const CaseResult& result, const std::string& name) {
    const auto found = result.metrics.find(name);
    if (found == result.metrics.end() || !std::isfinite(found->second)) return std::nullopt;
    return found->second;
}

std::optional<double> finite_limit(const CaseResult& result, const std::string& name) {
    const auto found = result.limits.find(name);
    if (found == result.limits.end() || !std::isfinite(found->second)) return std::nullopt;
    return found->second;
}

}  // namespace rig::harness
