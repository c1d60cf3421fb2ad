#include "harness/regression/compare_report.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "harness/output/xml_text.h"
#include "harness/plot/figure_text.h"
#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

nlohmann::json optional_number(const std::optional<double>& value) {
    return value && std::isfinite(*value) ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

nlohmann::json side_json(const MetricSide& side) {
    return {{"runs", side.runs},
            {"measured", side.measured},
            {"median", optional_number(side.median)},
            {"min", optional_number(side.min)},
            {"max", optional_number(side.max)},
            {"values", side.values},
            {"not_measured_reason", side.not_measured_reason.empty() ? nlohmann::json(nullptr)
                                                                      : nlohmann::json(valid_utf8(side.not_measured_reason))}};
}

nlohmann::json counts_json(const std::map<CompareVerdict, std::size_t>& counts) {
    nlohmann::json json = nlohmann::json::object();
    for (CompareVerdict verdict : {CompareVerdict::regressed, CompareVerdict::improved, CompareVerdict::unchanged,
                                   CompareVerdict::not_comparable}) {
        const auto found = counts.find(verdict);
        json[std::string(compare_verdict_name(verdict))] = found == counts.end() ? 0 : found->second;
    }
    return json;
}

std::string shown(const std::optional<double>& value) {
    return value ? significant_text(*value, 4) : std::string("–");
}

// "1.58 (93 % of 1.7)": the head's value with its margin to the limit.
std::string head_with_limit(const MetricComparison& metric) {
    std::string text = shown(metric.head.median);
    if (metric.head_of_limit && metric.limit) {
        text += " (" + fixed_text(100.0 * *metric.head_of_limit, 0) + " % of " + significant_text(*metric.limit, 4) + ")";
    }
    return text;
}

std::string change_text(const MetricComparison& metric) {
    if (!metric.difference) return "–";
    std::string text = (*metric.difference > 0 ? "+" : "") + significant_text(*metric.difference, 3);
    if (metric.ratio) text += " (x" + significant_text(*metric.ratio, 3) + ")";
    return text;
}

struct Listed {
    const CaseComparison* one;
    const MetricComparison* metric;
};

std::vector<Listed> listed(const Comparison& comparison, CompareVerdict verdict) {
    std::vector<Listed> found;
    for (const CaseComparison& one : comparison.cases) {
        for (const MetricComparison& metric : one.metrics) {
            if (metric.verdict == verdict) found.push_back({&one, &metric});
        }
    }
    return found;
}

std::string what_changed(const Comparison& comparison) {
    std::map<std::string, std::size_t> changed;
    for (const CaseComparison& one : comparison.cases) {
        for (const std::string& what : one.changed) ++changed[what];
    }
    std::string text;
    for (const auto& [what, count] : changed) {
        text += (text.empty() ? "" : ", ") + what + " (" + std::to_string(count) + " cases)";
    }
    if (comparison.rig_differs) text += std::string(text.empty() ? "" : ", ") + "the rig";
    return text.empty() ? "nothing recorded (same controller, case and rig)" : text;
}

std::string markdown_cell(const std::string& text) {
    std::string cell;
    for (char c : text) {
        if (c == '|') {
            cell += "\\|";
        } else if (c == '\n') {
            cell += ' ';
        } else {
            cell += c;
        }
    }
    return cell;
}

void markdown_rows(std::ostringstream& md, const std::vector<Listed>& rows, std::size_t most) {
    md << "| case | metric | base | head | change | why |\n| --- | --- | --- | --- | --- | --- |\n";
    for (std::size_t k = 0; k < rows.size() && k < most; ++k) {
        const MetricComparison& metric = *rows[k].metric;
        md << "| " << markdown_cell(rows[k].one->name) << " | `" << metric.metric << "` | " << shown(metric.base.median)
           << " | " << head_with_limit(metric) << " | " << change_text(metric) << " | " << markdown_cell(metric.reason)
           << " |\n";
    }
    if (rows.size() > most) md << "\n... and " << rows.size() - most << " more in compare.json\n";
}

// One metric's two samples on one axis: each run a dot, the median a tick,
// the limit a red line (a run without a value is drawn at the axis's worst end
// as a hollow dot).
std::string distributions_svg(const MetricComparison& metric) {
    std::vector<double> all = metric.base.values;
    all.insert(all.end(), metric.head.values.begin(), metric.head.values.end());
    if (metric.limit) all.push_back(*metric.limit);
    if (all.empty()) return "";
    double low = *std::min_element(all.begin(), all.end()), high = *std::max_element(all.begin(), all.end());
    if (high - low < 1e-12) {
        low -= 0.5;
        high += 0.5;
    }
    const double pad = 0.05 * (high - low);
    low -= pad;
    high += pad;
    const double left = 60.0, width = 420.0;
    auto x = [&](double value) { return left + (value - low) / (high - low) * width; };
    std::ostringstream svg;
    svg << "<svg viewBox=\"0 0 500 86\" width=\"500\" height=\"86\" role=\"img\">";
    const struct {
        const char* label;
        const MetricSide* side;
        double y;
        const char* colour;
    } rows[] = {{"base", &metric.base, 22.0, "#4a6fa5"}, {"head", &metric.head, 52.0, "#c0392b"}};
    for (const auto& row : rows) {
        svg << "<text x=\"4\" y=\"" << fixed_text(row.y + 4, 1) << "\" font-size=\"12\">" << row.label << "</text>";
        for (double value : row.side->values) {
            svg << "<circle cx=\"" << fixed_text(x(value), 2) << "\" cy=\"" << fixed_text(row.y, 1)
                << "\" r=\"3\" fill=\"" << row.colour << "\" fill-opacity=\"0.6\"/>";
        }
        const double worst_end = metric.worse == WorseDirection::down ? left : left + width;
        for (std::size_t k = row.side->measured; k < row.side->runs; ++k) {
            svg << "<circle cx=\"" << fixed_text(worst_end, 2) << "\" cy=\"" << fixed_text(row.y, 1)
                << "\" r=\"4\" fill=\"none\" stroke=\"" << row.colour << "\"><title>not measured</title></circle>";
        }
        if (row.side->median) {
            svg << "<line x1=\"" << fixed_text(x(*row.side->median), 2) << "\" x2=\"" << fixed_text(x(*row.side->median), 2)
                << "\" y1=\"" << fixed_text(row.y - 10, 1) << "\" y2=\"" << fixed_text(row.y + 10, 1)
                << "\" stroke=\"black\" stroke-width=\"2\"/>";
        }
    }
    if (metric.limit) {
        svg << "<line x1=\"" << fixed_text(x(*metric.limit), 2) << "\" x2=\"" << fixed_text(x(*metric.limit), 2)
            << "\" y1=\"6\" y2=\"66\" stroke=\"red\" stroke-width=\"2\"><title>limit "
            << significant_text(*metric.limit, 4) << "</title></line>";
    }
    svg << "<text x=\"" << fixed_text(left, 1) << "\" y=\"82\" font-size=\"11\">" << html(significant_text(low + pad, 4))
        << "</text><text x=\"" << fixed_text(left + width, 1) << "\" y=\"82\" font-size=\"11\" text-anchor=\"end\">"
        << html(significant_text(high - pad, 4)) << "</text></svg>";
    return svg.str();
}

}  // namespace

