#include "harness/regression/history_report.h"

#include "harness/report/sweep.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "harness/output/xml_text.h"
#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

nlohmann::json json_number(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }
nlohmann::json json_optional(const std::optional<double>& value) { return value ? json_number(*value) : nlohmann::json(); }

// A median or value for people: "not measured" for the infinity that stands for a run that gave none.
std::string value_text(double value) { return std::isfinite(value) ? significant_text(value, 4) : "not measured"; }

std::string short_commit(const std::string& commit) { return commit.substr(0, std::min<std::size_t>(commit.size(), 10)); }

std::vector<double> measured_values(const HistoryPoint& point) {
    std::vector<double> values;
    for (const SeedValue& seed : point.seeds) {
        if (seed.value) values.push_back(*seed.value);
    }
    std::sort(values.begin(), values.end());
    return values;
}

// The sweep's percentile (harness/report/sweep.h), at 50: one definition of a median for every page.
std::optional<double> median_of_sorted(const std::vector<double>& sorted) {
    if (sorted.empty()) return std::nullopt;
    return percentile_of_sorted(sorted, 50.0);
}

std::string method_text(const ChangePointOptions& options) {
    return "At each boundary between commits, the Mann-Whitney rank statistic of every seed's value before against "
           "every one after (Pettitt 1979), standardised by its spread under no change (Hawkins and Deng 2010); the "
           "largest over the boundaries is tested by " +
           std::to_string(options.permutations) +
           " permutations of the values (fixed-seed generator, stopped early as Besag and Clifford 1991) at alpha " +
           significant_text(options.alpha, 3) +
           ", and binary segmentation finds further steps. A change point also needs its two sides' medians to "
           "differ by at least the metric's min effect. A run that measured nothing counts as the worst value.";
}

}  // namespace

std::vector<AnalysedBranch> analyse_history(const History& history, const ChangePointOptions& options) {
    std::vector<AnalysedBranch> analysed;
    for (const BranchHistory& branch : history.branches) {
        AnalysedBranch one{&branch, {}};
        for (const HistorySeries& series : branch.series) {
            one.series.push_back({&series, series_change_points(series, options)});
        }
        analysed.push_back(std::move(one));
    }
    return analysed;
}

nlohmann::json history_json(const History& history, const std::vector<AnalysedBranch>& analysed,
                            const ChangePointOptions& options) {
    nlohmann::json json;
    json["schema_version"] = 1;
    json["database"] = valid_utf8(history.database.string());
    json["method"] = {{"text", method_text(options)},
                      {"alpha", options.alpha},
                      {"permutations", options.permutations},
                      {"prng_seed", options.prng_seed},
                      {"order", "commit_order: insertion order per branch, or rig history add --order"}};
    json["branches"] = nlohmann::json::array();
    for (const AnalysedBranch& branch : analysed) {
        nlohmann::json commits = nlohmann::json::array();
        for (const HistoryCommit& commit : branch.branch->commits) {
            commits.push_back({{"commit", commit.commit},
                               {"order", commit.order},
                               {"date", commit.date},
                               {"source", valid_utf8(commit.source)},
                               {"kind", commit.kind},
                               {"rig_version", commit.rig_version},
                               {"rig_commit", commit.rig_commit},
                               {"controller_sha256", commit.controller_sha256},
                               {"controller_config_sha256", commit.controller_config_sha256}});
        }
        nlohmann::json series_list = nlohmann::json::array();
        for (const AnalysedSeries& analysed_series : branch.series) {
            const HistorySeries& series = *analysed_series.series;
            const SeriesChangePoints& judged = analysed_series.judged;
            nlohmann::json points = nlohmann::json::array();
            for (const HistoryPoint& point : series.points) {
                const HistoryCommit& commit = branch.branch->commits[point.commit_index];
                nlohmann::json values = nlohmann::json::array();
                std::size_t not_measured = 0;
                for (const SeedValue& seed : point.seeds) {
                    values.push_back({{"seed", seed.seed}, {"value", json_optional(seed.value)}});
                    if (!seed.value) ++not_measured;
                }
                points.push_back({{"commit", commit.commit},
                                  {"order", commit.order},
                                  {"median", json_optional(median_of_sorted(measured_values(point)))},
                                  {"not_measured", not_measured},
                                  {"limit", json_optional(point.limit)},
                                  {"values", std::move(values)}});
            }
            nlohmann::json changes = nlohmann::json::array();
            for (const ChangePoint& change : judged.change_points) {
                const HistoryCommit& commit = branch.branch->commits[series.points[change.group].commit_index];
                changes.push_back({{"commit", commit.commit},
                                   {"order", commit.order},
                                   {"p_value", change.p_value},
                                   {"before_median", json_number(change.before_median)},
                                   {"after_median", json_number(change.after_median)},
                                   {"shift", json_number(change.shift)},
                                   {"before_values", change.before_values},
                                   {"after_values", change.after_values},
                                   {"worse", change.worse}});
            }
            series_list.push_back({{"case", valid_utf8(series.case_name)},
                                   {"metric", valid_utf8(series.metric)},
                                   {"worse", std::string(worse_direction_name(judged.worse))},
                                   {"declared", judged.declared},
                                   {"min_effect", judged.min_effect},
                                   {"min_effect_from", judged.min_effect_from},
                                   {"points", std::move(points)},
                                   {"change_points", std::move(changes)}});
        }
        json["branches"].push_back(
            {{"branch", branch.branch->branch}, {"commits", std::move(commits)}, {"series", std::move(series_list)}});
    }
    return json;
}

