#include "harness/falsify/falsify_report.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "harness/plot/gnuplot_panel.h"
#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

// The run of a point its margin is: the first invalid, else the first broken,
// else the one with the smallest margin (worst_margin's choice).
std::optional<std::size_t> worst_run_of(const PointRuns& point) {
    std::optional<std::size_t> worst;
    for (std::size_t index = 0; index < point.margins.size(); ++index) {
        if (!point.margins[index].invalid.empty()) return index;
    }
    for (std::size_t index = 0; index < point.margins.size(); ++index) {
        if (!point.margins[index].broken.empty()) return index;
    }
    for (std::size_t index = 0; index < point.margins.size(); ++index) {
        const auto& margin = point.margins[index].margin;
        if (margin && (!worst || *margin < *point.margins[*worst].margin)) worst = index;
    }
    return worst;
}

nlohmann::json text_or_null(const std::string& text) {
    return text.empty() ? nlohmann::json(nullptr) : nlohmann::json(text);
}

nlohmann::json margin_json(const RunMargin& margin) {
    return nlohmann::json{{"margin", margin.margin ? nlohmann::json(*margin.margin) : nlohmann::json(nullptr)},
                          {"falsifying", margin.invalid.empty() && margin.falsifying()},
                          {"limiting_metric", text_or_null(margin.limiting_metric)},
                          {"broken", text_or_null(margin.broken)},
                          {"invalid", text_or_null(margin.invalid)}};
}

// "vehicle.speed_km_h=9.1 gnss.latency_s=0.2": the point's values as set.
std::string point_text(const FalsifyRecord& record, const SearchedPoint& point) {
    std::string text;
    for (std::size_t index = 0; index < record.search_case.ranges.size(); ++index) {
        const VaryRange& range = record.search_case.ranges[index];
        text += (index == 0 ? "" : " ") + range.key + "=" + value_text(range, point.values[index]);
    }
    return text;
}

// "overlap_m 3.57 against its limit 3.3", or why there is no number.
std::string margin_reason(const FalsifyRecord& record, std::size_t point_index) {
    const RunMargin& margin = record.outcome.points[point_index].margin;
    if (!margin.broken.empty()) return margin.broken;
    if (!margin.invalid.empty()) return margin.invalid;
    const PointRuns& runs = record.point_runs[point_index];
    const std::optional<std::size_t> worst = worst_run_of(runs);
    if (!worst) return "";
    const CaseResult& result = runs.runs[*worst];
    const auto value = result.metrics.find(margin.limiting_metric);
    const auto limit = result.limits.find(margin.limiting_metric);
    if (value == result.metrics.end() || limit == result.limits.end()) return margin.limiting_metric;
    return margin.limiting_metric + " " + significant_text_against(value->second, limit->second) + " against its limit " +
           significant_text_against(limit->second, value->second) +
           (record.search_case.seeds.size() > 1 ? " on seed " + std::to_string(result.seed) : "");
}

std::string margin_text(const RunMargin& margin) {
    if (margin.margin) return significant_text(*margin.margin, 4);
    return margin.broken.empty() ? "invalid" : "broken";
}

}  // namespace

std::size_t runs_made(const FalsifyRecord& record) {
    std::size_t runs = 0;
    for (const PointRuns& point : record.point_runs) runs += point.runs.size();
    return runs;
}

