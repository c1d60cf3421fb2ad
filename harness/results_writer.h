#pragma once
// Judging metrics against limits, and the run's outputs (docs/design.md "Results"): results.json, junit.xml and the human report / terminal table.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rig::harness {

// How late one device's emissions were against their deadlines in a real-time run.
struct EmissionJitter {
    std::string device;
    std::size_t samples = 0;
    double p50_ms = 0.0;
    double p99_ms = 0.0;
    double max_ms = 0.0;
    double step_p99_ms = 0.0;   // the device's own step (update) durations
    double step_max_ms = 0.0;
};

struct CaseResult {
    std::string name;
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

struct RunSummary {
    int passed = 0;
    int failed = 0;
    int invalid = 0;  // rig overloaded: neither passed nor failed (case_invalid)
    double sim_seconds = 0.0;
    double wall_seconds = 0.0;
    // Split by time mode: a real-time case runs at 1x by definition, so the
    // rig's speed is the lockstep figure. The walls are those of run_cases'
    // two phases (harness/case_runner.h RunPhaseWalls), known only to the run
    // that ran the cases (not to `rig judge` or `rig merge`).
    double lockstep_sim_seconds = 0.0;
    double realtime_sim_seconds = 0.0;
    std::optional<double> lockstep_wall_seconds;
    std::optional<double> realtime_wall_seconds;
    // When the run started, UTC, "2026-11-24T12:05:09" (junit.xml's timestamp);
    // empty: junit_xml() takes the time it is written.
    std::string started_utc;
};

// results.json's "schema_version". 1 was the unversioned form, whose
// trace_path was the path the run wrote to; from 2 on it is relative to the
// folder results.json is in (the --out directory), and "rig" says which rig wrote it.
inline constexpr int kResultsSchemaVersion = 2;

// ------------------------------------------------------------------ judging

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

// Counts and adds up the cases. wall_seconds is the sum of the cases' wall
// times; a run with --jobs > 1 should overwrite it with its own elapsed time.
RunSummary summarize(const std::vector<CaseResult>& results);

// ------------------------------------------------------------------ outputs

// The docs/design.md contract: {"schema_version": 2, "rig": {version, commit},
// "cases": [{name, passed, seed, metrics, limits,
// failures, trace_sha256, + file, expected_failure, error (null when none),
// trace_path, sim_seconds, wall_seconds}], "summary": {passed, failed,
// sim_seconds, wall_seconds, + total}}. NaN metrics become null; malformed
// UTF-8 in any string is replaced by U+FFFD, so dump() never throws. Paths are
// written as the results hold them: write_results() makes them relative to its folder.
nlohmann::json results_json(const std::vector<CaseResult>& results, const RunSummary& summary);

// JUnit XML, valid against Jenkins xunit's JUnit schema (tests/data/jenkins-junit-10.xsd):
// <testsuites> with one <testsuite> per case (that schema allows properties on a
// suite only), named like the case, with the run's timestamp, the hostname and
// the case's properties (seed, trace_sha256, trace_path, mode, controller_mode,
// case_file, verdict, expected_failure, rig_version, rig_commit), holding the
// case's one <testcase> whose classname is the case file's folder
// ("table2-flow-adjust"). A failed case has <failure message="first failure">
// with every failure in its text; a case with an error has <error> instead. The
// schema has no expected failure: such a case passes, its suite's property
// expected_failure is true and its <system-out> begins "XFAIL-OK". Metrics and
// seed go in <system-out>. Text is XML-escaped, invalid UTF-8 and characters XML
// 1.0 forbids are replaced.
std::string junit_xml(const std::vector<CaseResult>& results, const RunSummary& summary);

// The terminal table: case | PASS / FAIL / XFAIL-OK | limited metrics as
// "value / limit" | failures, then a timing line and a last line
// "N passed, M failed". `color` adds ANSI colours (for a terminal only).
std::string result_table(const std::vector<CaseResult>& results, const RunSummary& summary, bool color);

// The table followed by per-case details (file, seed, trace, all metrics, error).
std::string result_report(const std::vector<CaseResult>& results, const RunSummary& summary);
// The per-case details alone (`rig run --verbose` prints them after the table).
std::string result_details(const std::vector<CaseResult>& results);

// Writes out_dir/results.json, junit.xml and report.txt (creating out_dir),
// each through a temporary file renamed into place, so a reader never sees a
// half-written file. Trace paths in them are relative to out_dir (CI archives
// that folder, and the paths must still point at the traces there). Throws std::runtime_error / std::filesystem::filesystem_error.
void write_results(const std::filesystem::path& out_dir, const std::vector<CaseResult>& results,
                   const RunSummary& summary);

struct CaseFigures;        // harness/html_report.h
struct HtmlReportOptions;  // harness/html_report.h

// The same, plus out_dir/report.html with figures (figures[i] belongs to
// results[i]; see write_html_report). A problem with report.html (gnuplot
// missing or failing, the file not writable) never throws: it is returned,
// one line per problem, for the caller to print; empty when all went well.
// Problems with the other three files throw as above.
std::vector<std::string> write_results(const std::filesystem::path& out_dir, const std::vector<CaseResult>& results,
                                       const RunSummary& summary, const std::vector<CaseFigures>& figures,
                                       const HtmlReportOptions& options);

// ------------------------------------------------------------------ text and files (shared with html_report)

// One line of a real-time run's own lateness (CaseResult::rig_lateness): the
// latest emission, the late ones against the bound, an injected stall.
std::string rig_lateness_summary(const nlohmann::json& lateness);

// The text with malformed UTF-8 replaced by U+FFFD (nlohmann::json refuses to
// dump invalid UTF-8, and error text may come from a crashed child's output).
std::string valid_utf8(std::string_view text);

// Escapes for XML (and so XHTML) element text, or for a double-quoted attribute
// value; malformed UTF-8 and characters XML 1.0 forbids become U+FFFD.
std::string xml_escape(std::string_view text, bool attribute);

// Writes the file through a temporary beside it renamed into place, so a reader
// never sees a half-written file. Throws std::runtime_error / filesystem_error.
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

}  // namespace rig::harness
