#include "harness/html_report.h"

#include <stdlib.h>

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

#include "harness/board_io_report.h"
#include "rig/host/child_process.h"

namespace rig::harness {

namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------- numbers

// Shortest text that reads back as the same double: for gnuplot scripts and
// data, where the value must be exact and the text locale-independent.
std::string exact_number(double value) {
    if (std::isnan(value)) return "NaN";
    char buffer[64];
    const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
    return error == std::errc{} ? std::string(buffer, end) : std::string("NaN");
}

// For people: `significant_digits` like %g, "–" when not measured.
std::string shown_number(double value, int significant_digits = 4) {
    if (!std::isfinite(value)) return std::isnan(value) ? "\u2013" : (value > 0 ? "inf" : "-inf");
    char buffer[64];
    const auto [end, error] =
        std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, significant_digits);
    return error == std::errc{} ? std::string(buffer, end) : std::string("?");
}

std::string fixed_number(double value, int decimals) {
    if (!std::isfinite(value)) return shown_number(value);
    char buffer[64];
    const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed, decimals);
    return error == std::errc{} ? std::string(buffer, end) : std::string("?");
}

// `value` with enough digits not to print like a different `limit` (3.3000001
// against 3.3 must not read "3.3 / 3.3" while it fails).
std::string shown_against(double value, double limit) {
    if (!std::isfinite(value) || !std::isfinite(limit)) return shown_number(value);
    for (int digits = 4; digits < 17; ++digits) {
        const std::string text = shown_number(value, digits);
        if (value == limit || text != shown_number(limit, digits)) return text;
    }
    return shown_number(value, 17);
}

// ---------------------------------------------------------------- text

std::string html(std::string_view text) { return xml_escape(text, false); }

// A gnuplot string literal. Single quotes because gnuplot interprets no
// backslash escapes in them (a quote is written twice); control characters
// would end the command line, so they become spaces. Enhanced-text markup is
// off for every figure (termoption noenhanced), so '_' or '^' print as is.
std::string gnuplot_string(std::string_view text) {
    std::string quoted = "'";
    for (const char c : valid_utf8(text)) {
        const auto byte = static_cast<unsigned char>(c);
        if (byte < 0x20 || byte == 0x7F) {
            quoted += ' ';
        } else if (c == '\'') {
            quoted += "''";
        } else {
            quoted += c;
        }
    }
    return quoted + "'";
}

// At most `max_code_points`, with an ellipsis when cut (long case names on a bar chart's axis).
std::string shortened(std::string_view text, std::size_t max_code_points) {
    const std::string valid = valid_utf8(text);
    std::size_t count = 0;
    for (std::size_t i = 0; i < valid.size(); ++i) {
        if ((static_cast<unsigned char>(valid[i]) & 0xC0) == 0x80) continue;
        if (count == max_code_points) return valid.substr(0, i) + "\u2026";
        ++count;
    }
    return valid;
}

void replace_all(std::string& text, std::string_view from, std::string_view to) {
    if (from.empty()) return;
    for (std::size_t pos = text.find(from); pos != std::string::npos; pos = text.find(from, pos + to.size())) {
        text.replace(pos, from.size(), to);
    }
}

std::optional<std::string> read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return std::nullopt;
    std::ostringstream content;
    content << in.rdbuf();
    return content.str();
}

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

std::optional<double> metric(const CaseResult& result, const std::string& name) {
    const auto found = result.metrics.find(name);
    if (found == result.metrics.end() || !std::isfinite(found->second)) return std::nullopt;
    return found->second;
}

std::optional<double> limit(const CaseResult& result, const std::string& name) {
    const auto found = result.limits.find(name);
    if (found == result.limits.end() || !std::isfinite(found->second)) return std::nullopt;
    return found->second;
}

// ---------------------------------------------------------------- plotting helpers

struct Point {
    double x;
    double y;
};