nlohmann::json falsify_json(const FalsifyRecord& record) {
    const FalsifyCase& search = record.search_case;
    nlohmann::json vary = nlohmann::json::array();
    for (const VaryRange& range : search.ranges) {
        if (range.is_choice()) {
            vary.push_back({{"key", range.key}, {"choices", range.choices}, {"base", range.base_text}});
        } else {
            vary.push_back({{"key", range.key}, {"low", range.low}, {"high", range.high}, {"integer", range.integer},
                            {"base", range.base}});
        }
    }
    nlohmann::json settings = nlohmann::json::object();
    for (const KeySetting& setting : search.settings) settings[setting.key] = setting.value;
    nlohmann::json points = nlohmann::json::array();
    for (std::size_t index = 0; index < record.outcome.points.size(); ++index) {
        const SearchedPoint& point = record.outcome.points[index];
        const PointRuns& runs = record.point_runs[index];
        nlohmann::json parameters = nlohmann::json::object();
        for (std::size_t key = 0; key < search.ranges.size(); ++key) {
            const VaryRange& range = search.ranges[key];
            if (range.is_choice()) {
                parameters[range.key] = value_text(range, point.values[key]);
            } else {
                parameters[range.key] = point.values[key];
            }
        }
        nlohmann::json seeds = nlohmann::json::array();
        for (std::size_t run = 0; run < runs.runs.size(); ++run) {
            const CaseResult& result = runs.runs[run];
            nlohmann::json one = margin_json(runs.margins[run]);
            one["seed"] = result.seed;
            one["metrics"] = result.metrics;  // NaN dumps as null
            one["not_measured"] = result.not_measured;
            one["error"] = text_or_null(result.error);
            one["trace_sha256"] = text_or_null(result.trace_sha256);
            seeds.push_back(std::move(one));
        }
        nlohmann::json one = margin_json(point.margin);
        one["index"] = index + 1;
        one["phase"] = point.phase;
        one["parameters"] = std::move(parameters);
        one["runs"] = std::move(seeds);
        points.push_back(std::move(one));
    }
    const auto ordinal = [](const std::optional<std::size_t>& index) {
        return index ? nlohmann::json(*index + 1) : nlohmann::json(nullptr);
    };
    return nlohmann::json{
        {"schema_version", kFalsifySchemaVersion},
        {"case", search.file.string()},
        {"search_file", record.search_file.empty() ? nlohmann::json(nullptr) : nlohmann::json(record.search_file.string())},
        {"settings", std::move(settings)},
        {"vary", std::move(vary)},
        {"metrics", search.metrics},
        {"seeds", search.seeds},
        {"method", std::string(search_method_name(record.options.method))},
        {"budget", record.options.budget},
        {"start_points", std::count_if(record.outcome.points.begin(), record.outcome.points.end(),
                                       [](const SearchedPoint& point) { return point.phase == "start"; })},
        {"search_seed", record.options.seed},
        {"first", record.options.stop_at_first},
        {"points_evaluated", record.outcome.points.size()},
        {"runs", runs_made(record)},
        {"repeated_requests", record.outcome.repeated_requests},
        {"first_falsifying", ordinal(record.outcome.first_falsifying)},
        {"worst", ordinal(record.outcome.worst)},
        {"wall_seconds", record.wall_seconds},
        {"points", std::move(points)},
    };
}

std::vector<KeySetting> worst_settings(const FalsifyRecord& record) {
    if (!record.outcome.worst) return {};
    const std::size_t index = *record.outcome.worst;
    std::vector<KeySetting> settings = record.point_runs[index].settings;
    const std::optional<std::size_t> run = worst_run_of(record.point_runs[index]);
    if (run && record.case_writes_seed && !record.case_has_seed_list) {
        const std::uint64_t seed = record.point_runs[index].runs[*run].seed;
        if (seed != record.case_seed) settings.push_back(KeySetting{"seed", std::to_string(seed)});
    }
    return settings;
}

std::string worst_case_text(const FalsifyRecord& record) {
    if (!record.outcome.worst) return "";
    const std::size_t index = *record.outcome.worst;
    const SearchedPoint& point = record.outcome.points[index];
    const std::vector<KeySetting> settings = worst_settings(record);
    std::string header = "# Written by rig falsify: the worst point (" + std::to_string(index + 1) + " of " +
                         std::to_string(record.outcome.points.size()) + ", method " +
                         std::string(search_method_name(record.options.method)) + ") of a search of " +
                         record.search_case.file.string() + "\n";
    if (!record.search_file.empty()) header += "# (the search " + record.search_file.string() + ")\n";
    header += "# over";
    for (const VaryRange& range : record.search_case.ranges) {
        header += " " + range_text(range);
    }
    header += ".\n# Margin " + margin_text(point.margin) + ": " + margin_reason(record, index) + ".\n";
    header += "# Written in below: " + settings_text(settings) + "\n";
    const std::optional<std::size_t> run = worst_run_of(record.point_runs[index]);
    const bool seed_written = std::any_of(settings.begin(), settings.end(),
                                          [](const KeySetting& setting) { return setting.key == "seed"; });
    if (run && !seed_written && record.point_runs[index].runs[*run].seed != record.case_seed) {
        header += "# Its worst run is on seed " + std::to_string(record.point_runs[index].runs[*run].seed) +
                  ": rig run worst.yaml --seed " + std::to_string(record.point_runs[index].runs[*run].seed) + "\n";
    }
    return header + apply_key_settings(record.base_text, record.search_case.file.string(), settings);
}