nlohmann::json compare_json(const Comparison& comparison) {
    nlohmann::json cases = nlohmann::json::array();
    for (const CaseComparison& one : comparison.cases) {
        nlohmann::json metrics = nlohmann::json::array();
        for (const MetricComparison& metric : one.metrics) {
            metrics.push_back({{"metric", metric.metric},
                               {"verdict", compare_verdict_name(metric.verdict)},
                               {"reason", valid_utf8(metric.reason)},
                               {"worse", worse_direction_name(metric.worse)},
                               {"declared", metric.declared},
                               {"min_effect", metric.min_effect},
                               {"min_effect_from", metric.min_effect_from},
                               {"limit", optional_number(metric.limit)},
                               {"base", side_json(metric.base)},
                               {"head", side_json(metric.head)},
                               {"difference", optional_number(metric.difference)},
                               {"ratio", optional_number(metric.ratio)},
                               {"shift_low", optional_number(metric.shift_low)},
                               {"shift_high", optional_number(metric.shift_high)},
                               {"p_value", optional_number(metric.p_value)},
                               {"p_adjusted", optional_number(metric.p_adjusted)},
                               {"head_of_limit", optional_number(metric.head_of_limit)}});
        }
        cases.push_back({{"name", valid_utf8(one.name)},
                         {"verdict", compare_verdict_name(one.verdict)},
                         {"reason", valid_utf8(one.reason)},
                         {"method", one.method.empty() ? nlohmann::json(nullptr) : nlohmann::json(one.method)},
                         {"base_file", valid_utf8(one.base_file)},
                         {"head_file", valid_utf8(one.head_file)},
                         {"base_seeds", one.base_seeds},
                         {"head_seeds", one.head_seeds},
                         {"paired_seeds", one.paired_seeds},
                         {"same_traces", one.same_traces},
                         {"changed", one.changed},
                         {"metrics", std::move(metrics)}});
    }
    nlohmann::json min_effects = comparison.settings.min_effects;
    return {{"schema_version", kCompareSchemaVersion},
            {"base", {{"source", valid_utf8(comparison.base_source)}, {"kind", comparison.base_kind}, {"rig", comparison.base_rig}}},
            {"head", {{"source", valid_utf8(comparison.head_source)}, {"kind", comparison.head_kind}, {"rig", comparison.head_rig}}},
            {"rig_differs", comparison.rig_differs},
            {"settings",
             {{"alpha", comparison.settings.alpha},
              {"test", "Mann-Whitney U, two-sided; exact without ties up to 50 runs a side, else normal with the tie correction"},
              {"correction", "Holm over every U test of a metric with a direction in this comparison"},
              {"tests", comparison.tests},
              {"interval", "Hodges-Lehmann shift, distribution-free interval at 1 - alpha"},
              {"any_seeds", comparison.settings.any_seeds},
              {"min_effects", std::move(min_effects)}}},
            {"summary", {{"cases", counts_json(comparison.case_counts)}, {"metrics", counts_json(comparison.metric_counts)}}},
            {"cases", std::move(cases)}};
}

