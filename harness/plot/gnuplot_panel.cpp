#include "harness/plot/gnuplot_panel.h"

#include <stdlib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "rig/host/child_process.h"

namespace rig::harness {

namespace fs = std::filesystem;

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

void Extent::include(double value) {
    if (!std::isfinite(value)) return;
    low = std::isnan(low) ? value : std::min(low, value);
    high = std::isnan(high) ? value : std::max(high, value);
}

bool Extent::empty() const { return std::isnan(low); }

std::string Extent::range(double fraction_low, double fraction_high) const {
    double width = high - low;
    if (!(width > 0)) width = std::max(std::abs(high) * 0.1, 1.0);
    return "[" + exact_number(low - width * fraction_low) + ":" + exact_number(high + width * fraction_high) + "]";
}

std::string rgb(std::string_view hex) { return "rgb '" + std::string(hex) + "'"; }

std::string vertical_marker(int tag, double x, std::string_view color, std::string_view dash, const std::string& text,
                            bool text_on_left, double text_height) {
    const std::string at = exact_number(x);
    std::string script = "set arrow " + std::to_string(tag) + " from first " + at + ", graph 0 to first " + at +
                         ", graph 1 nohead back lw 1.5 lc " + rgb(color) + " dt " + std::string(dash) + "\n";
    script += "set label " + std::to_string(tag) + " " + gnuplot_string(text) + " at first " + at + ", graph " +
              exact_number(text_height) + (text_on_left ? " right offset -0.5,-1" : " left offset 0.5,-1") +
              " front boxed textcolor " + rgb(color) + "\n";
    return script;
}

namespace {

// The part every panel's script starts with after its terminal: one look for all figures.
constexpr std::string_view kCommonStyle =
    "set border lc rgb '#555555'\n"
    "set grid lc rgb '#e3e3e3' lt 1 lw 1\n"
    "set tics nomirror\n"
    "set key opaque box lc rgb '#bbbbbb' samplen 2.5 spacing 1.1\n"
    // Marker labels sit on a white box: a line crossing them must not run through the text.
    "set style textbox opaque noborder margins 1,1\n";

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
    GnuplotDrawer(const GnuplotOptions& options, const fs::path& scratch) : options_(options), scratch_(scratch) {}

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
            const std::string ending = gnuplot.stop(options_.time_limit);
            result.exited_cleanly = ending == "process exited with status 0";
            result.exited_with_status = ending.starts_with("process exited with status");
            if (!result.exited_cleanly) {
                result.message = "gnuplot (" + options_.gnuplot + "): " + ending;
                if (ending.find("signal 15") != std::string::npos || ending.find("SIGKILL") != std::string::npos) {
                    result.message += " (time limit " + std::to_string(options_.time_limit.count()) + " ms)";
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

    const GnuplotOptions& options_;
    fs::path scratch_;
};

}  // namespace

void draw_panels(std::vector<Panel>& panels, const GnuplotOptions& options) {
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


std::string FigurePage::place(Panel panel) {
    panels_.push_back(std::move(panel));
    return panel_marker(panels_.size() - 1);
}

namespace {

std::string drawn_panel(const Panel& panel) {
    if (!panel.svg.empty()) return "<div class=\"panel\">" + panel.svg + "</div>\n";
    return "<div class=\"panel figure-error\"><strong>" + html(panel.caption) + ": not drawn.</strong>\n<pre>" +
           html(panel.error) + "</pre></div>\n";
}

}  // namespace

// Puts each panel's drawing (or its error) where its marker is.
std::string FigurePage::with_panels(const std::string& body) const {
    const std::vector<Panel>& panels = panels_;
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
std::vector<std::string> FigurePage::problems() const {
    const std::vector<Panel>& panels = panels_;
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

}  // namespace rig::harness
