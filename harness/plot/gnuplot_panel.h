#pragma once
// Figures drawn by gnuplot into the report page (harness/report/html_report.h):
// a Panel is one plot, its script and, once drawn, its inline SVG; a FigurePage
// collects the panels of a whole page and draws them all at once
// (draw_panels: one gnuplot for every panel, each alone only when that fails).
// The drawing helpers (data blocks, extents, markers, one palette) are shared
// by the page and by each system's figures (harness/systems/*/).
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "harness/plot/figure_text.h"

namespace rig::harness {

struct Point {
    double x;
    double y;
};

// Long series are cut down for the page: per bucket of consecutive points the
// lowest and the highest are kept (in their order), so spikes and the envelope
// survive while a 60 s trace at 1 kHz does not make a 10 MB page.
std::vector<Point> thinned(const std::vector<Point>& points, std::size_t max_points);
inline constexpr std::size_t kMaxPointsPerSeries = 2400;

// A gnuplot inline data block: `$name << EOD` ... `EOD`; rows of numbers only.
std::string data_block(const std::string& name, const std::vector<std::vector<double>>& rows);
std::string data_block(const std::string& name, const std::vector<Point>& points);

// A closed interval that grows to include values; empty until the first finite one.
struct Extent {
    double low = kNotMeasured;
    double high = kNotMeasured;

    void include(double value);
    bool empty() const;
    // "[low:high]" widened by `fraction` of its width on each side (never zero-width).
    std::string range(double fraction_low, double fraction_high) const;
};

// One look for all figures.
std::string rgb(std::string_view hex);
inline constexpr std::string_view kTruthColor = "#1f77b4";
inline constexpr std::string_view kMeasuredColor = "#ff7f0e";
inline constexpr std::string_view kTargetColor = "#2ca02c";
inline constexpr std::string_view kBreakpointColor = "#222222";
inline constexpr std::string_view kOpenCommandColor = "#d62728";
inline constexpr std::string_view kLimitColor = "#d62728";
inline constexpr std::string_view kFirstPassColor = "#3182bd";
inline constexpr std::string_view kContinuationColor = "#31a354";
inline constexpr std::string_view kTotalColor = "#222222";

// A vertical marker across the plot at x (first axis), with its text at
// `text_height` (graph fraction) beside it. The line is drawn behind the curves
// and the text in front on an opaque box, so neither hides the other.
std::string vertical_marker(int tag, double x, std::string_view color, std::string_view dash, const std::string& text,
                            bool text_on_left, double text_height = 1.0);

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

struct GnuplotOptions {
    // The gnuplot program: searched in PATH when it has no '/'.
    std::string gnuplot = "gnuplot";
    // For drawing all figures; a gnuplot still running then is stopped and the
    // figures show that instead.
    std::chrono::milliseconds time_limit{60'000};
    // Where the scratch directory for gnuplot's script and output goes; empty:
    // std::filesystem::temp_directory_path(). Removed afterwards.
    std::filesystem::path scratch_parent;
};

// Draws every panel; problems go into each panel's error (never throws for them).
void draw_panels(std::vector<Panel>& panels, const GnuplotOptions& options);

// The panels of one page while it is built: each is placed where the page
// wants it, and all are drawn at once afterwards.
class FigurePage {
public:
    // Adds a panel and returns where its drawing will go in the page text.
    std::string place(Panel panel);
    std::vector<Panel>& panels() { return panels_; }
    // The page text with each panel's drawing (or its error) where place() put it.
    std::string with_panels(const std::string& body) const;
    // One line per distinct reason a panel was not drawn, naming the panels it spoiled.
    std::vector<std::string> problems() const;

private:
    std::vector<Panel> panels_;
};

}  // namespace rig::harness
