#pragma once
// report.html: the human report a person looks at rather than reads. One
// self-contained file (inline CSS and SVG, no script, no network) with the
// run summary, the case table and, per case, the figures of the paper's
// section 3.2.2: flow against distance to the breakpoint (Fig. 14) and row
// deposits across the breakpoint (Fig. 15). Figures are drawn by gnuplot's svg
// terminal, started as a child process; data goes through a script file, never
// through a shell. Same inputs give the same bytes (no timestamps).
#include <chrono>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "harness/metrics.h"  // AreaSpan
#include "harness/results_writer.h"

namespace rig::harness {

inline constexpr double kNotMeasured = std::numeric_limits<double>::quiet_NaN();

// One sample of the main-pipeline flow around the section-open command.
struct FlowSample {
    double t_s = kNotMeasured;                       // simulated time
    double distance_to_breakpoint_m = kNotMeasured;  // nozzle line minus breakpoint along the track: negative before it
    double main_flow_l_min = kNotMeasured;           // truth (plant)
    double measured_flow_l_min = kNotMeasured;       // what the controller computed (Eq. 3); NaN if unknown
};

// One row of the deposition grid, summed across the boom (the paper's row of filter papers).
struct DoseSample {
    double along_m = kNotMeasured;
    double first_pass_dose = kNotMeasured;    // sprayed before the breakpoint stop
    double continuation_dose = kNotMeasured;  // sprayed after the resume; same unit (the rig: uL/cm^2, mean across the boom)
};

// A stretch of track the harness classified; name is "operational", "repeated",
// "continuation" or "missed" (other names are drawn in grey).
// Wake-up jitter of one device emulator (real-time runs only).
struct JitterRow {
    std::string device;
    double p50_ms = kNotMeasured;
    double p99_ms = kNotMeasured;
    double max_ms = kNotMeasured;
    double step_max_ms = kNotMeasured;  // its own slowest update
};

// What one case recorded for its figures; a figure is drawn only when it has data.
// Seed 001's vision: one nozzle ROI of one frame, true and measured cover.
struct VisionRoiSample {
    int camera = 0;
    int nozzle = 0;
    double east_m = 0.0;              // the true ROI's centre, local frame
    double north_m = 0.0;
    double true_pct = 0.0;            // true cover D, %
    double measured_pct = kNotMeasured;  // the controller's D, %; NaN when it gave none
};
// A camera frame kept for the report (a PNG beside the trace, the true ROIs drawn on it).
struct VisionFrameImage {
    int camera = 0;
    long frame_number = 0;
    std::filesystem::path file;       // where the PNG is (as the trace's directory was named)
    std::vector<VisionRoiSample> rois;   // that frame's
};

struct CaseFigures {
    double target_flow_l_min = kNotMeasured;  // NaN: no flow control in this case
    double breakpoint_along_m = 0.0;
    // Where the controller opened the sections (distance to breakpoint, m) ...
    std::optional<double> section_open_command_distance_m;
    // ... and when (s). Without it the time is interpolated from the flow samples'
    // distances; without either, the flow-time panel counts from the first sample.
    std::optional<double> section_open_command_t_s;
    std::vector<FlowSample> flow;
    std::vector<DoseSample> dose;
    std::vector<AreaSpan> areas;
    std::vector<JitterRow> jitter;
    std::vector<VisionRoiSample> vision_rois;    // every frame's
    std::vector<VisionFrameImage> vision_frames;
};

struct HtmlReportOptions {
    std::string title = "Sprayer HIL rig report";
    // The gnuplot program: searched in PATH when it has no '/'.
    std::string gnuplot = "gnuplot";
    // For drawing all figures; a gnuplot still running then is stopped and the
    // figures show that instead.
    std::chrono::milliseconds gnuplot_time_limit{60'000};
    // Where the scratch directory for gnuplot's script and output goes; empty:
    // std::filesystem::temp_directory_path(). Removed afterwards.
    std::filesystem::path scratch_parent;
    // The report's directory: images beside the traces are linked relative to
    // it. Empty: linked by the path the figures hold (write_html_report sets it).
    std::filesystem::path report_dir;
};

struct HtmlReport {
    std::string html;
    // One line per figure that could not be drawn (or other trouble, e.g. figures
    // and results of different lengths); the html shows each in place.
    std::vector<std::string> problems;
};

// Builds the page. figures[i] belongs to results[i]; missing entries count as
// "no figures". Never throws for a figure problem (it is in `problems`); only
// for running out of memory and the like.
HtmlReport render_html_report(const std::vector<CaseResult>& results, const std::vector<CaseFigures>& figures,
                              const RunSummary& summary, const HtmlReportOptions& options = {});

// render_html_report() written to `file` through a temporary renamed into place.
// Returns the problems (empty when every figure was drawn); throws
// std::runtime_error / filesystem_error only when the file cannot be written.
std::vector<std::string> write_html_report(const std::filesystem::path& file, const std::vector<CaseResult>& results,
                                           const std::vector<CaseFigures>& figures, const RunSummary& summary,
                                           const HtmlReportOptions& options = {});

}  // namespace rig::harness