namespace {

// One series as an inline SVG: commits along x (every commit of the branch,
// so a gap shows where the case was not run), the metric up y.
std::string series_svg(const BranchHistory& branch, const AnalysedSeries& analysed) {
    const HistorySeries& series = *analysed.series;
    constexpr double width = 720.0, height = 220.0, left = 64.0, right = 12.0, top = 12.0, bottom = 56.0;
    const std::size_t commits = branch.commits.size();
    const double slot = (width - left - right) / static_cast<double>(std::max<std::size_t>(commits, 1));
    auto x_of = [&](std::size_t index) { return left + slot * (static_cast<double>(index) + 0.5); };
    double low = std::numeric_limits<double>::infinity(), high = -low;
    for (const HistoryPoint& point : series.points) {
        for (double value : measured_values(point)) low = std::min(low, value), high = std::max(high, value);
        if (point.limit) low = std::min(low, *point.limit), high = std::max(high, *point.limit);
    }
    if (!(high - low > 1e-12 * std::max(1.0, std::abs(high)))) {
        const double pad = std::max(1e-9, 0.05 * std::abs(high));
        low -= pad;
        high += pad;
    }
    const double plot_bottom = height - bottom, plot_top = top + 8.0;  // the strip above plot_top holds "not measured"
    auto y_of = [&](double value) { return plot_bottom - (value - low) / (high - low) * (plot_bottom - plot_top); };
    auto at = [](double coordinate) { return fixed_text(coordinate, 1); };

    std::ostringstream svg;
    svg << "<svg viewBox=\"0 0 " << at(width) << " " << at(height) << "\" width=\"" << at(width) << "\" height=\""
        << at(height) << "\" role=\"img\" class=\"series\"><title>" << xml_escape(series.case_name, false) << ": "
        << xml_escape(series.metric, false) << "</title>";
    svg << "<rect x=\"" << at(left) << "\" y=\"" << at(top) << "\" width=\"" << at(width - left - right)
        << "\" height=\"" << at(plot_bottom - top) << "\" fill=\"none\" stroke=\"#bbb\"/>";
    for (const double value : {low, (low + high) / 2.0, high}) {
        svg << "<text x=\"" << at(left - 4) << "\" y=\"" << at(y_of(value) + 4) << "\" text-anchor=\"end\">"
            << xml_escape(significant_text(value, 4), false) << "</text>";
    }
    const std::size_t label_every = std::max<std::size_t>(1, (commits + 23) / 24);
    for (std::size_t index = 0; index < commits; index += label_every) {
        svg << "<text x=\"" << at(x_of(index)) << "\" y=\"" << at(plot_bottom + 10)
            << "\" text-anchor=\"end\" transform=\"rotate(-45 " << at(x_of(index)) << " " << at(plot_bottom + 10)
            << ")\">" << xml_escape(short_commit(branch.commits[index].commit).substr(0, 7), false) << "</text>";
    }
    // The limit: a red step over each commit that had one.
    for (const HistoryPoint& point : series.points) {
        if (!point.limit) continue;
        const double x = x_of(point.commit_index);
        svg << "<line class=\"limit\" x1=\"" << at(x - slot / 2) << "\" y1=\"" << at(y_of(*point.limit)) << "\" x2=\""
            << at(x + slot / 2) << "\" y2=\"" << at(y_of(*point.limit)) << "\"><title>limit "
            << xml_escape(significant_text(*point.limit, 6), false) << "</title></line>";
    }
    // Change points: a dashed line on the boundary before the commit, red when for the worse.
    for (const ChangePoint& change : analysed.judged.change_points) {
        const std::size_t index = series.points[change.group].commit_index;
        const double x = x_of(index) - slot / 2;
        svg << "<line class=\"" << (change.worse ? "change worse" : "change") << "\" x1=\"" << at(x) << "\" y1=\""
            << at(top) << "\" x2=\"" << at(x) << "\" y2=\"" << at(plot_bottom) << "\"><title>change point at "
            << xml_escape(branch.commits[index].commit, false) << ": median " << xml_escape(value_text(change.before_median), false)
            << " to " << xml_escape(value_text(change.after_median), false) << ", p "
            << xml_escape(significant_text(change.p_value, 2), false) << (change.worse ? ", for the worse" : "")
            << "</title></line>";
    }
    // Each commit's seeds, spread across its slot by seed so they do not hide one another; the median line.
    std::string median_line;
    for (const HistoryPoint& point : series.points) {
        const double x = x_of(point.commit_index);
        const std::size_t count = point.seeds.size();
        for (std::size_t k = 0; k < count; ++k) {
            const SeedValue& seed = point.seeds[k];
            const double spread = count > 1 ? (static_cast<double>(k) / static_cast<double>(count - 1) - 0.5) * slot * 0.5 : 0.0;
            if (seed.value) {
                svg << "<circle cx=\"" << at(x + spread) << "\" cy=\"" << at(y_of(*seed.value))
                    << "\" r=\"2\"><title>seed " << seed.seed << ": "
                    << xml_escape(significant_text(*seed.value, 6), false) << "</title></circle>";
            } else {
                svg << "<text class=\"nm\" x=\"" << at(x + spread) << "\" y=\"" << at(top + 7)
                    << "\" text-anchor=\"middle\">&#215;<title>seed " << seed.seed << ": not measured</title></text>";
            }
        }
        if (const std::optional<double> median = median_of_sorted(measured_values(point))) {
            median_line += (median_line.empty() ? "" : " ") + at(x) + "," + at(y_of(*median));
        }
    }
    if (!median_line.empty()) svg << "<polyline class=\"median\" points=\"" << median_line << "\"/>";
    svg << "</svg>";
    return svg.str();
}

}  // namespace