std::string falsify_summary(const FalsifyRecord& record, const std::filesystem::path& out_dir) {
    const SearchOutcome& outcome = record.outcome;
    const std::string counts = std::to_string(outcome.points.size()) + " point(s), " +
                               std::to_string(runs_made(record)) + " run(s)";
    const std::string worst_file = (out_dir / "worst.yaml").string();
    const auto point_line = [&](std::size_t index) {
        return "point " + std::to_string(index + 1) + ": " + point_text(record, outcome.points[index]) + ": margin " +
               margin_text(outcome.points[index].margin) + " (" + margin_reason(record, index) + ")";
    };
    if (outcome.first_falsifying) {
        std::string line = "rig falsify: FALSIFIED " + record.search_case.file.string() + " in " + counts +
                           "; first at " + point_line(*outcome.first_falsifying);
        if (outcome.worst && *outcome.worst != *outcome.first_falsifying) line += "; worst at " + point_line(*outcome.worst);
        return line + "; worst: " + worst_file;
    }
    if (!outcome.worst) {
        return "rig falsify: no point of " + record.search_case.file.string() + " could be judged in " + counts +
               " (every one invalid: see falsify.json)";
    }
    const std::size_t worst = *outcome.worst;
    return "rig falsify: no falsifying point of " + record.search_case.file.string() + " in " + counts +
           "; smallest margin " + margin_text(outcome.points[worst].margin) + " (" + margin_reason(record, worst) +
           ") at " + point_text(record, outcome.points[worst]) + ": " + worst_file;
}

