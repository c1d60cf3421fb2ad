#pragma once
// What the judge says of one run of a case (results.json's `cases[i]`,
// docs/design.md "Results"): its verdict, metrics against limits, error, and
// the facts of the run the trace recorded.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/trace/run_facts.h"

namespace rig::harness {

struct CaseResult {
    std::string name;               // the run's name: the case's, or NAME-seedN for a case with `seeds:`
    std::string case_name;          // the case's own name (empty in traces from before it was recorded)
    std::string file;               // the case file
    bool passed = false;            // verdict, including the expect.fail logic (judge_case)
    bool expected_failure = false;  // the case has expect.fail (a negative case)
    std::uint64_t seed = 1;
    std::map<std::string, double> metrics;
    // Metrics the run gave no value for because of what the controller did, with
    // why ("never settled: ..."); a limit on one of them is broken (docs/metrics.md).
    std::map<std::string, std::string> not_measured;
    std::map<std::string, double> limits;  // effective limits the case was judged against
    std::vector<std::string> failures;     // e.g. "overlap_m 3.61 > 3.3"
    std::string error;  // non-empty: the case did not run to the end (node died, bad config...)
    std::string error_kind;      // rig::FailureKind name of the error ("node_exited", ...)
    std::string expected_error;  // the case's expect.error: this error is the verdict it wants
    // The case's expectation described the reference controller and another ran:
    // why it was set aside (judged on the limits alone); empty otherwise.
    std::string expectation_set_aside;
    std::string trace_sha256;
    std::string trace_path;
    // What the run was run with (harness/run/run_identity.h): the case without its
    // controller section, the controller's program or plugin, and its
    // configuration; empty when not known (an external board, an older trace).
    std::string case_sha256;
    std::string controller_sha256;
    std::string controller_config_sha256;
    // `rig run --set KEY=VALUE`: the case file's values the command line
    // replaced (key path -> the value as given); empty when none.
    std::map<std::string, std::string> settings;
    // The case's `compare.min_effect`: rig compare's minimum effects over the declared ones.
    std::map<std::string, double> min_effects;
    double sim_seconds = 0.0;
    double wall_seconds = 0.0;
    double startup_wall_seconds = 0.0;  // of wall_seconds: process start, DDS discovery, hello
    // Lockstep: instants and rounds run, and the wall time they took (after start-up).
    std::uint64_t instants = 0;
    std::uint64_t rounds = 0;
    double stepping_wall_seconds = 0.0;
    std::string mode = "lockstep";      // or "realtime"
    // Where the controller ran: "process", "in_process" (a plugin, software-in-the-loop)
    // or "external" (a wired board); empty in traces from before it was recorded.
    std::string controller_mode;
    std::string in_process_refused;  // in process was asked for; why it ran as a process
    // Real-time runs only: what scheduling the rig got, and the emission jitter per device.
    std::string realtime_scheduling;
    std::vector<EmissionJitter> emission_jitter;
    // Real-time runs: the rig's own emission lateness against the case's bound
    // (run facts `lateness`, harness/case_runner.cpp); null in lockstep.
    nlohmann::json rig_lateness;
    // A Modbus board wire: frames per kind, fail-safe, attachment (harness/board_attach.h board_io_report).
    nlohmann::json board_io;
    std::string wiring;                 // e.g. "gnss serial /dev/pts/4, board_io modbus_rtu /dev/pts/6"
};

// A metric's value, or its limit, when the case has a finite one (for figures and captions).
std::optional<double> finite_metric(const CaseResult& result, const std::string& name);
std::optional<double> finite_limit(const CaseResult& result, const std::string& name);

}  // namespace rig::harness
