#pragma once
// The judge: a case's verdict, metrics and figures from its recorded trace
// alone (docs/metrics.md). `rig run` records the trace and then judges it here,
// and `rig judge` does the same with a trace written earlier, so a metric fix
// re-judges old runs and both give exactly the same numbers. Nothing here reads
// the plant, the spec object or the controller: only what the trace holds (its
// samples, deposition, landing edges, discovery, and the judging plan the run
// wrote into its meta table).
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/html_report.h"
#include "harness/metrics.h"
#include "harness/results_writer.h"
#include "rig/runtime/clock.h"

namespace rig::harness {

// What to judge and how, fixed by the run from its case file and route (meta key
// `judging`, JSON). Everything here is a number the case or its route gave, never
// something the controller did.
struct JudgingPlan {
    std::string scenario;  // breakpoint_identification | breakpoint_continuation | static_flow | valve_calibration
    double breakpoint_along_m = 0.0;
    double field_origin_lat_deg = 0.0;
    double field_origin_lon_deg = 0.0;
    double field_origin_height_m = 0.0;
    double field_heading_deg = 0.0;
    bool judge_breakpoint = false;
    bool judge_flow = false;
    FlowJudging flow;
    FlowWindow flow_window;
    double kf11_pulses_per_l = 90.0;  // the meter's nameplate k (Eq. 3) for the paper-style readings
    double kf11_window_s = 0.25;
    // Fig. 11 from truth (valve_calibration), over flow_window (the switch on).
    bool judge_fig11 = false;
    bool judge_deposition = false;
    DepositionJudging deposition;
    std::map<std::string, double> limits;
    std::vector<std::string> expect_fail;
    std::string expect_error;
    // Non-empty: the case's expectation was set aside, and why (applied_expectation,
    // harness/case_spec.h); the run is judged on its limits alone.
    std::string expect_set_aside;
};
nlohmann::json to_json(const JudgingPlan& plan);
// Throws std::runtime_error naming the missing or malformed key.
JudgingPlan judging_plan_from_json(const nlohmann::json& json);

// A sample of the trace's `samples` table.
struct RecordedSample {
    TimeNs t_ns = 0;
    int round = 0;
    nlohmann::json json;
};

struct RecordedDiscovery {
    TimeNs t_ns = 0;
    std::string participant;
    std::string guid_prefix;
    std::string endpoint;  // reader | writer
    std::string topic;
    std::string event;     // discovered | removed
};

struct RecordedForeignSample {
    TimeNs t_ns = 0;
    std::string topic;
    std::string participant;
};

// What the judge reads of a trace.
struct RecordedTrace {
    std::filesystem::path file;
    std::map<std::string, std::string> meta;
    std::map<std::string, std::vector<RecordedSample>> samples;  // the topics the judge uses, in delivery order
    DoseProfile dose;                                            // from the deposition table
    std::vector<LandingEdgeSample> landing_edges;
    std::vector<RecordedDiscovery> discovery;
    std::vector<RecordedForeignSample> foreign_samples;
    // The digest recomputed from the tables (samples, deposition, landing edges),
    // to compare with meta's trace_sha256: a trace changed after its run differs.
    std::string recomputed_sha256;
};

// Reads a trace written by TraceRecorder. Throws std::runtime_error naming the
// file and what is wrong (not SQLite, another trace format, a missing table or
// meta key, malformed JSON at a row).
RecordedTrace read_trace(const std::filesystem::path& file);

// A case's verdict and what the report draws of it (Fig. 14 flow curve, Fig. 15 dose).
struct CaseRun {
    CaseResult result;
    CaseFigures figures;
};

// Judges a recorded trace: every metric, the verdict against the plan's limits
// and expectations, and the figures. Never throws for a trace read_trace accepted.
CaseRun judge_trace(const RecordedTrace& trace);

// Roles (docs/design.md "Data flow"): a participant other than the rig's may not
// read or write truth/*, nor write device/* or the clock's tick. Returns why an
// endpoint breaks its role ("reads truth topic truth/vehicle"), or nullopt.
std::optional<std::string> topic_role_violation(const std::string& endpoint, const std::string& topic);
// The same for what a node declared in its hello (the topics it reads and
// writes): why the first one breaks its role, or nullopt. Checked when the
// hellos arrive, before time starts, so a node that declares a forbidden topic
// fails at the same point in every run.
std::optional<std::string> declared_role_violation(const std::vector<std::string>& subscribed,
                                                   const std::vector<std::string>& published);

}  // namespace rig::harness