namespace {

bool counts_as_falsifying(const RunMargin& margin) { return margin.invalid.empty() && margin.falsifying(); }

// A parameter's axis: its range, or its choices as named tics at their
// indexes (where the points of a choice are drawn).
std::string axis_script(const std::string& axis, const VaryRange& range) {
    if (!range.is_choice()) {
        return "set " + axis + "range [" + exact_number(range.low) + ":" + exact_number(range.high) + "]\n";
    }
    std::string tics;
    for (std::size_t index = 0; index < range.choices.size(); ++index) {
        tics += (index == 0 ? "" : ", ") + gnuplot_string(range.choices[index]) + " " + std::to_string(index);
    }
    return "set " + axis + "range [-0.5:" + exact_number(static_cast<double>(range.choices.size()) - 0.5) + "]\nset " +
           axis + "tics (" + tics + ")\n";
}

// The margin over one parameter: each point, the falsifying ones marked, the
// limit (margin 0) as a line; a broken point (no number) at the bottom.
Panel parameter_panel(const FalsifyRecord& record, std::size_t key) {
    const VaryRange& range = record.search_case.ranges[key];
    std::vector<std::vector<double>> passing;
    std::vector<std::vector<double>> falsifying;
    std::vector<double> broken_at;
    Extent margins;
    margins.include(0.0);
    for (const SearchedPoint& point : record.outcome.points) {
        if (point.margin.margin) {
            margins.include(*point.margin.margin);
            (counts_as_falsifying(point.margin) ? falsifying : passing).push_back({point.values[key], *point.margin.margin});
        } else if (!point.margin.broken.empty()) {
            broken_at.push_back(point.values[key]);
        }
    }
    const double bottom = margins.low - 0.1 * std::max(margins.high - margins.low, 0.1);
    margins.include(bottom);
    std::vector<std::vector<double>> broken;
    for (const double x : broken_at) broken.push_back({x, bottom});
    Panel panel;
    panel.what = "margin over " + range.key;
    panel.caption = "the margin over " + range.key;
    std::string& script = panel.script;
    script += data_block("passing", passing) + data_block("falsifying", falsifying) + data_block("broken", broken);
    script += "set title " + gnuplot_string("margin over " + range.key) + "\n";
    script += "set xlabel " + gnuplot_string(range.key) + "\nset ylabel 'margin (fraction of the limit)'\n";
    script += axis_script("x", range);
    script += "set yrange " + margins.range(0.05, 0.08) + "\n";
    script += "set grid\nset key outside bottom center horizontal\n";
    script += "plot 0 with lines lw 2 dt 2 lc " + rgb(kLimitColor) + " title 'the limit (margin 0)', "
              "$passing using 1:2 with points pt 7 ps 0.8 lc " + rgb(kTruthColor) + " title 'holds', "
              "$falsifying using 1:2 with points pt 9 ps 1.3 lc " + rgb(kLimitColor) + " title 'breaks a limit', "
              "$broken using 1:2 with points pt 11 ps 1.3 lc " + rgb(kBreakpointColor) +
              " title 'broken, no value (drawn at the bottom)'\n";
    return panel;
}

// Where a pair's plane breaks a limit, as far as the points say: each cell
// of a grid over the pair's ranges takes the verdict most of its three
// nearest judged points have (distances in each axis as a fraction of its
// range). The search's other parameters are projected away, so this is the
// points' own verdicts spread over the plane, not a margin interpolated
// between them: inverse-distance interpolation of the margins drew rings
// around single points and lines where no boundary was (margins from +0.2 to
// -3.7, the third parameter varying underneath).
struct JudgedPoint {
    double x = 0.0;
    double y = 0.0;
    bool falsifying = false;
};

// A gnuplot rgbimage block: x y r g b per cell, scan lines apart.
std::string verdict_regions(const std::vector<JudgedPoint>& judged, const VaryRange& x, const VaryRange& y) {
    constexpr int kCells = 60;
    constexpr std::size_t kNearest = 3;
    const auto axis_low = [](const VaryRange& range) { return range.is_choice() ? -0.5 : range.low; };
    const auto axis_high = [](const VaryRange& range) {
        return range.is_choice() ? static_cast<double>(range.choices.size()) - 0.5 : range.high;
    };
    const double x_low = axis_low(x);
    const double x_width = axis_high(x) - x_low;
    const double y_low = axis_low(y);
    const double y_width = axis_high(y) - y_low;
    std::string block = "$regions << EOD\n";
    std::vector<std::pair<double, bool>> nearest;
    for (int row = 0; row < kCells; ++row) {
        const double at_y = y_low + (row + 0.5) * y_width / kCells;
        for (int column = 0; column < kCells; ++column) {
            const double at_x = x_low + (column + 0.5) * x_width / kCells;
            nearest.clear();
            for (const JudgedPoint& point : judged) {
                const double dx = (point.x - at_x) / x_width;
                const double dy = (point.y - at_y) / y_width;
                nearest.emplace_back(dx * dx + dy * dy, point.falsifying);
            }
            const std::size_t count = std::min(kNearest, nearest.size());
            std::partial_sort(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(count), nearest.end());
            const auto breaking = std::count_if(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(count),
                                                [](const auto& near) { return near.second; });
            const bool breaks = 2 * static_cast<std::size_t>(breaking) > count;
            block += exact_number(at_x) + " " + exact_number(at_y) + (breaks ? " 253 224 221\n" : " 255 255 255\n");
        }
        block += "\n";
    }
    return block + "EOD\n";
}

// The margin over a pair of parameters: each point coloured by its margin,
// the falsifying ones marked, and the plane shaded where the nearest points
// break a limit (verdict_regions).
Panel pair_panel(const FalsifyRecord& record, std::size_t first, std::size_t second) {
    const VaryRange& x = record.search_case.ranges[first];
    const VaryRange& y = record.search_case.ranges[second];
    std::vector<std::vector<double>> points;
    std::vector<std::vector<double>> falsifying;
    std::vector<JudgedPoint> judged;
    double largest = 0.0;
    for (const SearchedPoint& point : record.outcome.points) {
        const bool breaks = counts_as_falsifying(point.margin);
        if (breaks) falsifying.push_back({point.values[first], point.values[second]});
        // An invalid point says nothing of the controller; a broken one breaks.
        if (point.margin.invalid.empty() && (point.margin.margin || breaks)) {
            judged.push_back({point.values[first], point.values[second], breaks});
        }
        if (!point.margin.margin) continue;
        points.push_back({point.values[first], point.values[second], *point.margin.margin});
        largest = std::max(largest, std::fabs(*point.margin.margin));
    }
    if (largest == 0.0) largest = 1.0;
    Panel panel;
    panel.what = "margin over " + x.key + " and " + y.key;
    panel.caption = panel.what + "; shaded where the three nearest points (in these two parameters) mostly break a limit";
    panel.height = 480;
    std::string& script = panel.script;
    script += data_block("points", points) + data_block("falsifying", falsifying);
    const bool shaded = !judged.empty();
    if (shaded) script += verdict_regions(judged, x, y);
    script += "set title " + gnuplot_string("margin over " + x.key + " and " + y.key) + "\n";
    script += "set xlabel " + gnuplot_string(x.key) + "\nset ylabel " + gnuplot_string(y.key) + "\n";
    script += axis_script("x", x) + axis_script("y", y);
    script += "set palette defined (-1 '#d62728', 0 '#f7f7f7', 1 '#1f77b4')\n";
    script += "set cbrange [" + exact_number(-largest) + ":" + exact_number(largest) + "]\nset cblabel 'margin'\n";
    script += "set grid front\nset key outside bottom center horizontal\nplot ";
    if (shaded) {
        script += "$regions using 1:2:3:4:5 with rgbimage title 'shaded: the nearest points mostly break a limit', ";
    }
    // Each point outlined: a margin near 0 is near white in the palette.
    script += "$points using 1:2:3 with points pt 7 ps 1.1 lc palette title 'points (colour: margin)', "
              "$points using 1:2 with points pt 6 ps 1.1 lc rgb '#555555' notitle";
    script += ", $falsifying using 1:2 with points pt 2 ps 1.6 lw 2 lc rgb '#000000' title 'breaks a limit'\n";
    return panel;
}

constexpr std::string_view kFalsifyStyle = R"(
body { font-family: system-ui, sans-serif; color: #222; margin: 1.5em auto; max-width: 1240px; padding: 0 1.2em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.2em 0.5em; text-align: left; }
tr.falsifying td { background: #fde0dd; }
.summary { font-weight: 600; }
)";

}  // namespace

std::string falsify_html(const FalsifyRecord& record, std::vector<std::string>& problems) {
    const FalsifyCase& search = record.search_case;
    FigurePage page;
    std::string body = "<h2>The margin over each parameter</h2>\n";
    for (std::size_t key = 0; key < search.ranges.size(); ++key) body += page.place(parameter_panel(record, key));
    if (search.ranges.size() > 1) {
        body += "<h2>The margin over each pair of parameters</h2>\n";
        for (std::size_t first = 0; first < search.ranges.size(); ++first) {
            for (std::size_t second = first + 1; second < search.ranges.size(); ++second) {
                body += page.place(pair_panel(record, first, second));
            }
        }
    }
    body += "<h2>Every point</h2>\n<table><tr><th>#</th><th>phase</th>";
    for (const VaryRange& range : search.ranges) body += "<th>" + html(range.key) + "</th>";
    body += "<th>margin</th><th>why</th></tr>\n";
    for (std::size_t index = 0; index < record.outcome.points.size(); ++index) {
        const SearchedPoint& point = record.outcome.points[index];
        body += std::string("<tr") + (counts_as_falsifying(point.margin) ? " class=\"falsifying\"" : "") + "><td>" +
                std::to_string(index + 1) + "</td><td>" + html(point.phase) + "</td>";
        for (std::size_t key = 0; key < search.ranges.size(); ++key) {
            body += "<td>" + html(value_text(search.ranges[key], point.values[key])) + "</td>";
        }
        body += "<td>" + html(margin_text(point.margin)) + "</td><td>" + html(margin_reason(record, index)) + "</td></tr>\n";
    }
    body += "</table>\n";
    draw_panels(page.panels(), GnuplotOptions{});
    const std::vector<std::string> drawn_problems = page.problems();
    problems.insert(problems.end(), drawn_problems.begin(), drawn_problems.end());

    std::string out = "<!DOCTYPE html>\n<html xmlns=\"http://www.w3.org/1999/xhtml\" lang=\"en\">\n<head>\n"
                      "<meta charset=\"utf-8\"/>\n<title>rig falsify: " + html(search.file.string()) + "</title>\n"
                      "<style>" + std::string(kFalsifyStyle) + "</style>\n</head>\n<body>\n";
    out += "<h1>rig falsify: " + html(search.file.string()) + "</h1>\n";
    out += "<p class=\"summary\">" + html(falsify_summary(record, ".")) + "</p>\n";
    out += "<p>Method " + html(std::string(search_method_name(record.options.method))) + ", budget " +
           std::to_string(record.options.budget) + " points, " + std::to_string(search.seeds.size()) +
           " seed(s) per point (a point's margin is its worst seed's); metrics judged: ";
    for (std::size_t index = 0; index < search.metrics.size(); ++index) {
        out += (index == 0 ? "" : ", ") + html(search.metrics[index]);
    }
    out += ". A margin is (limit - value) / |limit|: below 0 the limit is broken.</p>\n";
    out += "<table><tr><th>key</th><th>range</th><th>base</th></tr>\n";
    for (const VaryRange& range : search.ranges) {
        std::string values = shortest_text(range.low) + " .. " + shortest_text(range.high);
        if (range.is_choice()) {
            values.clear();
            for (const std::string& choice : range.choices) values += (values.empty() ? "" : ", ") + choice;
        }
        out += "<tr><td>" + html(range.key) + "</td><td>" + html(values) + "</td><td>" + html(range.base_text) +
               "</td></tr>\n";
    }
    out += "</table>\n";
    if (!problems.empty()) {
        out += "<p>Problems with this page:</p><ul>";
        for (const std::string& problem : problems) out += "<li>" + html(problem) + "</li>";
        out += "</ul>\n";
    }
    out += page.with_panels(body) + "</body>\n</html>\n";
    return out;
}

}  // namespace rig::harness
