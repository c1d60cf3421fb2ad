#include "harness/report/sweep.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "harness/judge/verdict.h"
#include "harness/output/xml_text.h"
#include "harness/report/build_info.h"
#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Four significant digits: the bands' spread, not the float's last bits.
std::string number(double value) { return std::isnan(value) ? "-" : significant_text(value, 4); }

std::string optional_number(const std::optional<double>& value) { return value ? number(*value) : "-"; }

nlohmann::json json_number(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

nlohmann::json json_optional(const std::optional<double>& value) {
    return value ? json_number(*value) : nlohmann::json();
}

MetricBand band_of(const std::string& metric, const std::vector<const CaseResult*>& runs,
                   const std::optional<double>& limit, const std::optional<double>& paper) {
    MetricBand band;
    band.metric = metric;
    band.limit = limit;
    band.paper = paper;
    std::vector<double> values;
    for (const CaseResult* run : runs) {
        const auto value = run->metrics.find(metric);
        if (value != run->metrics.end() && std::isfinite(value->second)) {
            values.push_back(value->second);
            if (limit && value->second > *limit) ++band.over_limit;
        } else {
            ++band.not_measured;
            if (limit) ++band.over_limit;  // a limited metric that is not measured breaks its limit (docs/metrics.md)
        }
    }
    band.measured = values.size();
    std::sort(values.begin(), values.end());
    band.min = values.empty() ? kNaN : values.front();
    band.max = values.empty() ? kNaN : values.back();
    band.p5 = percentile_of_sorted(values, 5.0);
    band.p50 = percentile_of_sorted(values, 50.0);
    band.p95 = percentile_of_sorted(values, 95.0);
    double sum = 0.0;
    for (double value : values) sum += value;
    band.mean = values.empty() ? kNaN : sum / static_cast<double>(values.size());
    return band;
}

}  // namespace

double percentile_of_sorted(const std::vector<double>& sorted, double p) {
    if (sorted.empty()) return kNaN;
    // Type 7: h = (n - 1) p, between the floor(h)-th and the next (0-based).
    const double h = (static_cast<double>(sorted.size()) - 1.0) * std::clamp(p, 0.0, 100.0) / 100.0;
    const auto below = static_cast<std::size_t>(std::floor(h));
    const std::size_t above = std::min(below + 1, sorted.size() - 1);
    return sorted[below] + (h - static_cast<double>(below)) * (sorted[above] - sorted[below]);
}

std::vector<CaseSweep> summarize_sweep(const std::vector<CaseSpec>& specs, const std::vector<CaseInstance>& runs,
                                       const std::vector<CaseResult>& results) {
    std::vector<CaseSweep> cases;
    for (std::size_t spec_index = 0; spec_index < specs.size(); ++spec_index) {
        const CaseSpec& spec = specs[spec_index];
        CaseSweep sweep;
        sweep.name = spec.name;
        sweep.file = spec.source_path.string();
        sweep.paper_source = spec.paper.source;
        std::vector<const CaseResult*> mine;
        for (std::size_t i = 0; i < runs.size() && i < results.size(); ++i) {
            if (runs[i].spec_index != spec_index) continue;
            const CaseResult& result = results[i];
            mine.push_back(&result);
            ++sweep.runs;
            if (case_invalid(result)) {
                ++sweep.invalid;
            } else if (case_passed(result)) {
                ++sweep.passed;
            }
            if (!case_passed(result)) sweep.failed_seeds.push_back(runs[i].seed);
            if (!result.error.empty() && result.error_kind != result.expected_error) ++sweep.errors;
        }
        std::sort(sweep.failed_seeds.begin(), sweep.failed_seeds.end());
        // The union of what the runs measured, what the case limits and what the paper gives.
        std::set<std::string> metrics;
        std::map<std::string, double> limits;
        for (const CaseResult* run : mine) {
            for (const auto& [name, value] : run->metrics) metrics.insert(name);
            for (const auto& [name, limit] : run->limits) {
                metrics.insert(name);
                limits[name] = limit;
            }
        }
        for (const auto& [name, value] : spec.paper.values) {
            if (!metrics.contains(name)) sweep.paper_unmatched.push_back(name);
        }
        for (const std::string& name : metrics) {
            const auto limit = limits.find(name);
            const auto paper = spec.paper.values.find(name);
            sweep.bands.push_back(band_of(name, mine, limit == limits.end() ? std::nullopt : std::optional(limit->second),
                                          paper == spec.paper.values.end() ? std::nullopt : std::optional(paper->second)));
        }
        cases.push_back(std::move(sweep));
    }
    return cases;
}