std::string history_html(const History& history, const std::vector<AnalysedBranch>& analysed,
                         const ChangePointOptions& options) {
    std::ostringstream html;
    html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
            "<title>rig history</title><style>"
            "body{font-family:sans-serif;margin:1em;max-width:76em}"
            "table{border-collapse:collapse;margin-bottom:1.5em}"
            "td,th{padding:2px 8px;text-align:left;border-bottom:1px solid #ddd}"
            "svg.series{max-width:100%;height:auto;font-size:10px}"
            "svg circle{fill:#3b78b0;fill-opacity:0.55}svg .nm{fill:#b00}"
            "svg .median{fill:none;stroke:#123;stroke-width:1.5}"
            "svg .limit{stroke:#c00;stroke-width:2}"
            "svg .change{stroke:#777;stroke-width:1.5;stroke-dasharray:4 3}svg .change.worse{stroke:#c00}"
            ".worse{color:#b00}.none{color:#777}"
            "</style></head><body>\n";
    html << "<h1>rig history</h1>\n<p>" << xml_escape(history.database.string(), false) << ": "
         << history.branches.size() << " branch" << (history.branches.size() == 1 ? "" : "es") << ".</p>\n"
         << "<p>" << xml_escape(method_text(options), false) << "</p>\n"
         << "<p>Each plot: a commit's seeds as points (a red &#215; at the top for a run that measured nothing), "
            "their median as the dark line, the case's limit as a red line, a change point as a dashed line before "
            "its commit (red when for the worse). Commits are in their order on the branch: the order they were "
            "added, or rig history add --order.</p>\n";
    for (const AnalysedBranch& branch : analysed) {
        const std::string& name = branch.branch->branch;
        html << "<h2 id=\"branch-" << xml_escape(name, true) << "\">Branch " << xml_escape(name, false) << "</h2>\n";
        html << "<table><tr><th>order</th><th>commit</th><th>date</th><th>rig</th><th>controller</th></tr>\n";
        std::string previous_controller;
        for (const HistoryCommit& commit : branch.branch->commits) {
            const std::string controller = commit.controller_sha256.substr(0, 12) + " " + commit.controller_config_sha256.substr(0, 12);
            html << "<tr><td>" << commit.order << "</td><td>" << xml_escape(commit.commit, false) << "</td><td>"
                 << xml_escape(commit.date, false) << "</td><td>" << xml_escape(commit.rig_version, false)
                 << "</td><td>" << xml_escape(controller, false)
                 << (!previous_controller.empty() && controller != previous_controller ? " (changed)" : "")
                 << "</td></tr>\n";
            previous_controller = controller;
        }
        html << "</table>\n";
        std::string current_case;
        for (const AnalysedSeries& analysed_series : branch.series) {
            const HistorySeries& series = *analysed_series.series;
            const SeriesChangePoints& judged = analysed_series.judged;
            if (series.case_name != current_case) {
                current_case = series.case_name;
                html << "<h3>" << xml_escape(name, false) << ": " << xml_escape(current_case, false) << "</h3>\n";
            }
            html << "<h4>" << xml_escape(series.metric, false) << "</h4>\n<p>";
            if (judged.worse == WorseDirection::none) {
                html << "<span class=\"none\">" << (judged.declared ? "neither better nor worse" : "not declared")
                     << ": shown, never judged</span>";
            } else {
                html << "worse " << worse_direction_name(judged.worse);
            }
            html << "; min effect " << xml_escape(significant_text(judged.min_effect, 4), false) << " ("
                 << judged.min_effect_from << "). ";
            if (judged.change_points.empty()) html << "No change point.";
            for (const ChangePoint& change : judged.change_points) {
                const HistoryCommit& commit = branch.branch->commits[series.points[change.group].commit_index];
                html << "<span" << (change.worse ? " class=\"worse\"" : "") << ">Change point at "
                     << xml_escape(short_commit(commit.commit), false) << " (order " << commit.order << "): median "
                     << xml_escape(value_text(change.before_median), false) << " to "
                     << xml_escape(value_text(change.after_median), false) << ", p "
                     << xml_escape(significant_text(change.p_value, 2), false) << (change.worse ? ", for the worse" : "")
                     << ".</span> ";
            }
            html << "</p>\n";
            bool any_value = false;
            for (const HistoryPoint& point : series.points) any_value = any_value || !measured_values(point).empty();
            if (any_value) {
                html << series_svg(*branch.branch, analysed_series) << "\n";
            } else {
                html << "<p class=\"none\">Never measured.</p>\n";
            }
        }
    }
    html << "</body></html>\n";
    return html.str();
}