// Long series are cut down for the page: per bucket of consecutive points the
// lowest and the highest are kept (in their order), so spikes and the envelope
// survive while a 60 s trace at 1 kHz does not make a 10 MB page.
std::vector<Point> thinned(const std::vector<Point>& points, std::size_t max_points) {
    if (points.size() <= max_points || max_points < 4) return points;
    const std::size_t buckets = max_points / 2;
    std::vector<Point> kept;
    kept.reserve(max_points + 2);
    for (std::size_t bucket = 0; bucket < buckets; ++bucket) {
        const std::size_t begin = bucket * points.size() / buckets;
        const std::size_t end = (bucket + 1) * points.size() / buckets;
        std::size_t low = begin;
        std::size_t high = begin;
        for (std::size_t i = begin; i < end; ++i) {
            if (points[i].y < points[low].y) low = i;
            if (points[i].y > points[high].y) high = i;
        }
        kept.push_back(points[std::min(low, high)]);
        if (low != high) kept.push_back(points[std::max(low, high)]);
    }
    return kept;
}

constexpr std::size_t kMaxPointsPerSeries = 2400;

// A gnuplot inline data block: `$name << EOD` ... `EOD`; rows of numbers only.
std::string data_block(const std::string& name, const std::vector<std::vector<double>>& rows) {
    std::string block = "$" + name + " << EOD\n";
    for (const auto& row : rows) {
        for (std::size_t i = 0; i < row.size(); ++i) block += (i == 0 ? "" : " ") + exact_number(row[i]);
        block += '\n';
    }
    return block + "EOD\n";
}

std::string data_block(const std::string& name, const std::vector<Point>& points) {
    std::vector<std::vector<double>> rows;
    rows.reserve(points.size());
    for (const Point& point : points) rows.push_back({point.x, point.y});
    return data_block(name, rows);
}

// A closed interval that grows to include values; empty until the first finite one.
struct Extent {
    double low = kNotMeasured;
    double high = kNotMeasured;

    void include(double value) {
        if (!std::isfinite(value)) return;
        low = std::isnan(low) ? value : std::min(low, value);
        high = std::isnan(high) ? value : std::max(high, value);
    }
    bool empty() const { return std::isnan(low); }
    // "[low:high]" widened by `fraction` of its width on each side (never zero-width).
    std::string range(double fraction_low, double fraction_high) const {
        double width = high - low;
        if (!(width > 0)) width = std::max(std::abs(high) * 0.1, 1.0);
        return "[" + exact_number(low - width * fraction_low) + ":" + exact_number(high + width * fraction_high) + "]";
    }
};

std::string rgb(std::string_view hex) { return "rgb '" + std::string(hex) + "'"; }

constexpr std::string_view kTruthColor = "#1f77b4";
constexpr std::string_view kMeasuredColor = "#ff7f0e";
constexpr std::string_view kTargetColor = "#2ca02c";
constexpr std::string_view kBreakpointColor = "#222222";
constexpr std::string_view kOpenCommandColor = "#d62728";
constexpr std::string_view kLimitColor = "#d62728";
constexpr std::string_view kFirstPassColor = "#3182bd";
constexpr std::string_view kContinuationColor = "#31a354";
constexpr std::string_view kTotalColor = "#222222";

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

// The part every panel's script starts with after its terminal: one look for all figures.
constexpr std::string_view kCommonStyle =
    "set border lc rgb '#555555'\n"
    "set grid lc rgb '#e3e3e3' lt 1 lw 1\n"
    "set tics nomirror\n"
    "set key opaque box lc rgb '#bbbbbb' samplen 2.5 spacing 1.1\n"
    // Marker labels sit on a white box: a line crossing them must not run through the text.
    "set style textbox opaque noborder margins 1,1\n";