std::string sweep_table(const std::vector<CaseSweep>& cases, const SweepInfo& info) {
    std::ostringstream out;
    std::size_t runs = 0, passed = 0;
    for (const CaseSweep& sweep : cases) {
        runs += sweep.runs;
        passed += sweep.passed;
    }
    char header[256];
    std::snprintf(header, sizeof header, "%-34s %-9s %-40s %9s %9s %9s %9s %9s %6s %9s\n", "CASE", "PASS", "METRIC", "P5",
                  "P50", "P95", "MAX", "LIMIT", "OVER", "PAPER");
    out << header;
    for (const CaseSweep& sweep : cases) {
        const std::string pass = std::to_string(sweep.passed) + "/" + std::to_string(sweep.runs);
        bool first = true;
        for (const MetricBand& band : sweep.bands) {
            // The limited and the paper's metrics; the rest are in sweep.json and sweep.html.
            if (!band.limit && !band.paper) continue;
            char line[512];
            std::snprintf(line, sizeof line, "%-34s %-9s %-40s %9s %9s %9s %9s %9s %6s %9s\n",
                          first ? sweep.name.c_str() : "", first ? pass.c_str() : "", band.metric.c_str(),
                          number(band.p5).c_str(), number(band.p50).c_str(), number(band.p95).c_str(),
                          number(band.max).c_str(), optional_number(band.limit).c_str(),
                          band.limit ? std::to_string(band.over_limit).c_str() : "-", optional_number(band.paper).c_str());
            out << line;
            first = false;
        }
        if (first) out << sweep.name << std::string(sweep.name.size() < 35 ? 35 - sweep.name.size() : 1, ' ') << pass << "\n";
        if (!sweep.failed_seeds.empty()) {
            out << std::string(35, ' ') << "did not pass with seed";
            out << (sweep.failed_seeds.size() > 1 ? "s" : "");
            std::size_t shown = 0;
            for (std::uint64_t seed : sweep.failed_seeds) {
                if (shown++ == 20) {
                    out << " ... (" << sweep.failed_seeds.size() << " in all)";
                    break;
                }
                out << " " << seed;
            }
            out << "\n";
        }
    }
    char summary[256];
    std::snprintf(summary, sizeof summary,
                  "sweep: %zu seeds, %zu cases, %zu runs: %zu passed (%.1f %%); %.1f s simulated in %.1f s wall\n",
                  info.seeds.size(), cases.size(), runs, passed,
                  runs == 0 ? 0.0 : 100.0 * static_cast<double>(passed) / static_cast<double>(runs), info.sim_seconds,
                  info.wall_seconds);
    out << summary;
    return out.str();
}

