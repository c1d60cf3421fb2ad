#pragma once
// The run's outputs (docs/design.md "Results"): results.json, junit.xml, the
// terminal table and report.txt, and (harness/report/html_report.h) report.html.
// The verdict itself is the judge's (harness/judge/verdict.h).
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "harness/judge/case_figures.h"
#include "harness/judge/case_result.h"

namespace rig::harness {

struct RunSummary {
    int passed = 0;
    int failed = 0;
    int invalid = 0;  // rig overloaded: neither passed nor failed (case_invalid)
    double sim_seconds = 0.0;
    double wall_seconds = 0.0;
    // Split by time mode: a real-time case runs at 1x by definition, so the
    // rig's speed is the lockstep figure. The walls are those of run_cases'
    // two phases (harness/run/case_runner.h RunPhaseWalls), known only to the run
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
// A run's identity and what it did not measure, as results.json and sweep.json
// write them for each run: `case`, `case_sha256`, `controller_sha256`,
// `controller_config_sha256` (null when not recorded), `min_effects`, `not_measured`,
// `settings` (`rig run --set`: key path -> value as given; {} when none).
void add_run_identity(const CaseResult& result, nlohmann::json& run);

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

struct HtmlReportOptions;  // harness/report/html_report.h

// The same, plus out_dir/report.html with figures (figures[i] belongs to
// results[i]; see write_html_report). A problem with report.html (gnuplot
// missing or failing, the file not writable) never throws: it is returned,
// one line per problem, for the caller to print; empty when all went well.
// Problems with the other three files throw as above.
std::vector<std::string> write_results(const std::filesystem::path& out_dir, const std::vector<CaseResult>& results,
                                       const RunSummary& summary, const std::vector<CaseFigures>& figures,
                                       const HtmlReportOptions& options);

// ------------------------------------------------------------------ text

// One line of a real-time run's own lateness (CaseResult::rig_lateness): the
// latest emission, the late ones against the bound, an injected stall.
std::string rig_lateness_summary(const nlohmann::json& lateness);

}  // namespace rig::harness
