#include "harness/systems/breakpoint/breakpoint_figures.h"

#include <algorithm>
#include <cmath>
#include <string_view>

namespace rig::harness {

namespace {

struct AreaStyle {
    std::string_view fill;
    std::string_view text;
};

AreaStyle area_style(const std::string& name) {
    if (name == "operational") return {"#9ecae1", "#08519c"};
    if (name == "repeated") return {"#fdae6b", "#a63603"};
    if (name == "continuation") return {"#a1d99b", "#006d2c"};
    if (name == "missed") return {"#fc9272", "#a50f15"};
    return {"#d9d9d9", "#444444"};
}

// The target as a dashed line and its ±3 % band as a pale strip (docs/design.md: the
// adjust time ends when flow enters ±3 % of target and stays there).
std::string target_band(double target) {
    const std::string low = exact_number(target * 0.97);
    const std::string high = exact_number(target * 1.03);
    const std::string at = exact_number(target);
    return "set object 1 rect from graph 0, first " + low + " to graph 1, first " + high + " behind fc " +
           rgb(kTargetColor) + " fs transparent solid 0.15 noborder\n" + "set arrow 1 from graph 0, first " + at +
           " to graph 1, first " + at + " nohead lw 1.5 dt 2 lc " + rgb(kTargetColor) + "\n";
}

std::string target_key_entries(double target) {
    return ", keyentry with lines lw 1.5 dt 2 lc " + rgb(kTargetColor) + " title " +
           gnuplot_string("target " + shown_number(target) + " L/min") + ", keyentry with boxes fc " +
           rgb(kTargetColor) + " fs transparent solid 0.15 noborder title " + gnuplot_string("\u00b13 % band");
}

// Flow against distance to the breakpoint, as the paper's Fig. 14.
std::optional<Panel> flow_distance_panel(const BreakpointFigures& figures) {
    std::vector<Point> truth;
    std::vector<Point> measured;
    Extent x_extent;
    Extent y_extent;
    for (const FlowSample& sample : figures.flow) {
        if (!std::isfinite(sample.distance_to_breakpoint_m)) continue;
        if (std::isfinite(sample.main_flow_l_min)) {
            truth.push_back({sample.distance_to_breakpoint_m, sample.main_flow_l_min});
            y_extent.include(sample.main_flow_l_min);
            x_extent.include(sample.distance_to_breakpoint_m);
        }
        if (std::isfinite(sample.measured_flow_l_min)) {
            measured.push_back({sample.distance_to_breakpoint_m, sample.measured_flow_l_min});
            y_extent.include(sample.measured_flow_l_min);
            x_extent.include(sample.distance_to_breakpoint_m);
        }
    }
    if (truth.empty() && measured.empty()) return std::nullopt;
    const bool has_target = std::isfinite(figures.target_flow_l_min);
    if (has_target) y_extent.include(figures.target_flow_l_min * 1.03);
    y_extent.include(0.0);
    x_extent.include(0.0);
    if (figures.section_open_command_distance_m) x_extent.include(*figures.section_open_command_distance_m);

    Panel panel;
    panel.caption = "Main-pipeline flow against distance to the breakpoint";
    panel.width = 700;
    panel.height = 380;
    std::string& script = panel.script;
    script += data_block("truth", thinned(truth, kMaxPointsPerSeries));
    script += data_block("measured", thinned(measured, kMaxPointsPerSeries));
    script += "set title " + gnuplot_string(panel.caption) + "\n";
    script += "set xlabel " + gnuplot_string("distance to breakpoint (m), negative before it") + "\n";
    script += "set ylabel " + gnuplot_string("main-pipeline flow (L/min)") + "\n";
    script += "set xrange " + x_extent.range(0.03, 0.03) + "\n";
    script += "set yrange " + y_extent.range(0.0, 0.12) + "\n";
    script += "set key bottom right\n";
    if (has_target) script += target_band(figures.target_flow_l_min);
    script += vertical_marker(2, 0.0, kBreakpointColor, "1", "breakpoint", false);
    if (figures.section_open_command_distance_m) {
        script += vertical_marker(3, *figures.section_open_command_distance_m, kOpenCommandColor, "3",
                                  "sections opened (" + shown_number(*figures.section_open_command_distance_m, 3) +
                                      " m)",
                                  true);
    }
    std::vector<std::string> plots;
    if (!truth.empty()) {
        plots.push_back("$truth using 1:2 with lines lw 2 lc " + rgb(kTruthColor) + " title " +
                        gnuplot_string("main flow (truth)"));
    }
    if (!measured.empty()) {
        plots.push_back("$measured using 1:2 with points pt 7 ps 0.3 lc " + rgb(kMeasuredColor) + " title " +
                        gnuplot_string("computed by the controller"));
    }
    script += "plot ";
    for (std::size_t i = 0; i < plots.size(); ++i) script += (i == 0 ? "" : ", ") + plots[i];
    if (has_target) script += target_key_entries(figures.target_flow_l_min);
    script += "\n";
    return panel;
}

// When the sections were opened: given, or where the samples pass the open
// command's distance, or (without either) the first sample.
struct TimeOrigin {
    double t_s;
    bool at_open_command;
};

TimeOrigin flow_time_origin(const BreakpointFigures& figures) {
    if (figures.section_open_command_t_s) return {*figures.section_open_command_t_s, true};
    if (figures.section_open_command_distance_m) {
        const double open = *figures.section_open_command_distance_m;
        const FlowSample* previous = nullptr;
        for (const FlowSample& sample : figures.flow) {
            if (!std::isfinite(sample.t_s) || !std::isfinite(sample.distance_to_breakpoint_m)) continue;
            if (sample.distance_to_breakpoint_m >= open) {
                if (previous == nullptr || sample.distance_to_breakpoint_m == previous->distance_to_breakpoint_m) {
                    return {sample.t_s, true};
                }
                const double fraction = (open - previous->distance_to_breakpoint_m) /
                                        (sample.distance_to_breakpoint_m - previous->distance_to_breakpoint_m);
                return {previous->t_s + fraction * (sample.t_s - previous->t_s), true};
            }
            previous = &sample;
        }
    }
    for (const FlowSample& sample : figures.flow) {
        if (std::isfinite(sample.t_s)) return {sample.t_s, false};
    }
    return {0.0, false};
}

// Flow against time since the open command, with the adjust time and its limit.
std::optional<Panel> flow_time_panel(const CaseResult& result, const BreakpointFigures& figures) {
    const TimeOrigin origin = flow_time_origin(figures);
    const std::optional<double> adjust = finite_metric(result, "flow_adjust_time_s");
    const std::optional<double> adjust_limit = finite_limit(result, "flow_adjust_time_s");
    // Enough to see the approach and the settling, not the whole pass.
    double shown_until = 10.0;
    if (adjust) shown_until = std::max({5.0, 2.0 * *adjust + 1.0, adjust_limit.value_or(0.0) + 1.0});
    constexpr double kShownBefore = 1.0;

    std::vector<Point> truth;
    std::vector<Point> measured;
    Extent y_extent;
    Extent x_extent;
    for (const FlowSample& sample : figures.flow) {
        const double since = sample.t_s - origin.t_s;
        if (!std::isfinite(since) || since < -kShownBefore || since > shown_until) continue;
        if (std::isfinite(sample.main_flow_l_min)) {
            truth.push_back({since, sample.main_flow_l_min});
            y_extent.include(sample.main_flow_l_min);
            x_extent.include(since);
        }
        if (std::isfinite(sample.measured_flow_l_min)) {
            measured.push_back({since, sample.measured_flow_l_min});
            y_extent.include(sample.measured_flow_l_min);
            x_extent.include(since);
        }
    }
    if (truth.empty() && measured.empty()) return std::nullopt;
    const bool has_target = std::isfinite(figures.target_flow_l_min);
    if (has_target) y_extent.include(figures.target_flow_l_min * 1.03);
    y_extent.include(0.0);
    if (origin.at_open_command) x_extent.include(0.0);
    if (adjust) x_extent.include(*adjust);
    if (adjust_limit && *adjust_limit <= shown_until) x_extent.include(*adjust_limit);

    Panel panel;
    panel.caption = origin.at_open_command ? "Flow against time since the section-open command"
                                           : "Flow against time since the first sample";
    panel.width = 480;
    panel.height = 380;
    std::string& script = panel.script;
    script += data_block("truth", thinned(truth, kMaxPointsPerSeries));
    script += data_block("measured", thinned(measured, kMaxPointsPerSeries));
    script += "set title " + gnuplot_string(origin.at_open_command ? "Flow since the open command" : "Flow") + "\n";
    script += "set xlabel " +
              gnuplot_string(origin.at_open_command ? "time since open command (s)" : "time since first sample (s)") +
              "\n";
    script += "set ylabel " + gnuplot_string("main-pipeline flow (L/min)") + "\n";
    script += "set xrange " + x_extent.range(0.02, 0.04) + "\n";
    script += "set yrange " + y_extent.range(0.0, 0.12) + "\n";
    script += "set key bottom right\n";
    if (has_target) script += target_band(figures.target_flow_l_min);
    if (origin.at_open_command) script += vertical_marker(2, 0.0, kOpenCommandColor, "3", "open", false);
    if (adjust) {
        // On the side away from the limit's line, which would cross the text.
        const bool limit_to_the_right = adjust_limit && *adjust_limit > *adjust;
        script += vertical_marker(3, *adjust, kTargetColor, "1", "settled " + shown_number(*adjust, 3) + " s",
                                  limit_to_the_right, 0.12);
    }
    if (adjust_limit && *adjust_limit <= shown_until) {
        const bool adjust_to_the_right = adjust && *adjust > *adjust_limit;
        script += vertical_marker(4, *adjust_limit, kLimitColor, "2", "limit " + shown_number(*adjust_limit, 3) + " s",
                                  adjust_to_the_right);
    }
    std::vector<std::string> plots;
    if (!truth.empty()) plots.push_back("$truth using 1:2 with lines lw 2 lc " + rgb(kTruthColor) + " notitle");
    if (!measured.empty()) {
        plots.push_back("$measured using 1:2 with points pt 7 ps 0.3 lc " + rgb(kMeasuredColor) + " notitle");
    }
    script += "set key off\nplot ";
    for (std::size_t i = 0; i < plots.size(); ++i) script += (i == 0 ? "" : ", ") + plots[i];
    script += "\n";
    return panel;
}

struct DoseRow {
    double along_m;
    double first_pass;
    double continuation;
    double total;
};

std::vector<DoseRow> dose_rows(const BreakpointFigures& figures) {
    std::vector<DoseRow> rows;
    for (const DoseSample& sample : figures.dose) {
        if (!std::isfinite(sample.along_m)) continue;
        // A pass that left nothing on a row counts as 0 in the total, as a filter paper would.
        const double first = std::isfinite(sample.first_pass_dose) ? sample.first_pass_dose : 0.0;
        const double continuation = std::isfinite(sample.continuation_dose) ? sample.continuation_dose : 0.0;
        rows.push_back({sample.along_m, sample.first_pass_dose, sample.continuation_dose, first + continuation});
    }
    std::stable_sort(rows.begin(), rows.end(),
                     [](const DoseRow& a, const DoseRow& b) { return a.along_m < b.along_m; });
    return rows;
}

// The x range the two dose panels share, so their axes line up.
Extent dose_x_extent(const BreakpointFigures& figures, const std::vector<DoseRow>& rows) {
    Extent extent;
    for (const DoseRow& row : rows) extent.include(row.along_m);
    extent.include(figures.breakpoint_along_m);
    for (const AreaSpan& area : figures.areas) {
        extent.include(area.from_along_m);
        extent.include(area.to_along_m);
    }
    return extent;
}

std::string area_shading(const BreakpointFigures& figures, bool with_labels) {
    std::string script;
    int tag = 10;
    for (const AreaSpan& area : figures.areas) {
        if (!std::isfinite(area.from_along_m) || !std::isfinite(area.to_along_m)) continue;
        const AreaStyle style = area_style(area.name);
        const double from = std::min(area.from_along_m, area.to_along_m);
        const double to = std::max(area.from_along_m, area.to_along_m);
        script += "set object " + std::to_string(tag) + " rect from first " + exact_number(from) + ", graph 0 to first " +
                  exact_number(to) + ", graph 1 behind fc " + rgb(style.fill) + " fs solid 0.45 noborder\n";
        if (with_labels) {
            // Alternate heights so the labels of narrow neighbouring areas do not overprint.
            const double height = (tag % 2 == 0) ? 0.955 : 0.89;
            script += "set label " + std::to_string(tag) + " " + gnuplot_string(area.name) + " at first " +
                      exact_number((from + to) / 2.0) + ", graph " + exact_number(height) + " center front textcolor " +
                      rgb(style.text) + "\n";
        }
        ++tag;
    }
    return script;
}

// Fig. 15's scale. Where the sprayer stood with its nozzles open (starting a
// pass from standstill, stopping at the breakpoint) a few rows get many times
// what a moving boom leaves; a scale set by them flattens everything the figure
// is about. The scale is cut at kDoseScaleOverMedian times the median of the
// rows that got spray, and the rows above it are counted on the figure.
constexpr double kDoseScaleOverMedian = 3.0;

struct DoseScale {
    double top = 0.0;             // the y axis' top, uL/cm^2 (0: nothing sprayed)
    std::size_t rows_above = 0;   // rows whose total is off the scale
    double highest = 0.0;         // the largest total
};

DoseScale dose_scale(const std::vector<DoseRow>& rows) {
    std::vector<double> sprayed;
    DoseScale scale;
    for (const DoseRow& row : rows) {
        if (row.total > 0.0) sprayed.push_back(row.total);
        scale.highest = std::max(scale.highest, row.total);
    }
    if (sprayed.empty()) return scale;
    std::nth_element(sprayed.begin(), sprayed.begin() + static_cast<std::ptrdiff_t>(sprayed.size() / 2), sprayed.end());
    const double cut = kDoseScaleOverMedian * sprayed[sprayed.size() / 2];
    scale.top = std::min(scale.highest, cut);
    for (const DoseRow& row : rows) scale.rows_above += row.total > cut ? 1 : 0;
    return scale;
}

// The label on a figure whose scale cut rows off.
std::string off_scale_label(int tag, const DoseScale& scale, const std::string& highest_text) {
    if (scale.rows_above == 0) return {};
    return "set label " + std::to_string(tag) + " " +
           gnuplot_string(std::to_string(scale.rows_above) + " row" + (scale.rows_above == 1 ? "" : "s") +
                          " off the scale (up to " + highest_text + ") where the sprayer stood spraying") +
           " at graph 0.99, graph 0.72 right front boxed textcolor rgb '#8d1010'\n" +
           "set style textbox opaque fillcolor rgb 'white' noborder\n";
}

// Row deposits across the breakpoint, as the paper's Fig. 15 (before its normalisation).
std::optional<Panel> dose_panel(const BreakpointFigures& figures, const std::vector<DoseRow>& rows) {
    if (rows.empty()) return std::nullopt;
    const DoseScale scale = dose_scale(rows);
    Extent y_extent;
    y_extent.include(0.0);
    y_extent.include(scale.top);
    std::vector<std::vector<double>> data;
    for (const DoseRow& row : rows) data.push_back({row.along_m, row.first_pass, row.continuation, row.total});
    Panel panel;
    panel.caption = "Dose per row along the track across the breakpoint";
    panel.width = 860;
    panel.height = 400;
    std::string& script = panel.script;
    script += data_block("dose", data);
    // No title: the key takes its place above the plot, the figure's caption says the rest.
    script += "set xlabel " + gnuplot_string("along track (m)") + "\n";
    script += "set ylabel " + gnuplot_string("dose per row, mean across the boom (uL/cm^2)") + "\n";
    script += "set lmargin 12\nset rmargin 4\n";
    script += "set xrange " + dose_x_extent(figures, rows).range(0.02, 0.02) + "\n";
    script += "set yrange " + y_extent.range(0.0, 0.25) + "\n";
    script += "set key outside top center horizontal\n";
    script += area_shading(figures, true);
    script += off_scale_label(3, scale, shown_number(scale.highest, 3) + " uL/cm^2");
    script += vertical_marker(2, figures.breakpoint_along_m, kBreakpointColor, "1", "breakpoint", false, 0.82);
    script += "plot $dose using 1:2 with linespoints lw 1.5 pt 7 ps 0.5 lc " + rgb(kFirstPassColor) + " title " +
              gnuplot_string("first pass") + ", $dose using 1:3 with linespoints lw 1.5 pt 7 ps 0.5 lc " +
              rgb(kContinuationColor) + " title " + gnuplot_string("continuation") +
              ", $dose using 1:4 with linespoints lw 2.5 pt 5 ps 0.5 lc " + rgb(kTotalColor) + " title " +
              gnuplot_string("total") + "\n";
    return panel;
}

// The total per row normalised by Eq. 9, y = (x - min) / (max - min), as the paper plots it.
std::optional<Panel> normalised_dose_panel(const BreakpointFigures& figures, const std::vector<DoseRow>& rows) {
    Extent totals;
    for (const DoseRow& row : rows) totals.include(row.total);
    if (totals.empty() || !(totals.high > totals.low)) return std::nullopt;  // Eq. 9 undefined
    // Eq. 9 as the paper defines it (its max is a standing row's, if any), shown on the same cut scale.
    const DoseScale scale = dose_scale(rows);
    const double top = (scale.top - totals.low) / (totals.high - totals.low);
    std::vector<Point> normalised;
    for (const DoseRow& row : rows) {
        normalised.push_back({row.along_m, (row.total - totals.low) / (totals.high - totals.low)});
    }
    Panel panel;
    panel.caption = "Normalised total dose per row (Eq. 9)";
    panel.width = 860;
    panel.height = 240;
    std::string& script = panel.script;
    script += data_block("normalised", normalised);
    script += "set title " + gnuplot_string(panel.caption) + "\n";
    script += "set xlabel " + gnuplot_string("along track (m)") + "\n";
    script += "set ylabel " + gnuplot_string("normalised (Eq. 9)") + "\n";
    script += "set lmargin 12\nset rmargin 4\n";
    script += "set xrange " + dose_x_extent(figures, rows).range(0.02, 0.02) + "\n";
    script += "set yrange [0:" + exact_number(std::max(top, 0.05) * 1.1) + "]\nset key off\n";
    script += area_shading(figures, false);
    script += off_scale_label(3, scale, "1");
    script += vertical_marker(2, figures.breakpoint_along_m, kBreakpointColor, "1", "", false);
    script += "plot $normalised using 1:2 with linespoints lw 2 pt 5 ps 0.5 lc " + rgb(kTotalColor) + " notitle\n";
    return panel;
}

std::string area_table(const BreakpointFigures& figures) {
    if (figures.areas.empty()) return {};
    std::string table = "<table class=\"areas\">\n<tr><th>area</th><th>from (m)</th><th>to (m)</th><th>length (m)</th>"
                        "<th>relative to the breakpoint (m)</th></tr>\n";
    for (const AreaSpan& area : figures.areas) {
        const double from = area.from_along_m;
        const double to = area.to_along_m;
        table += "<tr><td>" + html(area.name) + "</td><td class=\"num\">" + fixed_number(from, 2) +
                 "</td><td class=\"num\">" + fixed_number(to, 2) + "</td><td class=\"num\">" +
                 fixed_number(to - from, 2) + "</td><td class=\"num\">" +
                 fixed_number(from - figures.breakpoint_along_m, 2) + " \u2026 " +
                 fixed_number(to - figures.breakpoint_along_m, 2) + "</td></tr>\n";
    }
    return table + "</table>\n";
}

std::string flow_figure(FigurePage& page, const FigureContext& where, const CaseResult& result, const BreakpointFigures& figures) {
    std::optional<Panel> by_distance = flow_distance_panel(figures);
    if (!by_distance) return {};
    by_distance->what = where.label + ": flow against distance";
    std::string figure =
        "<figure class=\"figure flow\" id=\"" + where.anchor + "-flow\">\n<div class=\"panels\">\n";
    figure += page.place(std::move(*by_distance));
    if (std::optional<Panel> by_time = flow_time_panel(result, figures)) {
        by_time->what = where.label + ": flow against time";
        figure += page.place(std::move(*by_time));
    }
    figure += "</div>\n<figcaption>Main-pipeline flow as in the paper's Fig. 14: truth as a line";
    bool has_measured = false;
    for (const FlowSample& sample : figures.flow) {
        has_measured = has_measured || std::isfinite(sample.measured_flow_l_min);
    }
    if (has_measured) figure += ", the controller's own computation (Eq. 3) as dots";
    figure += ".";
    if (std::isfinite(figures.target_flow_l_min)) {
        figure += " Target " + shown_number(figures.target_flow_l_min) + " L/min with its \u00b13 % band.";
    }
    if (figures.section_open_command_distance_m) {
        const double open = *figures.section_open_command_distance_m;
        figure += " Sections opened " + shown_number(std::abs(open), 3) + " m " + (open <= 0 ? "before" : "after") +
                  " the breakpoint.";
    }
    if (const std::optional<double> adjust = finite_metric(result, "flow_adjust_time_s")) {
        figure += " Adjust time " + shown_number(*adjust, 3) + " s";
        if (const std::optional<double> adjust_limit = finite_limit(result, "flow_adjust_time_s")) {
            figure += " (limit " + shown_number(*adjust_limit, 3) + " s)";
        }
        figure += ".";
    }
    return figure + "</figcaption>\n</figure>\n";
}

std::string dose_figure(FigurePage& page, const FigureContext& where, const BreakpointFigures& figures) {
    const std::vector<DoseRow> rows = dose_rows(figures);
    std::optional<Panel> dose = dose_panel(figures, rows);
    if (!dose) return {};
    dose->what = where.label + ": dose along the track";
    std::string figure =
        "<figure class=\"figure dose\" id=\"" + where.anchor + "-dose\">\n<div class=\"panels stacked\">\n";
    figure += page.place(std::move(*dose));
    if (std::optional<Panel> normalised = normalised_dose_panel(figures, rows)) {
        normalised->what = where.label + ": normalised dose";
        figure += page.place(std::move(*normalised));
    }
    figure += "</div>\n<figcaption>Dose per row of the deposition grid, summed across the boom, as in the paper's "
              "Fig. 15: the first pass (before the breakpoint stop), the continuation (after the resume) and their "
              "total; shaded areas as the harness classified them; below, the total normalised by Eq. 9.";
    if (const DoseScale scale = dose_scale(rows); scale.rows_above > 0) {
        figure += " The scale is cut at " + std::to_string(static_cast<int>(kDoseScaleOverMedian)) +
                  " times the median row: " + std::to_string(scale.rows_above) + " row" +
                  (scale.rows_above == 1 ? "" : "s") + " reach up to " + html(shown_number(scale.highest, 3)) +
                  " uL/cm<sup>2</sup>, where the sprayer stood with its nozzles open (starting from standstill, "
                  "stopping at the breakpoint): a filter paper there is soaked, and Eq. 9's maximum is theirs.";
    }
    figure += "</figcaption>\n";
    figure += area_table(figures);
    return figure + "</figure>\n";
}

}  // namespace

std::string BreakpointFigures::html(FigurePage& page, const FigureContext& where, const CaseResult& result) const {
    return flow_figure(page, where, result, *this) + dose_figure(page, where, *this);
}

}  // namespace rig::harness