nlohmann::json sweep_json(const std::vector<CaseSweep>& cases, const std::vector<CaseInstance>& runs,
                          const std::vector<CaseResult>& results, const SweepInfo& info) {
    nlohmann::json json;
    json["schema_version"] = 1;
    json["rig"] = {{"version", rig_version()}, {"commit", rig_commit()}};
    json["seeds"] = info.seeds;
    json["started_utc"] = info.started_utc;
    json["wall_seconds"] = info.wall_seconds;
    json["sim_seconds"] = info.sim_seconds;
    json["keep_traces"] = info.keep_traces;
    json["controller_mode"] = info.controller_mode;
    json["percentiles"] = "linear between order statistics (Hyndman-Fan type 7)";
    json["cases"] = nlohmann::json::array();
    for (std::size_t spec_index = 0; spec_index < cases.size(); ++spec_index) {
        const CaseSweep& sweep = cases[spec_index];
        nlohmann::json item = {{"name", sweep.name},
                               {"file", sweep.file},
                               {"runs", sweep.runs},
                               {"passed", sweep.passed},
                               {"pass_rate", sweep.runs == 0 ? 0.0 : static_cast<double>(sweep.passed) / static_cast<double>(sweep.runs)},
                               {"errors", sweep.errors},
                               {"invalid", sweep.invalid},
                               {"failed_seeds", sweep.failed_seeds},
                               {"paper_source", sweep.paper_source.empty() ? nlohmann::json() : nlohmann::json(sweep.paper_source)},
                               {"paper_unmatched", sweep.paper_unmatched}};
        nlohmann::json bands = nlohmann::json::object();
        for (const MetricBand& band : sweep.bands) {
            bands[band.metric] = {{"measured", band.measured},     {"not_measured", band.not_measured},
                                  {"min", json_number(band.min)},   {"p5", json_number(band.p5)},
                                  {"p50", json_number(band.p50)},   {"p95", json_number(band.p95)},
                                  {"max", json_number(band.max)},   {"mean", json_number(band.mean)},
                                  {"limit", json_optional(band.limit)}, {"over_limit", band.over_limit},
                                  {"paper", json_optional(band.paper)}};
        }
        item["bands"] = std::move(bands);
        nlohmann::json seeds = nlohmann::json::array();
        for (std::size_t i = 0; i < runs.size() && i < results.size(); ++i) {
            if (runs[i].spec_index != spec_index) continue;
            const CaseResult& result = results[i];
            nlohmann::json metrics = nlohmann::json::object();
            for (const auto& [name, value] : result.metrics) metrics[name] = json_number(value);
            nlohmann::json seed = {{"seed", runs[i].seed},
                                   {"run", runs[i].name},
                                   {"passed", case_passed(result)},
                                   {"metrics", std::move(metrics)},
                                   {"failures", result.failures},
                                   {"error", result.error.empty() ? nlohmann::json() : nlohmann::json(valid_utf8(result.error))},
                                   {"trace_sha256", result.trace_sha256}};
            // What rig compare needs of each run (docs/regression.md).
            add_run_identity(result, seed);
            seeds.push_back(std::move(seed));
        }
        item["seeds"] = std::move(seeds);
        json["cases"].push_back(std::move(item));
    }
    return json;
}

namespace {

// A band as a 360 x 24 inline SVG on its own scale (the limit and the paper's
// number included, so both are always on it).
std::string band_svg(const MetricBand& band) {
    if (band.measured == 0) return "<span class=\"none\">not measured</span>";
    double lo = band.min, hi = band.max;
    if (band.limit) lo = std::min(lo, *band.limit), hi = std::max(hi, *band.limit);
    if (band.paper) lo = std::min(lo, *band.paper), hi = std::max(hi, *band.paper);
    if (hi - lo <= 1e-12 * std::max(1.0, std::abs(hi))) {
        const double pad = std::max(1e-9, 0.05 * std::abs(hi));
        lo -= pad;
        hi += pad;
    }
    constexpr double left = 8.0, width = 344.0;
    auto x = [&](double v) { return left + (v - lo) / (hi - lo) * width; };
    char text[2048];
    std::string svg = "<svg class=\"band\" viewBox=\"0 0 360 24\" width=\"360\" height=\"24\" role=\"img\">";
    std::snprintf(text, sizeof text,
                  "<title>min %s, p5 %s, p50 %s, p95 %s, max %s; limit %s; paper %s</title>"
                  "<line x1=\"%.2f\" y1=\"12\" x2=\"%.2f\" y2=\"12\" stroke=\"#555\"/>"
                  "<rect x=\"%.2f\" y=\"5\" width=\"%.2f\" height=\"14\" fill=\"#9cc3e6\" stroke=\"#3b78b0\"/>"
                  "<line x1=\"%.2f\" y1=\"3\" x2=\"%.2f\" y2=\"21\" stroke=\"#123\" stroke-width=\"2\"/>",
                  number(band.min).c_str(), number(band.p5).c_str(), number(band.p50).c_str(), number(band.p95).c_str(),
                  number(band.max).c_str(), optional_number(band.limit).c_str(), optional_number(band.paper).c_str(),
                  x(band.min), x(band.max), x(band.p5), std::max(1.0, x(band.p95) - x(band.p5)), x(band.p50),
                  x(band.p50));
    svg += text;
    if (band.limit) {
        std::snprintf(text, sizeof text, "<line x1=\"%.2f\" y1=\"0\" x2=\"%.2f\" y2=\"24\" stroke=\"#c00\" stroke-width=\"2\"/>",
                      x(*band.limit), x(*band.limit));
        svg += text;
    }
    if (band.paper) {
        const double px = x(*band.paper);
        std::snprintf(text, sizeof text, "<polygon points=\"%.2f,6 %.2f,12 %.2f,18 %.2f,12\" fill=\"#000\"/>", px,
                      px + 6, px, px - 6);
        svg += text;
    }
    return svg + "</svg>";
}

}  // namespace

