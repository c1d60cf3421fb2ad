#include "harness/report/diff_page.h"

#include <algorithm>
#include <set>
#include <string_view>

namespace rig::harness {

namespace {

constexpr std::string_view kStyle = R"(
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; color: #222;
       margin: 1.5em auto; max-width: 1240px; padding: 0 1.2em; line-height: 1.4; }
h1 { font-size: 1.7em; margin: 0 0 0.3em 0; }
h2 { font-size: 1.3em; border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 2em; }
pre { background: #f6f6f6; padding: 0.8em; overflow-x: auto; font-size: 0.9em; }
figure { margin: 1em 0; overflow-x: auto; }
figcaption { color: #555; font-size: 0.9em; }
.notice { background: #fff4e5; border: 1px solid #f0c36d; padding: 0.5em 1em; }
)";

// Run A solid, run B dashed over it, so where they agree B's dashes lie on A.
constexpr std::string_view kRunAColor = kTruthColor;
constexpr std::string_view kRunBColor = kMeasuredColor;

const KeySignal* signal_named(const std::vector<KeySignal>& signals, const std::string& name) {
    for (const KeySignal& signal : signals) {
        if (signal.name == name) return &signal;
    }
    return nullptr;
}

// The points of `signal` that draw [from_s, to_s]: those inside, and the one
// on either side, so a line or a held value reaches the window's edges; a
// held value lasts to the run's end (`end_s`) or the window's.
std::vector<Point> within(const KeySignal& signal, double from_s, double to_s, double end_s) {
    std::vector<Point> kept;
    const std::vector<Point>& points = signal.points;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const bool inside = points[i].x >= from_s && points[i].x <= to_s;
        const bool next_inside = i + 1 < points.size() && points[i + 1].x >= from_s;
        const bool previous_inside = i > 0 && points[i - 1].x <= to_s;
        if (inside || (points[i].x < from_s && next_inside) || (points[i].x > to_s && previous_inside)) {
            kept.push_back(points[i]);
        }
    }
    const double held_to_s = std::min(to_s, end_s);
    if (signal.held && !kept.empty() && kept.back().x < held_to_s) kept.push_back({held_to_s, kept.back().y});
    return kept;
}

std::string plot_of(const std::string& block, const KeySignal& signal, std::string_view color, bool dashed,
                    const std::string& title) {
    return "$" + block + " using 1:2 with " + (signal.held ? "steps" : "lines") + " lw 2" + (dashed ? " dt 2" : "") +
           " lc " + rgb(color) + " title " + gnuplot_string(title);
}

// One signal of both runs over each other; nullopt when neither has a point to draw.
std::optional<Panel> signal_panel(const DiffPage& page, const std::string& name) {
    const KeySignal* a = signal_named(page.a_signals, name);
    const KeySignal* b = signal_named(page.b_signals, name);
    const std::vector<Point> a_points = a != nullptr ? within(*a, page.from_s, page.to_s, page.a_end_s) : std::vector<Point>{};
    const std::vector<Point> b_points = b != nullptr ? within(*b, page.from_s, page.to_s, page.b_end_s) : std::vector<Point>{};
    if (a_points.empty() && b_points.empty()) return std::nullopt;
    const KeySignal& either = a != nullptr ? *a : *b;
    Extent values;
    for (const std::vector<Point>* points : {&a_points, &b_points}) {
        for (const Point& point : *points) values.include(point.y);
    }
    Panel panel;
    panel.what = "signal " + name;
    panel.caption = name;
    panel.width = 900;
    panel.height = 300;
    std::string& script = panel.script;
    script += data_block("a", thinned(a_points, kMaxPointsPerSeries));
    script += data_block("b", thinned(b_points, kMaxPointsPerSeries));
    script += "set title " + gnuplot_string(name) + "\n";
    script += "set xlabel " + gnuplot_string("simulated time (s)") + "\n";
    script += "set ylabel " + gnuplot_string(either.unit) + "\n";
    script += "set xrange [" + exact_number(page.from_s) + ":" + exact_number(page.to_s) + "]\n";
    script += "set yrange " + values.range(0.08, 0.15) + "\n";
    script += "set key top left\n";
    if (page.parted_at_s) {
        script += vertical_marker(1, *page.parted_at_s, kBreakpointColor, "1", "the runs part", false);
    }
    std::vector<std::string> plots;
    if (!a_points.empty()) plots.push_back(plot_of("a", either, kRunAColor, false, "A"));
    if (!b_points.empty()) plots.push_back(plot_of("b", either, kRunBColor, true, "B"));
    script += "plot ";
    for (std::size_t i = 0; i < plots.size(); ++i) script += (i == 0 ? "" : ", ") + plots[i];
    script += "\n";
    return panel;
}

}  // namespace

HtmlReport render_diff_page(const DiffPage& page, const GnuplotOptions& options) {
    // Every signal either run has, in the order its system gives them (A's first).
    std::vector<std::string> names;
    std::set<std::string> seen;
    for (const std::vector<KeySignal>* signals : {&page.a_signals, &page.b_signals}) {
        for (const KeySignal& signal : *signals) {
            if (seen.insert(signal.name).second) names.push_back(signal.name);
        }
    }
    FigurePage figures;
    std::string body = "<section>\n<h2>Key signals</h2>\n<p>Run A (" + html(page.a_label) + ") solid, run B (" +
                       html(page.b_label) + ") dashed over it, from t = " + html(shown_number(page.from_s, 6)) +
                       " s to " + html(shown_number(page.to_s, 6)) + " s";
    body += page.parted_at_s ? "; the black line is where the runs part (" + html(page.parted_topic) + ", t = " +
                                   html(shown_number(*page.parted_at_s, 9)) + " s).</p>\n"
                             : ": the runs do not part.</p>\n";
    for (const std::string& name : names) {
        const std::optional<Panel> panel = signal_panel(page, name);
        const bool in_a = signal_named(page.a_signals, name) != nullptr;
        const bool in_b = signal_named(page.b_signals, name) != nullptr;
        const std::string only = in_a && in_b ? "" : in_a ? " (only run A has it)" : " (only run B has it)";
        if (!panel) {
            body += "<p>" + html(name) + only + ": no sample in this stretch of time.</p>\n";
            continue;
        }
        // The drawing carries its name as its title; the caption only says what one run lacks.
        body += "<figure>" + figures.place(*panel) + (only.empty() ? "" : "<figcaption>" + html(name) + only + "</figcaption>") +
                "</figure>\n";
    }
    if (names.empty()) body += "<p>Neither trace holds a sample of its system's key signals.</p>\n";
    body += "</section>\n";
    draw_panels(figures.panels(), options);

    HtmlReport report;
    report.problems = figures.problems();
    std::string& out = report.html;
    // Polyglot markup (well-formed XML as well as HTML), as report.html.
    out = "<!DOCTYPE html>\n<html xmlns=\"http://www.w3.org/1999/xhtml\" lang=\"en\">\n<head>\n";
    out += "<meta charset=\"utf-8\"/>\n";
    out += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"/>\n";
    out += "<title>rig diff: " + html(page.case_name) + "</title>\n";
    out += "<style>" + std::string(kStyle) + "</style>\n</head>\n<body>\n";
    out += "<h1>rig diff: " + html(page.case_name) + "</h1>\n";
    if (!report.problems.empty()) {
        out += "<div class=\"notice\"><strong>Figures that could not be drawn</strong> (the reason is in their "
               "place):<ul>";
        for (const std::string& problem : report.problems) out += "<li><pre>" + html(problem) + "</pre></li>";
        out += "</ul></div>\n";
    }
    out += "<pre>" + html(page.report_text) + "</pre>\n";
    out += figures.with_panels(body);
    out += "</body>\n</html>\n";
    return report;
}

}  // namespace rig::harness
