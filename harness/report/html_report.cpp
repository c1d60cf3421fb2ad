#include "harness/report/html_report.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <utility>

#include "harness/judge/verdict.h"
#include "harness/output/atomic_file.h"
#include "harness/output/xml_text.h"
#include "harness/plot/figure_text.h"
#include "harness/plot/gnuplot_panel.h"
#include "harness/report/board_io_report.h"

namespace rig::harness {

namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------- case facts

enum class Verdict { pass, fail, expected_failure_ok, invalid };

Verdict verdict_of(const CaseResult& result) {
    if (case_invalid(result)) return Verdict::invalid;
    if (!case_passed(result)) return Verdict::fail;
    return result.expected_failure ? Verdict::expected_failure_ok : Verdict::pass;
}

std::string verdict_badge(Verdict verdict) {
    switch (verdict) {
        case Verdict::pass: return "<span class=\"badge pass\">PASS</span>";
        case Verdict::expected_failure_ok:
            return "<span class=\"badge xfail\" title=\"broke exactly the limits the case expects to "
                   "break\">expected failure OK</span>";
        case Verdict::invalid:
            return "<span class=\"badge invalid\" title=\"the rig was overloaded: the run cannot judge the "
                   "controller\">INVALID</span>";
        case Verdict::fail: break;
    }
    return "<span class=\"badge fail\">FAIL</span>";
}

// How a metric stands against its limit; judge()'s rule: equal passes, missing or NaN fails.
enum class LimitState { unlimited, within, over, missing };

LimitState limit_state(const CaseResult& result, const std::string& metric) {
    const auto limit = result.limits.find(metric);
    if (limit == result.limits.end()) return LimitState::unlimited;
    const auto value = result.metrics.find(metric);
    if (value == result.metrics.end() || std::isnan(value->second)) return LimitState::missing;
    return value->second <= limit->second ? LimitState::within : LimitState::over;
}

// The CSS class of a limited metric: over a limit is red, unless the case
// expected exactly that (then amber).
std::string limit_class(const CaseResult& result, LimitState state) {
    if (state == LimitState::within || state == LimitState::unlimited) return "within";
    return verdict_of(result) == Verdict::expected_failure_ok ? "expected" : "over";
}

// One limited metric across the cases that have it: a bar per case, its limit as a red dash.
struct SuiteMetric {
    std::string name;
    std::vector<std::size_t> cases;  // indices into results, in order
};

std::vector<SuiteMetric> suite_metrics(const std::vector<CaseResult>& results) {
    std::map<std::string, SuiteMetric> by_name;
    for (std::size_t i = 0; i < results.size(); ++i) {
        for (const auto& [name, value] : results[i].limits) {
            SuiteMetric& entry = by_name[name];
            entry.name = name;
            entry.cases.push_back(i);
        }
    }
    std::vector<SuiteMetric> shared;
    for (auto& [name, entry] : by_name) {
        std::size_t measured = 0;
        for (const std::size_t i : entry.cases) measured += finite_metric(results[i], name).has_value() ? 1 : 0;
        if (measured >= 2) shared.push_back(std::move(entry));
    }
    return shared;
}

constexpr int kBarWithinColor = 0x6baed6;
constexpr int kBarOverColor = 0xde2d26;
constexpr int kBarExpectedColor = 0xf0a500;

Panel suite_metric_panel(const std::vector<CaseResult>& results, const SuiteMetric& suite_metric) {
    Extent y_extent;
    y_extent.include(0.0);
    std::vector<std::vector<double>> data;
    std::string tics;
    for (std::size_t slot = 0; slot < suite_metric.cases.size(); ++slot) {
        const CaseResult& result = results[suite_metric.cases[slot]];
        const double value = finite_metric(result, suite_metric.name).value_or(kNotMeasured);
        const double limit_value = finite_limit(result, suite_metric.name).value_or(kNotMeasured);
        const std::string css = limit_class(result, limit_state(result, suite_metric.name));
        const int color = css == "within" ? kBarWithinColor : css == "expected" ? kBarExpectedColor : kBarOverColor;
        y_extent.include(value);
        y_extent.include(limit_value);
        // The value's text goes above the limit's dash when that is higher, so the dash never crosses it.
        const double label_at = std::isfinite(limit_value) ? std::max(value, limit_value) : value;
        data.push_back({static_cast<double>(slot), value, static_cast<double>(color), limit_value, label_at});
        tics += (slot == 0 ? "" : ", ") + gnuplot_string(shortened(result.name, 28)) + " " + std::to_string(slot);
    }
    const double slots = static_cast<double>(suite_metric.cases.size());
    Panel panel;
    panel.caption = suite_metric.name + " across cases";
    panel.width = std::clamp(160 + 56 * static_cast<int>(suite_metric.cases.size()), 420, 1150);
    panel.height = 360;
    std::string& script = panel.script;
    script += data_block("metric", data);
    script += "set title " + gnuplot_string(suite_metric.name) + "\n";
    script += "set xrange [-0.6:" + exact_number(slots - 0.4) + "]\n";
    script += "set yrange " + y_extent.range(0.05, 0.15) + "\n";
    script += "set xtics (" + tics + ") rotate by 30 right nomirror\n";
    // The first name, written right-aligned and slanted, reaches left of the plot:
    // leave it room (in characters, roughly cos 30° of its length less half a slot).
    const std::size_t first_name_length = shortened(results[suite_metric.cases.front()].name, 28).size();
    const int left_margin = std::clamp(static_cast<int>(first_name_length) * 3 / 4 - 2, 10, 24);
    script += "set lmargin " + std::to_string(left_margin) + "\n";
    script += "set grid noxtics ytics\nset key off\nset boxwidth 0.6\n";
    script += "set style fill solid 0.85 border rgb '#555555'\n";
    script += "plot $metric using 1:2:3 with boxes lc rgb variable notitle, "
              "$metric using ($1-0.4):4:(0.8):(0) with vectors nohead lw 2.5 lc " +
              rgb(kLimitColor) +
              " notitle, "
              "$metric using 1:5:(sprintf('%.4g', $2)) with labels offset 0,0.8 notitle\n";
    return panel;
}

// ---------------------------------------------------------------- page

constexpr std::string_view kStyle = R"(
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; color: #222;
       margin: 1.5em auto; max-width: 1240px; padding: 0 1.2em; line-height: 1.4; }