std::string sweep_html(const std::vector<CaseSweep>& cases, const SweepInfo& info) {
    std::ostringstream html;
    html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
            "<title>rig sweep</title><style>"
            "body{font-family:sans-serif;margin:1em;max-width:72em}"
            "table{border-collapse:collapse;margin-bottom:1.5em}"
            "td,th{padding:2px 8px;text-align:right;border-bottom:1px solid #ddd}"
            "td:first-child,th:first-child{text-align:left}"
            ".wrap{overflow-x:auto}.fail{color:#b00}.none{color:#777}"
            "</style></head><body>\n";
    std::size_t runs = 0, passed = 0;
    for (const CaseSweep& sweep : cases) {
        runs += sweep.runs;
        passed += sweep.passed;
    }
    html << "<h1>rig sweep</h1>\n<p>" << info.seeds.size() << " seeds";
    if (!info.seeds.empty()) html << " (" << info.seeds.front() << "-" << info.seeds.back() << ")";
    html << ", " << cases.size() << " case files, " << runs << " runs: " << passed << " passed. "
         << xml_escape(number(info.sim_seconds), false) << " s simulated in " << xml_escape(number(info.wall_seconds), false)
         << " s wall, started " << xml_escape(info.started_utc, false) << ".</p>\n"
         << "<p>Each band: the box spans p5 to p95 of the seeds' values, the dark tick is p50, the whisker min to max; "
            "the red line is the case's limit (an upper bound), the black diamond the paper's number. "
            "Percentiles interpolate linearly between order statistics (Hyndman-Fan type 7).</p>\n";
    for (const CaseSweep& sweep : cases) {
        html << "<h2 id=\"" << xml_escape(sweep.name, true) << "\">" << xml_escape(sweep.name, false) << "</h2>\n<p>"
             << xml_escape(sweep.file, false) << ": <b" << (sweep.passed == sweep.runs ? "" : " class=\"fail\"") << ">"
             << sweep.passed << " of " << sweep.runs << " passed</b>";
        if (!sweep.failed_seeds.empty()) {
            html << "; not with seed" << (sweep.failed_seeds.size() > 1 ? "s" : "");
            for (std::uint64_t seed : sweep.failed_seeds) html << " " << seed;
        }
        if (!sweep.paper_source.empty()) html << ". Paper: " << xml_escape(sweep.paper_source, false);
        html << ".</p>\n";
        for (const std::string& metric : sweep.paper_unmatched) {
            html << "<p class=\"none\">The paper's " << xml_escape(metric, false) << " has no run's value beside it.</p>\n";
        }
        html << "<div class=\"wrap\"><table><tr><th>metric</th><th>band</th><th>p5</th><th>p50</th><th>p95</th>"
                "<th>max</th><th>limit</th><th>over</th><th>paper</th></tr>\n";
        for (const MetricBand& band : sweep.bands) {
            html << "<tr><td>" << xml_escape(band.metric, false) << "</td><td>" << band_svg(band) << "</td><td>"
                 << number(band.p5) << "</td><td>" << number(band.p50) << "</td><td>" << number(band.p95) << "</td><td>"
                 << number(band.max) << "</td><td>" << optional_number(band.limit) << "</td><td"
                 << (band.over_limit > 0 ? " class=\"fail\"" : "") << ">"
                 << (band.limit ? std::to_string(band.over_limit) : "-") << "</td><td>" << optional_number(band.paper)
                 << "</td></tr>\n";
        }
        html << "</table></div>\n";
    }
    html << "</body></html>\n";
    return html.str();
}

}  // namespace rig::harness
