#pragma once
// The judge: a case's verdict, metrics and figures from its recorded trace
// alone (docs/metrics.md). `rig run` records the trace and then judges it,
// and `rig judge` does the same with a trace written earlier, so a metric fix
// re-judges old runs and both give exactly the same numbers. Nothing here
// reads the plant, the case file or the controller: only what the trace holds.
//
// What every system's judge shares is here: the trace's own facts (its
// digest, how the run ended, the run facts), the topic roles, a real-time
// run's overload, and the verdict against the limits and expectations of the
// plan the run wrote (meta `judging`). The metrics and figures are the
// system's (SystemJudge, one per system in harness/systems/).
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/judge/case_figures.h"
#include "harness/judge/case_result.h"
#include "harness/judge/metric_set.h"
#include "harness/trace/trace_reader.h"

namespace rig::harness {

// What to judge against, fixed by the run from its case file (meta `judging`,
// JSON): the part every system writes. A system adds its own keys beside these.
struct JudgingPlan {
    std::string scenario;  // what the vehicle and operator did (the system's word)
    std::map<std::string, double> limits;
    std::vector<std::string> expect_fail;
    std::string expect_error;
    // Non-empty: the case's expectation was set aside, and why (applied_expectation,
    // harness/spec/case_spec.h); the run is judged on its limits alone.
    std::string expect_set_aside;
    // The case's `compare.min_effect` (rig compare's minimum effects); absent in older traces.
    std::map<std::string, double> min_effects;
};
// Writes the keys above into `json` (an object): scenario, limits, expect.
void add_to_json(const JudgingPlan& plan, nlohmann::json& json);
// Throws std::runtime_error naming the missing or malformed key.
JudgingPlan judging_plan_from_json(const nlohmann::json& json);
// `node[key]` of a judging plan (`path`: where node is, "flow." say), or
// std::runtime_error "judging plan: no key flow.window_to_ns": how every
// system's plan reader names what a trace's plan lacks.
const nlohmann::json& plan_key(const nlohmann::json& node, const std::string& key, const std::string& path);

// What a system's judge makes of a trace.
struct SystemJudgement {
    MetricSet metrics;
    std::shared_ptr<const SystemFigures> figures;
};

class SystemJudge {
public:
    virtual ~SystemJudge() = default;
    // Every metric of the system's plan (`plan`: the whole meta `judging`) and
    // its figures. Throws std::runtime_error for a trace whose content does not
    // hold together (the judge reports it as the rig's own error).
    virtual SystemJudgement judge(const RecordedTrace& trace, const nlohmann::json& plan) const = 0;
};

// A case's verdict and what the report draws of it.
struct CaseRun {
    CaseResult result;
    CaseFigures figures;
};

// Judges a recorded trace with its system's judge: every metric, the verdict
// against the plan's limits and expectations, and the figures. Never throws
// for a trace read_trace accepted.
CaseRun judge_trace(const RecordedTrace& trace, const SystemJudge& system);

}  // namespace rig::harness