HistoryCheck check_history(const History& history, const std::string& branch_name, const ChangePointOptions& options) {
    const std::string wanted = branch_name.empty() ? history.newest_branch : branch_name;
    const auto branch = std::find_if(history.branches.begin(), history.branches.end(),
                                     [&](const BranchHistory& one) { return one.branch == wanted; });
    if (branch == history.branches.end() || branch->commits.empty()) {
        std::string names;
        for (const BranchHistory& one : history.branches) names += (names.empty() ? "" : ", ") + one.branch;
        throw std::invalid_argument(history.database.string() + ": no branch '" + wanted + "' in it (branches: " +
                                    (names.empty() ? "none" : names) + ")");
    }
    HistoryCheck check;
    check.branch = branch->branch;
    check.newest = branch->commits.back();
    const std::size_t newest_index = branch->commits.size() - 1;
    for (const HistorySeries& series : branch->series) {
        if (series.points.empty() || series.points.back().commit_index != newest_index) continue;
        const std::string name = series.case_name + ": " + series.metric;
        const SeriesChangePoints judged = series_change_points(series, options);
        (judged.worse == WorseDirection::none ? check.never_judged : check.checked).push_back(name);
        for (const ChangePoint& change : judged.change_points) {
            if (change.group + 1 != series.points.size()) continue;
            NewestChange found{series.case_name, series.metric, judged.worse, change,
                               judged.min_effect, judged.min_effect_from, series.points.back().limit};
            (change.worse ? check.worse : check.other).push_back(std::move(found));
        }
    }
    return check;
}

std::string history_check_text(const HistoryCheck& check) {
    std::ostringstream out;
    out << "branch " << check.branch << ", newest commit " << check.newest.commit << " (order " << check.newest.order
        << (check.newest.date.empty() ? "" : ", " + check.newest.date) << ")\n";
    out << "checked " << check.checked.size() << " metric" << (check.checked.size() == 1 ? "" : "s")
        << " that can get worse:";
    for (const std::string& name : check.checked) out << "\n  " << name;
    out << "\n";
    if (!check.never_judged.empty()) {
        out << "shown in the report, never judged (declared neither better nor worse, or undeclared): "
            << check.never_judged.size() << "\n";
    }
    auto describe = [&](const NewestChange& change) {
        out << "  " << change.case_name << ": " << change.metric << ": median " << value_text(change.change.before_median)
            << " before, " << value_text(change.change.after_median) << " at this commit (worse "
            << worse_direction_name(change.worse) << ", min effect " << significant_text(change.min_effect, 4) << " from "
            << change.min_effect_from << ", limit "
            << (change.limit ? significant_text(*change.limit, 6) : std::string("none")) << ", p "
            << significant_text(change.change.p_value, 2) << ")\n";
    };
    if (!check.other.empty()) {
        out << "change points at this commit, not for the worse:\n";
        for (const NewestChange& change : check.other) describe(change);
    }
    if (check.worse.empty()) {
        out << "no change point for the worse at " << check.newest.commit << "\n";
    } else {
        out << "CHANGE POINT FOR THE WORSE at " << check.newest.commit << ":\n";
        for (const NewestChange& change : check.worse) describe(change);
    }
    return out.str();
}

}  // namespace rig::harness