h1 { font-size: 1.7em; margin: 0 0 0.3em 0; }
h2 { font-size: 1.3em; border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 2.2em; }
h3 { font-size: 1.05em; margin: 1.2em 0 0.4em 0; }
/* A table or figure wider than the screen (a phone's 390 px) scrolls inside its
   own box; the page never does, and figures are never shrunk below the size
   their text was drawn for (gnuplot's 11 px). */
table { border-collapse: collapse; margin: 0.4em 0 0.8em 0; display: block; overflow-x: auto; max-width: 100%; }
th, td { border: 1px solid #ddd; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f3f3f3; font-weight: 600; }
.num { font-family: ui-monospace, "DejaVu Sans Mono", Menlo, Consolas, monospace; font-variant-numeric: tabular-nums;
       text-align: right; white-space: nowrap; }
.mono { font-family: ui-monospace, "DejaVu Sans Mono", Menlo, Consolas, monospace; word-break: break-all; }
.metric-line { white-space: nowrap; }
.metric-line .name { display: inline-block; min-width: 13em; }
.badge { display: inline-block; padding: 0.05em 0.55em; border-radius: 0.3em; font-weight: 700; font-size: 0.9em;
         white-space: nowrap; }
.badge.pass { background: #dcf3dc; color: #17611a; }
.badge.fail { background: #fbd3d3; color: #8d1010; }
.badge.xfail { background: #fcefc7; color: #765600; }
.badge.invalid { background: #e8dcf5; color: #4b1d7a; }
.over { color: #b00000; font-weight: 700; }
td.over { background: #fdecec; }
.expected { color: #8a6400; }
td.expected { background: #fdf6dd; }
.failures { color: #8d1010; margin: 0; padding-left: 1.2em; }
.verdict { font-size: 1.2em; font-weight: 700; margin: 0.2em 0 0.6em 0; }
.verdict.pass { color: #17611a; }
.verdict.fail { color: #8d1010; }
.error-box { border: 2px solid #b00000; background: #fff1f1; padding: 0.6em 1em; margin: 0.8em 0; }
.error-box strong { color: #8d1010; }
.notice { border: 1px solid #e0b000; background: #fff9e0; padding: 0.4em 0.8em; }
pre { white-space: pre-wrap; word-break: break-word; margin: 0.3em 0;
      font-family: ui-monospace, "DejaVu Sans Mono", Menlo, Consolas, monospace; }
figure { margin: 1.2em 0; max-width: 100%; overflow-x: auto; }
#suite figure { margin: 0.4em 0; }
.panels { display: flex; flex-wrap: wrap; gap: 0.8em; align-items: flex-start; }
.frames { display: flex; flex-wrap: wrap; gap: 0.8em; }
.frames img { max-width: 100%; height: auto; border: 1px solid #ccc; }
.panels.stacked { flex-direction: column; flex-wrap: nowrap; }
svg { max-width: none; height: auto; flex: none; }
@media (max-width: 600px) {
  body { padding: 0 0.6em; margin-top: 0.8em; }
  .metric-line .name { min-width: 0; margin-right: 0.5em; }
}
figcaption { color: #555; font-size: 0.92em; margin-top: 0.3em; max-width: 70em; }
.figure-error { border: 1px dashed #b00000; background: #fff6f6; padding: 0.5em 0.8em; max-width: 60em; }
.nav { font-size: 0.9em; }
.muted { color: #777; }
)";

std::string verdict_text(const RunSummary& summary) {
    const int total = summary.passed + summary.failed + summary.invalid;
    if (summary.invalid > 0) {
        return "<p class=\"verdict fail\">" + std::to_string(summary.failed) + " of " + std::to_string(total) +
               " failed, " + std::to_string(summary.invalid) +
               " invalid (the rig was overloaded: not judged, run again on a quieter machine)</p>\n";
    }
    if (summary.failed == 0) {
        return "<p class=\"verdict pass\">All " + std::to_string(total) + " case" + (total == 1 ? "" : "s") +
               " passed</p>\n";
    }
    return "<p class=\"verdict fail\">" + std::to_string(summary.failed) + " of " + std::to_string(total) + " case" +
           (total == 1 ? "" : "s") + " failed</p>\n";
}

std::string run_numbers_table(const RunSummary& summary) {
    const std::string speed_up =
        summary.wall_seconds > 0.0 ? shown_number(summary.sim_seconds / summary.wall_seconds, 3) + "\u00d7" : "\u2013";
    std::string table = "<table class=\"run\">\n<tr><th>passed</th><th>failed</th><th>invalid</th><th>simulated</th><th>wall</th>"
                        "<th>speed-up (simulated / wall)</th></tr>\n";
    table += "<tr><td class=\"num\">" + std::to_string(summary.passed) + "</td><td class=\"num" +
             (summary.failed > 0 ? " over" : "") + "\">" + std::to_string(summary.failed) + "</td><td class=\"num" +
             (summary.invalid > 0 ? " over" : "") + "\">" + std::to_string(summary.invalid) + "</td><td class=\"num\">" +
             fixed_number(summary.sim_seconds, 1) + " s</td><td class=\"num\">" + fixed_number(summary.wall_seconds, 1) +
             " s</td><td class=\"num\">" + speed_up + "</td></tr>\n</table>\n";
    return table;
}

std::string case_anchor(std::size_t index) { return "case-" + std::to_string(index + 1); }

std::string failure_items(const CaseResult& result) {
    const bool expected = verdict_of(result) == Verdict::expected_failure_ok;
    std::string items;
    for (const std::string& failure : result.failures) {
        items += "<li>" + html(failure) + (expected ? " <span class=\"expected\">(expected)</span>" : "") + "</li>";
    }
    return items;
}

std::string summary_table(const std::vector<CaseResult>& results) {
    std::string table = "<table class=\"cases\">\n<tr><th>#</th><th>case</th><th>result</th>"
                        "<th>limited metrics (value / limit)</th><th>failures</th></tr>\n";
    for (std::size_t i = 0; i < results.size(); ++i) {
        const CaseResult& result = results[i];
        table += "<tr><td class=\"num\">" + std::to_string(i + 1) + "</td><td><a href=\"#" + case_anchor(i) + "\">" +
                 html(result.name) + "</a></td><td>" + verdict_badge(verdict_of(result)) + "</td><td>";
        for (const auto& [name, limit_value] : result.limits) {
            const LimitState state = limit_state(result, name);
            const auto value = result.metrics.find(name);
            const std::string value_text = value == result.metrics.end() ? std::string("missing")
                                                                         : shown_against(value->second, limit_value);
            table += "<div class=\"metric-line " + limit_class(result, state) + "\"><span class=\"name\">" + html(name) +
                     "</span> <span class=\"num\">" + html(value_text) + " / " + shown_number(limit_value, 6) +
                     "</span></div>";
        }
        const std::string failures = failure_items(result);
        table += "</td><td>" + (failures.empty() ? std::string() : "<ul class=\"failures\">" + failures + "</ul>") +
                 "</td></tr>\n";
    }
    return table + "</table>\n";
}

std::string case_facts(const CaseResult& result) {
    std::string facts = "<table class=\"facts\">\n";
    const auto row = [&facts](std::string_view label, const std::string& value_html) {
        facts += "<tr><th>" + std::string(label) + "</th><td>" + value_html + "</td></tr>\n";
    };
    row("file", "<span class=\"mono\">" + html(result.file) + "</span>");
    row("seed", "<span class=\"num\">" + std::to_string(result.seed) + "</span>");
    row("simulated", "<span class=\"num\">" + fixed_number(result.sim_seconds, 3) + " s</span>");
    std::string wall = "<span class=\"num\">" + fixed_number(result.wall_seconds, 3) + " s</span>";
    if (result.startup_wall_seconds > 0.0) {
        wall += " <span class=\"muted\">(of it start-up " + fixed_number(result.startup_wall_seconds, 3) + " s)</span>";
    }
    row("wall", wall);
    if (!result.controller_mode.empty()) {
        std::string placed = html(result.controller_mode == "in_process" ? "in process (plugin)" : result.controller_mode);
        if (!result.in_process_refused.empty()) {
            placed += " <span class=\"muted\">(not in process: " + html(result.in_process_refused) + ")</span>";
        }
        row("controller", placed);
    }
    if (result.rig_lateness.is_object()) row("rig lateness", html(rig_lateness_summary(result.rig_lateness)));
    row("trace", result.trace_path.empty() ? std::string("<span class=\"muted\">none</span>")
                                           : "<span class=\"mono\">" + html(result.trace_path) + "</span>");
    row("trace_sha256", result.trace_sha256.empty() ? std::string("<span class=\"muted\">none</span>")
                                                    : "<span class=\"mono\">" + html(result.trace_sha256) + "</span>");
    return facts + "</table>\n";
}

std::string metrics_table(const CaseResult& result) {
    std::set<std::string> names;
    for (const auto& [name, value] : result.metrics) names.insert(name);
    for (const auto& [name, value] : result.limits) names.insert(name);
    if (names.empty()) return "<p class=\"muted\">No metrics.</p>\n";
    std::string table = "<table class=\"metrics\">\n<tr><th>metric</th><th>value</th><th>limit</th><th></th></tr>\n";
    for (const std::string& name : names) {
        const LimitState state = limit_state(result, name);
        const auto value = result.metrics.find(name);
        const auto limit_value = result.limits.find(name);
        const std::string css = limit_class(result, state);
        std::string value_text = "missing";
        if (const auto why = result.not_measured.find(name); why != result.not_measured.end()) {
            value_text = "not measured: " + why->second;
        }
        if (value != result.metrics.end()) {
            value_text = limit_value == result.limits.end() ? shown_number(value->second, 6)
                                                            : shown_against(value->second, limit_value->second);
        }
        std::string state_text;
        if (state == LimitState::within) state_text = "within";
        if (state == LimitState::over) state_text = css == "expected" ? "over (expected)" : "over";
        if (state == LimitState::missing) {
            state_text = result.not_measured.count(name) ? (css == "expected" ? "broken (expected)" : "broken")
                                                         : "not measured";
        }
        const bool highlighted = state == LimitState::over || state == LimitState::missing;
        const std::string limit_text =
            limit_value == result.limits.end() ? std::string() : shown_number(limit_value->second, 6);
        table += "<tr><td class=\"mono\">" + html(name) + "</td><td class=\"num" + (highlighted ? " " + css : "") +
                 "\">" + html(value_text) + "</td><td class=\"num\">" + limit_text + "</td><td" +
                 (highlighted ? " class=\"" + css + "\"" : "") + ">" + state_text + "</td></tr>\n";
    }
    return table + "</table>\n";
}

std::string jitter_table(const std::vector<JitterRow>& jitter) {
    std::string table = "<table class=\"jitter\">\n<tr><th>device</th><th>p50 (ms)</th><th>p99 (ms)</th>"
                        "<th>max (ms)</th><th>slowest own step (ms)</th></tr>\n";
    for (const JitterRow& row : jitter) {
        table += "<tr><td>" + html(row.device) + "</td><td class=\"num\">" + fixed_number(row.p50_ms, 3) +
                 "</td><td class=\"num\">" + fixed_number(row.p99_ms, 3) + "</td><td class=\"num\">" +
                 fixed_number(row.max_ms, 3) + "</td><td class=\"num\">" + fixed_number(row.step_max_ms, 3) +
                 "</td></tr>\n";
    }
    return table + "</table>\n";
}

// The Modbus board wire's frame counts per kind, fail-safe and attachment.
std::string board_io_table(const nlohmann::json& board_io) {
    std::string table = "<table class=\"facts\">\n";
    for (const auto& [what, value] : board_io_rows(board_io)) {
        table += "<tr><th>" + html(what) + "</th><td class=\"mono\">" + html(value) + "</td></tr>\n";
    }
    return table + "</table>\n";
}

std::string case_label(std::size_t index, const CaseResult& result) {
    return "case " + std::to_string(index + 1) + " (" + valid_utf8(result.name) + ")";
}

std::string case_section(FigurePage& page, std::size_t index, const CaseResult& result, const CaseFigures* figures,
                         const HtmlReportOptions& options) {
    std::string section = "<section class=\"case\" id=\"" + case_anchor(index) + "\">\n";
    section += "<h2>" + std::to_string(index + 1) + ". " + html(result.name) + " " + verdict_badge(verdict_of(result)) +
               "</h2>\n";
    if (verdict_of(result) == Verdict::invalid) {
        section += "<div class=\"error-box\"><strong>Invalid: this run cannot judge the controller (" +
                   html(result.error_kind) + "):</strong>\n<pre>" + html(result.error) +
                   "</pre>The metrics below are reported, not judged; run the case again on a quieter machine.</div>\n";
    } else if (!result.error.empty()) {
        section += "<div class=\"error-box\"><strong>The case did not run to the end (" + html(result.error_kind) +
                   (verdict_of(result) == Verdict::expected_failure_ok ? ", as the case expects" : "") +
                   "):</strong>\n<pre>" + html(result.error) + "</pre>The trace keeps every sample up to it.</div>\n";
    }
    section += case_facts(result);
    section += "<h3>Metrics</h3>\n" + metrics_table(result);
    if (!result.failures.empty()) {
        section += "<h3>Failures</h3>\n<ul class=\"failures\">" + failure_items(result) + "</ul>\n";
    }

    std::string drawn;
    if (figures != nullptr) {
        if (figures->system) {
            drawn += figures->system->html(page, FigureContext{case_anchor(index), case_label(index, result), options.report_dir},
                                           result);
        }
        if (!figures->jitter.empty()) drawn += "<h3>Timing jitter</h3>\n" + jitter_table(figures->jitter);
    }
    if (!result.board_io.is_null()) drawn += "<h3>Board I/O (Modbus)</h3>\n" + board_io_table(result.board_io);
    if (drawn.empty()) drawn = "<p class=\"muted\">No flow, dose, vision or jitter data was recorded for this case.</p>\n";
    section += drawn;
    section += "<p class=\"nav\"><a href=\"#cases\">\u2191 case table</a></p>\n</section>\n";
    return section;
}

std::string suite_section(FigurePage& page, const std::vector<CaseResult>& results) {
    const std::vector<SuiteMetric> shared = suite_metrics(results);
    if (shared.empty()) return {};
    std::string section = "<section id=\"suite\">\n<h2>Limited metrics across cases</h2>\n<div class=\"panels\">\n";
    for (std::size_t i = 0; i < shared.size(); ++i) {
        Panel panel = suite_metric_panel(results, shared[i]);
        panel.what = "suite: " + shared[i].name;
        section += "<figure class=\"figure suite-metric\" id=\"suite-" + std::to_string(i + 1) + "\">\n";
        section += page.place(std::move(panel));
        section += "<figcaption><span class=\"mono\">" + html(shared[i].name) +
                   "</span> per case: blue within its limit, red over it, amber over it as the case expects; the red "
                   "dash is the case's limit.</figcaption>\n</figure>\n";
    }
    return section + "</div>\n</section>\n";
}

}  // namespace

HtmlReport render_html_report(const std::vector<CaseResult>& results, const std::vector<CaseFigures>& figures,
                              const RunSummary& summary, const HtmlReportOptions& options) {
    HtmlReport report;
    if (figures.size() != results.size() && !figures.empty()) {
        report.problems.push_back("figures for " + std::to_string(figures.size()) + " cases, results for " +
                                  std::to_string(results.size()) + ": the figures are matched by position");
    }

    FigurePage page;
    std::string body = "<section id=\"cases\">\n<h2>Cases</h2>\n" + summary_table(results) + "</section>\n";
    body += suite_section(page, results);
    for (std::size_t i = 0; i < results.size(); ++i) {
        body += case_section(page, i, results[i], i < figures.size() ? &figures[i] : nullptr, options);
    }
    draw_panels(page.panels(), GnuplotOptions{options.gnuplot, options.gnuplot_time_limit, options.scratch_parent});
    const std::vector<std::string> problems = page.problems();
    report.problems.insert(report.problems.end(), problems.begin(), problems.end());

    std::string& out = report.html;
    // Polyglot markup (well-formed XML as well as HTML), so XML tools can check it.
    out = "<!DOCTYPE html>\n<html xmlns=\"http://www.w3.org/1999/xhtml\" lang=\"en\">\n<head>\n";
    out += "<meta charset=\"utf-8\"/>\n";
    out += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"/>\n";
    out += "<title>" + html(options.title) + ": " + std::to_string(summary.passed) + " passed, " +
           std::to_string(summary.failed) + " failed" +
           (summary.invalid > 0 ? ", " + std::to_string(summary.invalid) + " invalid" : "") + "</title>\n";
    out += "<style>" + std::string(kStyle) + "</style>\n</head>\n<body>\n";
    out += "<header>\n<h1>" + html(options.title) + "</h1>\n";
    out += verdict_text(summary) + run_numbers_table(summary);
    if (!report.problems.empty()) {
        out += "<div class=\"notice\"><strong>Problems with this report</strong> (a figure that could not be drawn "
               "shows the reason in its place):<ul>";
        for (const std::string& problem : report.problems) out += "<li><pre>" + html(problem) + "</pre></li>";
        out += "</ul></div>\n";
    }
    out += "</header>\n";
    out += page.with_panels(body);
    out += "</body>\n</html>\n";
    return report;
}

std::vector<std::string> write_html_report(const std::filesystem::path& file, const std::vector<CaseResult>& results,
                                           const std::vector<CaseFigures>& figures, const RunSummary& summary,
                                           const HtmlReportOptions& options) {
    HtmlReportOptions with_dir = options;
    if (with_dir.report_dir.empty()) with_dir.report_dir = file.parent_path();
    HtmlReport report = render_html_report(results, figures, summary, with_dir);
    write_file_atomically(file, report.html);
    return std::move(report.problems);
}

}  // namespace rig::harness