std::string compare_markdown(const Comparison& comparison) {
    std::ostringstream md;
    const std::vector<Listed> regressed = listed(comparison, CompareVerdict::regressed);
    const std::vector<Listed> improved = listed(comparison, CompareVerdict::improved);
    md << "### rig compare: " << (regressed.empty() ? "no regression" : std::to_string(regressed.size()) + " regressed")
       << ", " << improved.size() << " improved\n\n";
    md << "base `" << comparison.base_source << "` (rig " << comparison.base_rig << "), head `" << comparison.head_source
       << "` (rig " << comparison.head_rig << ")  \nwhat changed: " << what_changed(comparison) << "\n";
    if (comparison.rig_differs) md << "\n**The rig differs between the two: a difference may be the rig's, not the controller's.**\n";
    if (!regressed.empty()) {
        md << "\n#### Regressed\n\n";
        markdown_rows(md, regressed, 30);
    }
    if (!improved.empty()) {
        md << "\n#### Improved\n\n";
        markdown_rows(md, improved, 10);
    }
    std::vector<const CaseComparison*> not_comparable;
    for (const CaseComparison& one : comparison.cases) {
        if (one.verdict == CompareVerdict::not_comparable) not_comparable.push_back(&one);
    }
    if (!not_comparable.empty()) {
        md << "\n#### Not comparable\n\n";
        for (std::size_t k = 0; k < not_comparable.size() && k < 10; ++k) {
            md << "- " << markdown_cell(not_comparable[k]->name) << ": " << markdown_cell(not_comparable[k]->reason) << "\n";
        }
        if (not_comparable.size() > 10) md << "- ... and " << not_comparable.size() - 10 << " more\n";
    }
    const auto count = [&](CompareVerdict verdict) {
        const auto found = comparison.case_counts.find(verdict);
        return found == comparison.case_counts.end() ? std::size_t{0} : found->second;
    };
    md << "\n" << comparison.cases.size() << " cases: " << count(CompareVerdict::regressed) << " regressed, "
       << count(CompareVerdict::improved) << " improved, " << count(CompareVerdict::unchanged) << " unchanged, "
       << count(CompareVerdict::not_comparable) << " not comparable; alpha " << significant_text(comparison.settings.alpha, 3)
       << " over " << comparison.tests << " tests (Holm)\n";
    return md.str();
}