// A vertical marker across the plot at x (first axis), with its text at
// `text_height` (graph fraction) beside it. The line is drawn behind the curves
// and the text in front on an opaque box, so neither hides the other.
std::string vertical_marker(int tag, double x, std::string_view color, std::string_view dash, const std::string& text,
                            bool text_on_left, double text_height = 1.0) {
    const std::string at = exact_number(x);
    std::string script = "set arrow " + std::to_string(tag) + " from first " + at + ", graph 0 to first " + at +
                         ", graph 1 nohead back lw 1.5 lc " + rgb(color) + " dt " + std::string(dash) + "\n";
    script += "set label " + std::to_string(tag) + " " + gnuplot_string(text) + " at first " + at + ", graph " +
              exact_number(text_height) + (text_on_left ? " right offset -0.5,-1" : " left offset 0.5,-1") +
              " front boxed textcolor " + rgb(color) + "\n";
    return script;
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

// ---------------------------------------------------------------- panels

// One gnuplot plot, drawn into one inline SVG.
struct Panel {
    std::string what;     // for problem lines: "case 2 (name): flow against distance"
    std::string caption;  // the SVG's <title> (tooltip, screen readers)
    int width = 640;
    int height = 360;
    std::string script;  // commands after the terminal is set: data blocks, settings, plot
    std::string svg;     // the drawing, once drawn
    std::string error;   // why there is no drawing
};

// Placeholders for panels in the page while it is being built: \x01 never
// survives xml_escape (XML forbids it), so no escaped text can look like one.
std::string panel_marker(std::size_t index) { return "\x01panel " + std::to_string(index) + "\x01"; }

// Drops `<g ...></g>` with nothing inside. gnuplot's svg terminal opens such
// a group with the stroke colour the previous figure ended with, so without
// this a figure would depend on what the same gnuplot process drew before.
void remove_empty_groups(std::string& svg) {
    std::size_t pos = 0;
    while ((pos = svg.find("<g ", pos)) != std::string::npos) {
        const std::size_t tag_end = svg.find('>', pos);
        if (tag_end == std::string::npos) return;
        std::size_t next = svg.find_first_not_of(" \t\n", tag_end + 1);
        if (svg[tag_end - 1] != '/' && next != std::string::npos && svg.compare(next, 4, "</g>") == 0) {
            next += 4;
            if (next < svg.size() && svg[next] == '\n') ++next;
            svg.erase(pos, next - pos);
        } else {
            pos = tag_end;
        }
    }
}

// Makes the ids of gnuplot's SVG unique in the page (every SVG defines
// "gpPt0", "gnuplot_canvas"...) by prefixing them, inside tags only, so text
// that happens to read "id='" is left alone. Drops the XML declaration and puts
// our title in place of gnuplot's.
std::string inline_svg(const std::string& raw, const std::string& id_prefix, const std::string& title) {
    const std::size_t start = raw.find("<svg");
    if (start == std::string::npos) return {};
    std::string svg;
    svg.reserve(raw.size() - start + 256);
    bool in_tag = false;
    for (std::size_t i = start; i < raw.size(); ++i) {
        const char c = raw[i];
        if (!in_tag) {
            svg += c;
            in_tag = c == '<';
            continue;
        }
        if (c == '>') {
            in_tag = false;
            svg += c;
            continue;
        }
        bool replaced = false;
        const bool after_space = raw[i - 1] == ' ' || raw[i - 1] == '\t' || raw[i - 1] == '\n';
        for (const std::string_view reference : {"id='", "id=\"", "href='#", "href=\"#", "url(#"}) {
            // "id=" only as a whole attribute name (not the end of "grid=" or the like).
            if (raw.compare(i, reference.size(), reference) == 0 && (reference.front() != 'i' || after_space)) {
                svg += reference;
                svg += id_prefix;
                i += reference.size() - 1;
                replaced = true;
                break;
            }
        }
        if (!replaced) svg += c;
    }
    remove_empty_groups(svg);
    replace_all(svg, "<title>Gnuplot</title>", "<title>" + html(title) + "</title>");
    while (!svg.empty() && (svg.back() == '\n' || svg.back() == ' ')) svg.pop_back();
    return svg;
}

// A scratch directory for one report's scripts and drawings, removed afterwards.
class ScratchDirectory {
public:
    explicit ScratchDirectory(const fs::path& parent) {
        std::string pattern = ((parent.empty() ? fs::temp_directory_path() : parent) / "rig-report-XXXXXX").string();
        if (::mkdtemp(pattern.data()) == nullptr) {
            throw std::runtime_error("cannot create a scratch directory like " + pattern + ": " +
                                     std::strerror(errno));
        }
        path_ = pattern;
    }
    ~ScratchDirectory() {
        std::error_code ignored;
        fs::remove_all(path_, ignored);
    }
    ScratchDirectory(const ScratchDirectory&) = delete;
    ScratchDirectory& operator=(const ScratchDirectory&) = delete;
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

void write_text(const fs::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << text;
    out.flush();
    if (!out) throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(errno));
}

struct GnuplotRun {
    bool exited_cleanly = false;
    bool exited_with_status = false;  // ended by itself (status 0 or not), not by a signal
    std::string message;              // how it ended and what it printed, when not cleanly
};

class GnuplotDrawer {
public:
    GnuplotDrawer(const HtmlReportOptions& options, const fs::path& scratch) : options_(options), scratch_(scratch) {}

    // Draws every panel, filling svg or error. Fast path: one gnuplot for all
    // (starting gnuplot costs ~0.1 s); when that one fails, each panel alone,
    // so a bad panel spoils only itself and its error is its own.
    void draw(std::vector<Panel>& panels) {
        std::string batch;
        for (std::size_t i = 0; i < panels.size(); ++i) batch += script_for(panels[i], i);
        const GnuplotRun all = run(batch, "all");
        if (all.exited_cleanly) {
            for (std::size_t i = 0; i < panels.size(); ++i) collect(panels[i], i, all);
            return;
        }
        if (!all.exited_with_status) {  // not started, or stopped at the time limit: no use trying again
            for (Panel& panel : panels) panel.error = all.message;
            return;
        }
        for (std::size_t i = 0; i < panels.size(); ++i) {
            const GnuplotRun alone = run(script_for(panels[i], i), "panel-" + std::to_string(i));
            collect(panels[i], i, alone);
        }
    }

private:
    fs::path svg_path(std::size_t index) const { return scratch_ / ("panel-" + std::to_string(index) + ".svg"); }

    std::string script_for(const Panel& panel, std::size_t index) const {
        // `reset session` also forgets what a user's ~/.gnuplot may have set, so
        // the drawing depends on the inputs only.
        std::string script = "reset session\nset encoding utf8\n";
        script += "set terminal svg size " + std::to_string(panel.width) + "," + std::to_string(panel.height) +
                  " fixed font 'sans-serif,11' background rgb 'white'\n";
        script += "set termoption noenhanced\n";
        script += "set output " + gnuplot_string(svg_path(index).string()) + "\n";
        script += kCommonStyle;
        script += panel.script;
        script += "unset output\n";
        return script;
    }

    void collect(Panel& panel, std::size_t index, const GnuplotRun& run_result) const {
        const std::optional<std::string> raw = read_file(svg_path(index));
        std::error_code ignored;
        fs::remove(svg_path(index), ignored);
        if (!run_result.exited_cleanly) {
            panel.error = run_result.message;
        } else if (!raw || raw->find("</svg>") == std::string::npos) {
            panel.error = "gnuplot exited without writing the figure";
        } else {
            panel.svg = inline_svg(*raw, "p" + std::to_string(index) + "-", panel.caption);
        }
    }

    GnuplotRun run(const std::string& script, const std::string& stem) const {
        GnuplotRun result;
        const fs::path script_path = scratch_ / (stem + ".gp");
        const fs::path log_path = scratch_ / (stem + ".log");
        try {
            write_text(script_path, script);
            ChildProcess gnuplot({options_.gnuplot, script_path.string()}, log_path);
            const std::string ending = gnuplot.stop(options_.gnuplot_time_limit);
            result.exited_cleanly = ending == "process exited with status 0";
            result.exited_with_status = ending.starts_with("process exited with status");
            if (!result.exited_cleanly) {
                result.message = "gnuplot (" + options_.gnuplot + "): " + ending;
                if (ending.find("signal 15") != std::string::npos || ending.find("SIGKILL") != std::string::npos) {
                    result.message += " (time limit " + std::to_string(options_.gnuplot_time_limit.count()) + " ms)";
                }
                result.message += printed_by_gnuplot(log_path);
            }
        } catch (const std::exception& error) {
            result.message = error.what();  // names the command line, so the script in the scratch directory
            replace_all(result.message, scratch_.string(), "<scratch>");
        }
        return result;
    }

    // The end of what gnuplot printed. The scratch directory's random name is
    // replaced here and above: the page must not change from run to run because of it.
    std::string printed_by_gnuplot(const fs::path& log_path) const {
        std::string text = read_file(log_path).value_or("");
        replace_all(text, scratch_.string(), "<scratch>");
        constexpr std::size_t kKeep = 2000;
        if (text.size() > kKeep) text = "\u2026" + text.substr(text.size() - kKeep);
        while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
        return text.empty() ? std::string() : ":\n" + text;
    }

    const HtmlReportOptions& options_;
    fs::path scratch_;
};

// Draws all panels; problems go into each panel's error.
void draw_panels(std::vector<Panel>& panels, const HtmlReportOptions& options) {
    if (panels.empty()) return;
    try {
        const ScratchDirectory scratch(options.scratch_parent);
        GnuplotDrawer(options, scratch.path()).draw(panels);
    } catch (const std::exception& error) {
        for (Panel& panel : panels) {
            if (panel.svg.empty() && panel.error.empty()) panel.error = error.what();
        }
    }
}

// ---------------------------------------------------------------- figure scripts

// Flow against distance to the breakpoint, as the paper's Fig. 14.
std::optional<Panel> flow_distance_panel(const CaseFigures& figures) {
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

TimeOrigin flow_time_origin(const CaseFigures& figures) {
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
std::optional<Panel> flow_time_panel(const CaseResult& result, const CaseFigures& figures) {
    const TimeOrigin origin = flow_time_origin(figures);
    const std::optional<double> adjust = metric(result, "flow_adjust_time_s");
    const std::optional<double> adjust_limit = limit(result, "flow_adjust_time_s");
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

std::vector<DoseRow> dose_rows(const CaseFigures& figures) {
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
Extent dose_x_extent(const CaseFigures& figures, const std::vector<DoseRow>& rows) {
    Extent extent;
    for (const DoseRow& row : rows) extent.include(row.along_m);
    extent.include(figures.breakpoint_along_m);
    for (const AreaSpan& area : figures.areas) {
        extent.include(area.from_along_m);
        extent.include(area.to_along_m);
    }
    return extent;
}

std::string area_shading(const CaseFigures& figures, bool with_labels) {
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
std::optional<Panel> dose_panel(const CaseFigures& figures, const std::vector<DoseRow>& rows) {
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
std::optional<Panel> normalised_dose_panel(const CaseFigures& figures, const std::vector<DoseRow>& rows) {
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
        for (const std::size_t i : entry.cases) measured += metric(results[i], name).has_value() ? 1 : 0;
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
        const double value = metric(result, suite_metric.name).value_or(kNotMeasured);
        const double limit_value = limit(result, suite_metric.name).value_or(kNotMeasured);
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

std::string area_table(const CaseFigures& figures) {
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

class PageBuilder {
public:
    // Adds a panel and returns where its drawing will go in the page.
    std::string place(Panel panel) {
        panels_.push_back(std::move(panel));
        return panel_marker(panels_.size() - 1);
    }
    std::vector<Panel>& panels() { return panels_; }

private:
    std::vector<Panel> panels_;
};

std::string case_label(std::size_t index, const CaseResult& result) {
    return "case " + std::to_string(index + 1) + " (" + valid_utf8(result.name) + ")";
}

std::string flow_figure(PageBuilder& page, std::size_t index, const CaseResult& result, const CaseFigures& figures) {
    std::optional<Panel> by_distance = flow_distance_panel(figures);
    if (!by_distance) return {};
    by_distance->what = case_label(index, result) + ": flow against distance";
    std::string figure =
        "<figure class=\"figure flow\" id=\"" + case_anchor(index) + "-flow\">\n<div class=\"panels\">\n";
    figure += page.place(std::move(*by_distance));
    if (std::optional<Panel> by_time = flow_time_panel(result, figures)) {
        by_time->what = case_label(index, result) + ": flow against time";
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
    if (const std::optional<double> adjust = metric(result, "flow_adjust_time_s")) {
        figure += " Adjust time " + shown_number(*adjust, 3) + " s";
        if (const std::optional<double> adjust_limit = limit(result, "flow_adjust_time_s")) {
            figure += " (limit " + shown_number(*adjust_limit, 3) + " s)";
        }
        figure += ".";
    }
    return figure + "</figcaption>\n</figure>\n";
}

std::string dose_figure(PageBuilder& page, std::size_t index, const CaseResult& result, const CaseFigures& figures) {
    const std::vector<DoseRow> rows = dose_rows(figures);
    std::optional<Panel> dose = dose_panel(figures, rows);
    if (!dose) return {};
    dose->what = case_label(index, result) + ": dose along the track";
    std::string figure =
        "<figure class=\"figure dose\" id=\"" + case_anchor(index) + "-dose\">\n<div class=\"panels stacked\">\n";
    figure += page.place(std::move(*dose));
    if (std::optional<Panel> normalised = normalised_dose_panel(figures, rows)) {
        normalised->what = case_label(index, result) + ": normalised dose";
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

// Seed 001's vision: the cover each ROI truly had and what the controller
// measured, as two maps of the ROI centres side by side.
std::optional<Panel> vision_map_panel(const std::vector<VisionRoiSample>& rois, bool measured) {
    std::vector<std::vector<double>> data;
    Extent east, north;
    for (const VisionRoiSample& roi : rois) {
        const double value = measured ? roi.measured_pct : roi.true_pct;
        east.include(roi.east_m);
        north.include(roi.north_m);
        if (std::isfinite(value)) data.push_back({roi.east_m, roi.north_m, value});
    }
    if (east.empty()) return std::nullopt;
    Panel panel;
    panel.caption = measured ? "Cover D per ROI as the controller measured it" : "Cover D per ROI, truth";
    panel.width = 420;
    panel.height = 520;
    std::string& script = panel.script;
    script += data_block("rois", data);
    script += "set title " + gnuplot_string(measured ? "measured (controller)" : "true (crop map)") + "\n";
    script += "set xlabel " + gnuplot_string("east (m)") + "\nset ylabel " + gnuplot_string("north (m)") + "\n";
    script += "set xrange " + east.range(0.1, 0.1) + "\nset yrange " + north.range(0.02, 0.02) + "\n";
    script += "set cbrange [0:80]\nset cblabel " + gnuplot_string("cover D (%)") + "\n";
    script += "set palette defined (0 '#8c6d46', 40 '#e8d36a', 80 '#1f7a2e')\nunset key\n";
    script += data.empty() ? "plot NaN notitle\n" : "plot $rois using 1:2:3 with points pt 5 ps 0.9 lc palette notitle\n";
    return panel;
}

std::string vision_figure(PageBuilder& page, std::size_t index, const CaseResult& result, const CaseFigures& figures,
                          const HtmlReportOptions& options) {
    if (figures.vision_rois.empty() && figures.vision_frames.empty()) return {};
    std::string figure = "<figure class=\"figure vision\" id=\"" + case_anchor(index) + "-vision\">\n";
    if (!figures.vision_frames.empty()) {
        figure += "<div class=\"frames\">\n";
        for (const VisionFrameImage& frame : figures.vision_frames) {
            std::filesystem::path link = frame.file;
            if (!options.report_dir.empty()) {
                std::error_code ignored;
                const std::filesystem::path relative = std::filesystem::relative(
                    std::filesystem::absolute(frame.file, ignored), std::filesystem::absolute(options.report_dir, ignored), ignored);
                if (!relative.empty()) link = relative;
            }
            std::string densities;
            for (const VisionRoiSample& roi : frame.rois) {
                densities += " nozzle " + std::to_string(roi.nozzle) + ": true " + shown_number(roi.true_pct, 3) +
                             " %, measured " +
                             (std::isfinite(roi.measured_pct) ? shown_number(roi.measured_pct, 3) + " %" : std::string("none")) + ";";
            }
            figure += "<figure class=\"frame\"><img src=\"" + html(link.generic_string()) +
                      "\" width=\"640\" alt=\"" + html((frame.camera == 0 ? "left" : "right") + std::string(" camera frame ") +
                                                      std::to_string(frame.frame_number)) +
                      "\"><figcaption>" + (frame.camera == 0 ? "Left" : "Right") + " camera, frame " +
                      std::to_string(frame.frame_number) + ":" + html(densities) + "</figcaption></figure>\n";
        }
        figure += "</div>\n";
    }
    figure += "<div class=\"panels\">\n";
    for (const bool measured : {false, true}) {
        if (std::optional<Panel> map = vision_map_panel(figures.vision_rois, measured)) {
            map->what = case_label(index, result) + (measured ? ": measured cover map" : ": true cover map");
            figure += page.place(std::move(*map));
        }
    }
    figure += "</div>\n<figcaption>Seed 001's vision: each camera's frame from the middle of the run with every "
              "nozzle's Sec. 2.1 ROI (600 x 400 mm, 200-600 mm ahead of the nozzle) outlined where it truly lies; "
              "below, the cover D of every ROI of every frame at its centre, from the crop truth and as the "
              "controller measured it (Eq. 15-17). A ROI without a measurement is left out of the second map.";
    if (const std::optional<double> error = metric(result, "vision_worst_camera_density_error_mean_abs_pct")) {
        figure += " Worst camera's mean |error| " + shown_number(*error, 3) + " points of cover.";
    }
    return figure + "</figcaption>\n</figure>\n";
}

std::string case_section(PageBuilder& page, std::size_t index, const CaseResult& result, const CaseFigures* figures,
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
        drawn += flow_figure(page, index, result, *figures);
        drawn += dose_figure(page, index, result, *figures);
        drawn += vision_figure(page, index, result, *figures, options);
        if (!figures->jitter.empty()) drawn += "<h3>Timing jitter</h3>\n" + jitter_table(figures->jitter);
    }
    if (!result.board_io.is_null()) drawn += "<h3>Board I/O (Modbus)</h3>\n" + board_io_table(result.board_io);
    if (drawn.empty()) drawn = "<p class=\"muted\">No flow, dose, vision or jitter data was recorded for this case.</p>\n";
    section += drawn;
    section += "<p class=\"nav\"><a href=\"#cases\">\u2191 case table</a></p>\n</section>\n";
    return section;
}

std::string suite_section(PageBuilder& page, const std::vector<CaseResult>& results) {
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

std::string drawn_panel(const Panel& panel) {
    if (!panel.svg.empty()) return "<div class=\"panel\">" + panel.svg + "</div>\n";
    return "<div class=\"panel figure-error\"><strong>" + html(panel.caption) + ": not drawn.</strong>\n<pre>" +
           html(panel.error) + "</pre></div>\n";
}

// Puts each panel's drawing (or its error) where its marker is.
std::string with_panels(const std::string& body, const std::vector<Panel>& panels) {
    std::string page;
    page.reserve(body.size());
    std::size_t pos = 0;
    while (pos < body.size()) {
        const std::size_t start = body.find('\x01', pos);
        if (start == std::string::npos) {
            page.append(body, pos, std::string::npos);
            break;
        }
        page.append(body, pos, start - pos);
        const std::size_t end = body.find('\x01', start + 1);
        const std::string marker = body.substr(start + 1, end - start - 1);  // "panel N"
        const std::size_t index = std::stoul(marker.substr(marker.find(' ') + 1));
        page += drawn_panel(panels.at(index));
        pos = end + 1;
    }
    return page;
}

// One line per distinct reason, naming the panels it spoiled.
std::vector<std::string> panel_problems(const std::vector<Panel>& panels) {
    std::vector<std::string> reasons;
    std::map<std::string, std::vector<std::string>> spoiled;
    for (const Panel& panel : panels) {
        if (panel.error.empty()) continue;
        auto& whats = spoiled[panel.error];
        if (whats.empty()) reasons.push_back(panel.error);
        whats.push_back(panel.what);
    }
    std::vector<std::string> problems;
    for (const std::string& reason : reasons) {
        const auto& whats = spoiled[reason];
        std::string line = std::to_string(whats.size()) + " figure panel" + (whats.size() == 1 ? "" : "s") +
                           " not drawn (" + whats.front() + (whats.size() > 1 ? ", ..." : "") + "): " + reason;
        problems.push_back(std::move(line));
    }
    return problems;
}

}  // namespace

HtmlReport render_html_report(const std::vector<CaseResult>& results, const std::vector<CaseFigures>& figures,
                              const RunSummary& summary, const HtmlReportOptions& options) {
    HtmlReport report;
    if (figures.size() != results.size() && !figures.empty()) {
        report.problems.push_back("figures for " + std::to_string(figures.size()) + " cases, results for " +
                                  std::to_string(results.size()) + ": the figures are matched by position");
    }

    PageBuilder page;
    std::string body = "<section id=\"cases\">\n<h2>Cases</h2>\n" + summary_table(results) + "</section>\n";
    body += suite_section(page, results);
    for (std::size_t i = 0; i < results.size(); ++i) {
        body += case_section(page, i, results[i], i < figures.size() ? &figures[i] : nullptr, options);
    }
    draw_panels(page.panels(), options);
    const std::vector<std::string> problems = panel_problems(page.panels());
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
    out += with_panels(body, page.panels());
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
