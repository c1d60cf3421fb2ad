#include "harness/report/results_writer.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include "harness/report/board_io_report.h"
#include "harness/report/build_info.h"
#include "harness/report/html_report.h"
#include "harness/judge/verdict.h"
#include "harness/output/atomic_file.h"
#include "harness/output/xml_text.h"
#include "rig/text/number_text.h"
#include "rig/runtime/clock.h"

namespace rig::harness {

namespace {

// For times in reports: finite values only (a wall time is never NaN; a
// sum over no cases is 0).
std::string fixed_or_zero(double value, int decimals) { return fixed_text(std::isfinite(value) ? value : 0.0, decimals); }

std::string status_word(const CaseResult& result) {
    if (case_invalid(result)) return "INVALID";
    if (!case_passed(result)) return "FAIL";
    return result.expected_failure ? "XFAIL-OK" : "PASS";
}

}  // namespace

namespace {

std::string join_lines(const std::vector<std::string>& lines) {
    std::string text;
    for (const std::string& line : lines) {
        text += line;
        text += '\n';
    }
    return text;
}

// Metrics, each with its limit when it has one: "name value / limit" or "name value".
std::string metrics_text(const CaseResult& result) {
    std::string text;
    for (const auto& [name, value] : result.metrics) {
        text += name + ' ' + significant_text(value, 6);
        if (const auto limit = result.limits.find(name); limit != result.limits.end()) {
            text += " (limit " + significant_text(limit->second, 6) + ')';
        }
        text += '\n';
    }
    return text;
}

// ---------------------------------------------------------------- table

// Display width of UTF-8 text, counting code points (case names are ASCII; this
// only keeps a stray accented character from skewing the columns).
std::size_t display_width(std::string_view text) {
    std::size_t width = 0;
    for (const char c : text) {
        if ((static_cast<unsigned char>(c) & 0xC0) != 0x80) ++width;
    }
    return width;
}

std::string pad_right(const std::string& text, std::size_t width) {
    const std::size_t current = display_width(text);
    return current >= width ? text : text + std::string(width - current, ' ');
}

struct TableRow {
    std::string name;
    std::string status;
    std::vector<std::string> metric_lines;
    std::vector<std::string> failure_lines;
};

TableRow make_row(const CaseResult& result, std::size_t metric_name_width) {
    TableRow row{result.name, status_word(result), {}, {}};
    for (const auto& [name, limit] : result.limits) {
        const auto metric = result.metrics.find(name);
        const std::string value = metric == result.metrics.end() || std::isnan(metric->second)
                                      ? std::string("-")
                                      : significant_text_against(metric->second, limit, 4);
        row.metric_lines.push_back(pad_right(name, metric_name_width) + ' ' + value + " / " + significant_text(limit, 6));
    }
    const bool expected = case_passed(result) && result.expected_failure;
    for (const std::string& failure : result.failures) {
        row.failure_lines.push_back(expected ? failure + " (expected)" : failure);
    }
    return row;
}

const char* status_color(const std::string& status) {
    if (status == "PASS") return "\033[32m";
    if (status == "XFAIL-OK") return "\033[33m";
    if (status == "INVALID") return "\033[1;35m";
    return "\033[1;31m";
}
constexpr const char* kColorFailure = "\033[31m";
constexpr const char* kColorReset = "\033[0m";

}  // namespace

RunSummary summarize(const std::vector<CaseResult>& results) {
    RunSummary summary;
    for (const CaseResult& result : results) {
        if (case_passed(result)) {
            ++summary.passed;
        } else if (case_invalid(result)) {
            ++summary.invalid;
        } else {
            ++summary.failed;
        }
        summary.sim_seconds += result.sim_seconds;
        summary.wall_seconds += result.wall_seconds;
        (result.mode == "realtime" ? summary.realtime_sim_seconds : summary.lockstep_sim_seconds) += result.sim_seconds;
    }
    return summary;
}

// ---------------------------------------------------------------- outputs

namespace {

// A recorded fact, or null when the run did not record it.
nlohmann::json text_or_null(const std::string& text) {
    return text.empty() ? nlohmann::json(nullptr) : nlohmann::json(valid_utf8(text));
}

}  // namespace

void add_run_identity(const CaseResult& result, nlohmann::json& run) {
    run["case"] = text_or_null(result.case_name);
    run["case_sha256"] = text_or_null(result.case_sha256);
    run["controller_sha256"] = text_or_null(result.controller_sha256);
    run["controller_config_sha256"] = text_or_null(result.controller_config_sha256);
    run["min_effects"] = result.min_effects;
    nlohmann::json settings = nlohmann::json::object();
    for (const auto& [key, value] : result.settings) settings[valid_utf8(key)] = valid_utf8(value);
    run["settings"] = std::move(settings);
    nlohmann::json not_measured = nlohmann::json::object();
    for (const auto& [name, why] : result.not_measured) not_measured[valid_utf8(name)] = valid_utf8(why);
    run["not_measured"] = std::move(not_measured);
}

nlohmann::json results_json(const std::vector<CaseResult>& results, const RunSummary& summary) {
    nlohmann::json cases = nlohmann::json::array();
    for (const CaseResult& result : results) {
        nlohmann::json metrics = nlohmann::json::object();
        for (const auto& [name, value] : result.metrics) metrics[valid_utf8(name)] = value;  // NaN dumps as null
        nlohmann::json limits = nlohmann::json::object();
        for (const auto& [name, value] : result.limits) limits[valid_utf8(name)] = value;
        nlohmann::json failures = nlohmann::json::array();
        for (const std::string& failure : result.failures) failures.push_back(valid_utf8(failure));
        nlohmann::json one_case = {
            {"name", valid_utf8(result.name)},
            {"file", valid_utf8(result.file)},
            {"passed", case_passed(result)},
            {"verdict", case_passed(result) ? "passed" : case_invalid(result) ? "invalid" : "failed"},
            {"expected_failure", result.expected_failure},
            {"expected_error", result.expected_error.empty() ? nlohmann::json(nullptr) : nlohmann::json(result.expected_error)},
            {"expectation_set_aside", result.expectation_set_aside.empty() ? nlohmann::json(nullptr)
                                                                           : nlohmann::json(valid_utf8(result.expectation_set_aside))},
            {"seed", result.seed},
            {"metrics", std::move(metrics)},
            {"limits", std::move(limits)},
            {"failures", std::move(failures)},
            {"error", result.error.empty() ? nlohmann::json(nullptr) : nlohmann::json(valid_utf8(result.error))},
            {"error_kind", result.error_kind.empty() ? nlohmann::json(nullptr) : nlohmann::json(result.error_kind)},
            {"trace_sha256", valid_utf8(result.trace_sha256)},
            {"trace_path", valid_utf8(result.trace_path)},

            {"sim_seconds", result.sim_seconds},
            {"wall_seconds", result.wall_seconds},
            {"startup_wall_seconds", result.startup_wall_seconds},
            {"instants", result.instants},
            {"rounds", result.rounds},
            {"stepping_wall_seconds", result.stepping_wall_seconds},
            {"mode", valid_utf8(result.mode)},
            {"controller_mode", valid_utf8(result.controller_mode)},
        };
        add_run_identity(result, one_case);
        if (!result.in_process_refused.empty()) one_case["in_process_refused"] = valid_utf8(result.in_process_refused);
        if (result.mode == "realtime") {
            nlohmann::json jitter = nlohmann::json::object();
            for (const EmissionJitter& device : result.emission_jitter) {
                jitter[valid_utf8(device.device)] = {{"samples", device.samples},
                                                      {"p50_ms", device.p50_ms},
                                                      {"p99_ms", device.p99_ms},
                                                      {"max_ms", device.max_ms},
                                                      {"step_p99_ms", device.step_p99_ms},
                                                      {"step_max_ms", device.step_max_ms}};
            }
            one_case["realtime"] = {{"scheduling", valid_utf8(result.realtime_scheduling)},
                                    {"wiring", valid_utf8(result.wiring)},
                                    {"emission_jitter", std::move(jitter)}};
            if (!result.board_io.is_null()) one_case["realtime"]["board_io"] = result.board_io;
            if (!result.rig_lateness.is_null()) one_case["realtime"]["rig_lateness"] = result.rig_lateness;
        }
        cases.push_back(std::move(one_case));
    }
    nlohmann::json summary_json = {
        {"passed", summary.passed},
        {"failed", summary.failed},
        {"invalid", summary.invalid},
        {"total", summary.passed + summary.failed + summary.invalid},
        {"sim_seconds", summary.sim_seconds},
        {"wall_seconds", summary.wall_seconds},
    };
    // The speed figure (lockstep) apart from the real-time cases, which run at 1x.
    auto phase = [](double sim_seconds, const std::optional<double>& wall_seconds) {
        nlohmann::json json = {{"sim_seconds", sim_seconds}};
        if (wall_seconds) {
            json["wall_seconds"] = *wall_seconds;
            json["x_real_time"] = *wall_seconds > 0.0 ? nlohmann::json(sim_seconds / *wall_seconds) : nlohmann::json();
        }
        return json;
    };
    summary_json["lockstep"] = phase(summary.lockstep_sim_seconds, summary.lockstep_wall_seconds);
    summary_json["realtime"] = phase(summary.realtime_sim_seconds, summary.realtime_wall_seconds);
    return {
        {"schema_version", kResultsSchemaVersion},
        {"rig", {{"version", std::string(rig_version())}, {"commit", std::string(rig_commit())}}},
        {"cases", std::move(cases)},
        {"summary", std::move(summary_json)},
    };
}

namespace {

// JUnit's classname: the folder the case file is in ("cases/table2-flow-adjust/x.yaml"
// gives "table2-flow-adjust"), which is how a suite's cases are grouped; "rig"
// for a case file named without a folder.
std::string case_folder(const CaseResult& result) {
    const std::string folder = std::filesystem::path(result.file).parent_path().filename().string();
    return folder.empty() || folder == "." || folder == ".." ? std::string("rig") : folder;
}

std::string this_hostname() {
    char name[256] = {};
    if (gethostname(name, sizeof name - 1) != 0) return "unknown";
    return name;
}

std::string xml_property(const std::string& name, const std::string& value) {
    return "        <property name=\"" + xml_escape(name, true) + "\" value=\"" + xml_escape(value, true) + "\"/>\n";
}

}  // namespace

std::string junit_xml(const std::vector<CaseResult>& results, const RunSummary& summary) {
    int failures = 0;
    int errors = 0;
    for (const CaseResult& result : results) {
        // An invalid case (the rig was overloaded, the controller was not judged)
        // is its suite's skipped test; <testsuites> has no count for those.
        if (case_passed(result) || case_invalid(result)) continue;
        if (!result.error.empty()) {
            ++errors;
        } else {
            ++failures;
        }
    }
    const std::string timestamp = summary.started_utc.empty() ? utc_date_time_now() : summary.started_utc;
    const std::string hostname = this_hostname();

    std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    xml += "<testsuites name=\"rig\" tests=\"" + std::to_string(results.size()) + "\" failures=\"" +
           std::to_string(failures) + "\" errors=\"" + std::to_string(errors) + "\" time=\"" +
           fixed_or_zero(summary.wall_seconds, 3) + "\">\n";
    for (const CaseResult& result : results) {
        const bool passed = case_passed(result);
        const bool invalid = case_invalid(result);
        const bool errored = !passed && !invalid && !result.error.empty();
        const std::string time = fixed_or_zero(result.wall_seconds, 3);
        const std::string folder = case_folder(result);
        xml += "  <testsuite name=\"" + xml_escape(result.name, true) + "\" package=\"" + xml_escape(folder, true) +
               "\" tests=\"1\" failures=\"" + (passed || errored || invalid ? "0" : "1") + "\" errors=\"" +
               (errored ? "1" : "0") + "\" skipped=\"" + (invalid ? "1" : "0") + "\" time=\"" + time +
               "\" timestamp=\"" + timestamp + "\" hostname=\"" + xml_escape(hostname, true) + "\">\n";
        xml += "    <properties>\n";
        xml += xml_property("seed", std::to_string(result.seed));
        if (!result.trace_sha256.empty()) xml += xml_property("trace_sha256", result.trace_sha256);
        if (!result.trace_path.empty()) xml += xml_property("trace_path", result.trace_path);
        xml += xml_property("mode", result.mode);
        if (!result.controller_mode.empty()) xml += xml_property("controller_mode", result.controller_mode);
        xml += xml_property("case_file", result.file);
        xml += xml_property("verdict", status_word(result));
        xml += xml_property("expected_failure", result.expected_failure ? "true" : "false");
        xml += xml_property("rig_version", std::string(rig_version()));
        xml += xml_property("rig_commit", std::string(rig_commit()));
        xml += "    </properties>\n";
        xml += "    <testcase classname=\"" + xml_escape(folder, true) + "\" name=\"" + xml_escape(result.name, true) +
               "\" time=\"" + time + "\">\n";
        if (invalid) {
            // Not the controller's failure: the run could not judge it (docs/metrics.md "Verdicts").
            xml += "      <skipped message=\"invalid: " + xml_escape(result.error, true) + "\"/>\n";
        } else if (errored) {
            xml += "      <error type=\"" + xml_escape(result.error_kind.empty() ? "error" : result.error_kind, true) +
                   "\" message=\"" + xml_escape(result.error, true) + "\">" +
                   xml_escape(result.error + "\n" + join_lines(result.failures), false) + "</error>\n";
        } else if (!passed) {
            const std::string headline =
                result.failures.empty() ? std::string("case failed") : result.failures.front();
            xml += "      <failure type=\"limit\" message=\"" + xml_escape(headline, true) + "\">" +
                   xml_escape(join_lines(result.failures), false) + "</failure>\n";
        }
        std::string output;
        if (passed && result.expected_failure) {
            // JUnit has no expected failure: the case passes, and says why here.
            output += "XFAIL-OK: an expected failure: the case's expect: asked for exactly this outcome\n" +
                      join_lines(result.failures);
        }
        if (!result.expectation_set_aside.empty()) output += "expectation set aside: " + result.expectation_set_aside + "\n";
        output += "seed: " + std::to_string(result.seed) + "\n";
        if (!result.trace_sha256.empty()) output += "trace: " + result.trace_path + " sha256 " + result.trace_sha256 + "\n";
        output += metrics_text(result);
        xml += "      <system-out>" + xml_escape(output, false) + "</system-out>\n";
        xml += "    </testcase>\n";
        xml += "  </testsuite>\n";
    }
    xml += "</testsuites>\n";
    return xml;
}

std::string result_table(const std::vector<CaseResult>& results, const RunSummary& summary, bool color) {
    std::size_t metric_name_width = 0;
    for (const CaseResult& result : results) {
        for (const auto& [name, limit] : result.limits) metric_name_width = std::max(metric_name_width, name.size());
    }
    std::vector<TableRow> rows;
    for (const CaseResult& result : results) rows.push_back(make_row(result, metric_name_width));

    const std::string case_header = "CASE";
    const std::string status_header = "RESULT";
    const std::string metrics_header = "METRICS (value / limit)";
    std::size_t case_width = case_header.size();
    std::size_t status_width = std::string_view("XFAIL-OK").size();
    std::size_t metrics_width = metrics_header.size();
    for (const TableRow& row : rows) {
        case_width = std::max(case_width, display_width(row.name));
        for (const std::string& line : row.metric_lines) metrics_width = std::max(metrics_width, display_width(line));
    }

    std::string table = pad_right(case_header, case_width) + "  " + pad_right(status_header, status_width) + "  " +
                        pad_right(metrics_header, metrics_width) + "  FAILURES\n";
    for (const TableRow& row : rows) {
        const std::size_t lines = std::max({row.metric_lines.size(), row.failure_lines.size(), std::size_t{1}});
        for (std::size_t line = 0; line < lines; ++line) {
            std::string text = pad_right(line == 0 ? row.name : "", case_width) + "  ";
            const std::string status = pad_right(line == 0 ? row.status : "", status_width);
            text += color && line == 0 ? status_color(row.status) + status + kColorReset : status;
            text += "  ";
            const bool has_failure = line < row.failure_lines.size();
            text += pad_right(line < row.metric_lines.size() ? row.metric_lines[line] : "", has_failure ? metrics_width : 0);
            if (has_failure) {
                const std::string& failure = row.failure_lines[line];
                text += "  ";
                text += color && row.status == "FAIL" ? kColorFailure + failure + kColorReset : failure;
            }
            while (!text.empty() && text.back() == ' ') text.pop_back();
            table += text + '\n';
        }
    }
    table += "\nsimulated " + fixed_or_zero(summary.sim_seconds, 1) + " s in " + fixed_or_zero(summary.wall_seconds, 1) +
             " s wall";
    if (summary.lockstep_wall_seconds && summary.lockstep_sim_seconds > 0.0 && summary.realtime_sim_seconds > 0.0) {
        // Apart: a real-time case runs at 1x by definition.
        table += " (lockstep " + fixed_or_zero(summary.lockstep_sim_seconds, 1) + " s in " +
                 fixed_or_zero(*summary.lockstep_wall_seconds, 1) + " s, " +
                 fixed_or_zero(summary.lockstep_sim_seconds / std::max(*summary.lockstep_wall_seconds, 1e-9), 1) +
                 "x; real time " + fixed_or_zero(summary.realtime_sim_seconds, 1) + " s";
        if (summary.realtime_wall_seconds) table += " in " + fixed_or_zero(*summary.realtime_wall_seconds, 1) + " s";
        table += ")";
    } else if (summary.lockstep_wall_seconds && summary.lockstep_sim_seconds > 0.0) {
        table += ", " + fixed_or_zero(summary.lockstep_sim_seconds / std::max(*summary.lockstep_wall_seconds, 1e-9), 1) +
                 "x real time";
    }
    table += "\n";
    // Kept alone on the last line: CI log readers look for "N passed, N failed".
    table += std::to_string(summary.passed) + " passed, " + std::to_string(summary.failed) + " failed" +
             (summary.invalid > 0 ? ", " + std::to_string(summary.invalid) + " invalid (rig overloaded: not judged)" : "") +
             "\n";
    return table;
}

std::string result_report(const std::vector<CaseResult>& results, const RunSummary& summary) {
    return result_table(results, summary, /*color=*/false) + result_details(results);
}

std::string result_details(const std::vector<CaseResult>& results) {
    std::string report;
    for (const CaseResult& result : results) {
        report += "\n== " + result.name + " (" + result.file + ")\n";
        report += "result: " + status_word(result) + "   seed: " + std::to_string(result.seed) +
                  "   simulated: " + fixed_or_zero(result.sim_seconds, 3) +
                  " s   wall: " + fixed_or_zero(result.wall_seconds, 3) + " s\n";
        if (!result.trace_path.empty() || !result.trace_sha256.empty()) {
            report += "trace: " + result.trace_path + "   sha256: " + result.trace_sha256 + "\n";
        }
        if (!result.error.empty()) report += "error (" + result.error_kind + "): " + result.error + "\n";
        if (!result.expectation_set_aside.empty()) report += "expectation set aside: " + result.expectation_set_aside + "\n";
        for (const auto& [name, why] : result.not_measured) report += "not measured: " + name + ": " + why + "\n";
        if (!result.metrics.empty()) {
            report += "metrics:\n";
            for (const auto& [name, value] : result.metrics) {
                report += "  " + name + " = " + significant_text(value, 6);
                if (const auto limit = result.limits.find(name); limit != result.limits.end()) {
                    report += "   (limit " + significant_text(limit->second, 6) + ")";
                }
                report += '\n';
            }
        }
        for (const std::string& failure : result.failures) report += "failure: " + failure + "\n";
        if (result.mode == "realtime") {
            report += "real time: " + result.realtime_scheduling + "\nwiring: " + result.wiring + "\n";
            report += "emission jitter (ms)      p50      p99      max  samples   step p99  step max\n";
            for (const EmissionJitter& device : result.emission_jitter) {
                if (device.samples == 0) continue;
                char line[160];
                std::snprintf(line, sizeof line, "  %-20s %8.3f %8.3f %8.3f %8zu %10.3f %9.3f\n",
                              device.device.c_str(), device.p50_ms, device.p99_ms, device.max_ms, device.samples,
                              device.step_p99_ms, device.step_max_ms);
                report += line;
            }
            if (!result.board_io.is_null()) report += "board I/O: " + board_io_summary(result.board_io) + "\n";
            if (result.rig_lateness.is_object()) report += "rig lateness: " + rig_lateness_summary(result.rig_lateness) + "\n";
        }
    }
    return report;
}

namespace {

// `path` as seen from `base`: CI archives the output folder, so what its files
// name must be found from where they are, not from where the rig ran.
std::string path_relative_to(const std::filesystem::path& path, const std::filesystem::path& base) {
    std::error_code error;
    const std::filesystem::path relative = std::filesystem::relative(path, base, error);
    if (!error && !relative.empty()) return relative.generic_string();
    return std::filesystem::absolute(path).lexically_relative(std::filesystem::absolute(base)).generic_string();
}

std::vector<CaseResult> with_paths_relative_to(const std::filesystem::path& out_dir, std::vector<CaseResult> results) {
    for (CaseResult& result : results) {
        if (!result.trace_path.empty()) result.trace_path = path_relative_to(result.trace_path, out_dir);
    }
    return results;
}

}  // namespace

std::string rig_lateness_summary(const nlohmann::json& lateness) {
    try {
        const nlohmann::json& bound = lateness.at("bound");
        std::string line = "latest emission " + fixed_or_zero(lateness.at("max_ms").get<double>(), 1) + " ms (" +
                           valid_utf8(lateness.at("worst_device").get<std::string>()) + ", due at t = " +
                           fixed_or_zero(lateness.at("worst_at_s").get<double>(), 3) + " s); " +
                           std::to_string(lateness.at("late").get<std::size_t>()) + " of " +
                           std::to_string(lateness.at("emissions").get<std::size_t>()) + " emissions (" +
                           fixed_or_zero(lateness.at("late_pct").get<double>(), 2) + " %) more than " +
                           significant_text(bound.at("late_after_ms").get<double>(), 6) + " ms late; bound: at most " +
                           significant_text(bound.at("max_lateness_ms").get<double>(), 6) + " ms, at most " +
                           significant_text(bound.at("max_late_pct").get<double>(), 6) + " % late";
        // Devices judged by limits of their own (a record from before they existed has none).
        if (const auto own = bound.find("devices"); own != bound.end() && own->is_object()) {
            for (const auto& [device, limits] : own->items()) {
                line += "; " + valid_utf8(device) + " by its own: at most " +
                        significant_text(limits.at("max_lateness_ms").get<double>(), 6) + " ms, at most " +
                        significant_text(limits.at("max_late_pct").get<double>(), 6) + " % more than " +
                        significant_text(limits.at("late_after_ms").get<double>(), 6) + " ms late";
            }
        }
        if (const nlohmann::json& stall = lateness.at("injected_stall"); stall.is_object()) {
            line += "; self-test: the rig's loop was stalled " + significant_text(stall.at("for_s").get<double>(), 6) +
                    " s at t = " + significant_text(stall.at("at_s").get<double>(), 6) + " s (rig_faults)";
        }
        return line;
    } catch (const nlohmann::json::exception& error) {
        return std::string("(malformed lateness record: ") + error.what() + ")";
    }
}

void write_results(const std::filesystem::path& out_dir, const std::vector<CaseResult>& results,
                   const RunSummary& summary) {
    std::filesystem::create_directories(out_dir);
    const std::vector<CaseResult> relative = with_paths_relative_to(out_dir, results);
    const std::string json_text =
        results_json(relative, summary).dump(2) + "\n";
    write_file_atomically(out_dir / "results.json", json_text);
    write_file_atomically(out_dir / "junit.xml", junit_xml(relative, summary));
    write_file_atomically(out_dir / "report.txt", result_report(relative, summary));
}

std::vector<std::string> write_results(const std::filesystem::path& out_dir, const std::vector<CaseResult>& results,
                                       const RunSummary& summary, const std::vector<CaseFigures>& figures,
                                       const HtmlReportOptions& options) {
    write_results(out_dir, results, summary);
    // The human report is a view: whatever goes wrong with it is told, never a
    // reason to fail (or crash) a run whose results are already written.
    try {
        return write_html_report(out_dir / "report.html", with_paths_relative_to(out_dir, results), figures, summary,
                                 options);
    } catch (const std::exception& error) {
        return {std::string("report.html not written: ") + error.what()};
    }
}

}  // namespace rig::harness