std::string compare_html(const Comparison& comparison) {
    std::ostringstream page;
    page << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"/><title>rig compare</title><style>"
            "body{font-family:sans-serif;margin:1.5em}table{border-collapse:collapse}td,th{padding:3px 8px;"
            "border-bottom:1px solid #ddd;text-align:left;vertical-align:middle}.regressed{color:#b00}"
            ".improved{color:#070}</style></head><body>\n";
    page << "<h1>rig compare</h1><p>base <code>" << html(comparison.base_source) << "</code> (rig "
         << html(comparison.base_rig) << ")<br/>head <code>" << html(comparison.head_source) << "</code> (rig "
         << html(comparison.head_rig) << ")<br/>what changed: " << html(what_changed(comparison)) << "</p>\n";
    if (comparison.rig_differs) {
        page << "<p><b>The rig differs between the two: a difference may be the rig's, not the controller's.</b></p>\n";
    }
    for (CompareVerdict verdict : {CompareVerdict::regressed, CompareVerdict::improved}) {
        const std::vector<Listed> rows = listed(comparison, verdict);
        const std::string name(compare_verdict_name(verdict));
        page << "<h2 class=\"" << name << "\">" << rows.size() << " " << name << "</h2>\n";
        if (rows.empty()) continue;
        page << "<table><tr><th>case</th><th>metric</th><th>base &#8594; head (dots: runs; tick: median; red: limit)</th>"
                "<th>why</th></tr>\n";
        for (const Listed& row : rows) {
            page << "<tr><td>" << html(row.one->name) << "</td><td><code>" << html(row.metric->metric) << "</code></td><td>"
                 << distributions_svg(*row.metric) << "</td><td>" << html(row.metric->reason) << "</td></tr>\n";
        }
        page << "</table>\n";
    }
    page << "<h2>Every case</h2><table><tr><th>case</th><th>verdict</th><th>why</th></tr>\n";
    for (const CaseComparison& one : comparison.cases) {
        const std::string name(compare_verdict_name(one.verdict));
        page << "<tr><td>" << html(one.name) << "</td><td class=\"" << name << "\">" << name << "</td><td>"
             << html(one.reason) << "</td></tr>\n";
    }
    page << "</table></body></html>\n";
    return page.str();
}

std::string compare_junit(const Comparison& comparison) {
    std::size_t tests = 0;
    std::string body;
    for (const CaseComparison& one : comparison.cases) {
        bool any_regressed = false;
        for (const MetricComparison& metric : one.metrics) {
            if (metric.verdict != CompareVerdict::regressed) continue;
            any_regressed = true;
            ++tests;
            body += "  <testcase classname=\"compare." + xml_escape(one.name, true) + "\" name=\"" +
                    xml_escape(metric.metric, true) + "\">\n    <failure message=\"" +
                    xml_escape(metric.metric + " regressed: " + metric.reason, true) + "\" type=\"regressed\">" +
                    xml_escape(one.name + ": " + metric.metric + " regressed: " + metric.reason, false) +
                    "</failure>\n  </testcase>\n";
        }
        if (any_regressed) continue;
        ++tests;
        body += "  <testcase classname=\"compare." + xml_escape(one.name, true) + "\" name=\"" +
                xml_escape(std::string(compare_verdict_name(one.verdict)), true) + "\">\n";
        if (one.verdict == CompareVerdict::not_comparable) {
            body += "    <skipped message=\"" + xml_escape(one.reason, true) + "\"/>\n";
        } else {
            body += "    <system-out>" + xml_escape(one.reason, false) + "</system-out>\n";
        }
        body += "  </testcase>\n";
    }
    std::size_t skipped = 0;
    for (const CaseComparison& one : comparison.cases) skipped += one.verdict == CompareVerdict::not_comparable ? 1 : 0;
    return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites>\n<testsuite name=\"rig compare\" tests=\"" +
           std::to_string(tests) + "\" failures=\"" + std::to_string(comparison.regressions()) + "\" errors=\"0\" skipped=\"" +
           std::to_string(skipped) + "\">\n" + body + "</testsuite>\n</testsuites>\n";
}

std::string compare_table(const Comparison& comparison) {
    std::ostringstream out;
    for (CompareVerdict verdict : {CompareVerdict::regressed, CompareVerdict::improved}) {
        for (const Listed& row : listed(comparison, verdict)) {
            out << (verdict == CompareVerdict::regressed ? "REGRESSED " : "improved  ") << row.one->name << " "
                << row.metric->metric << ": " << row.metric->reason << "\n";
        }
    }
    for (const CaseComparison& one : comparison.cases) {
        if (one.verdict == CompareVerdict::not_comparable) out << "not comparable " << one.name << ": " << one.reason << "\n";
    }
    if (comparison.rig_differs) {
        out << "note: the rig differs (" << comparison.base_rig << " / " << comparison.head_rig
            << "): a difference may be the rig's\n";
    }
    const auto count = [&](CompareVerdict verdict) {
        const auto found = comparison.case_counts.find(verdict);
        return found == comparison.case_counts.end() ? std::size_t{0} : found->second;
    };
    out << comparison.cases.size() << " cases: " << count(CompareVerdict::regressed) << " regressed, "
        << count(CompareVerdict::improved) << " improved, " << count(CompareVerdict::unchanged) << " unchanged, "
        << count(CompareVerdict::not_comparable) << " not comparable (" << comparison.regressions()
        << " metric regressions; alpha " << significant_text(comparison.settings.alpha, 3) << " over "
        << comparison.tests << " tests, Holm)\n";
    return out.str();
}

}  // namespace rig::harness
