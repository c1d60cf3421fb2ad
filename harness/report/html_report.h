#pragma once
// report.html: the human report a person looks at rather than reads. One
// self-contained file (inline CSS and SVG, no script, no network) with the
// run summary, the case table, the limited metrics across cases and, per
// case, its facts, metrics and its system's figures (seed 000: the paper's
// Fig. 14 and 15; seed 001: the vision maps and frames; harness/systems/*/).
// Figures are drawn by gnuplot's svg terminal, started as a child process
// (harness/plot/gnuplot_panel.h); data goes through a script file, never
// through a shell. Same inputs give the same bytes (no timestamps).
#include <chrono>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "harness/judge/case_figures.h"
#include "harness/judge/case_result.h"
#include "harness/report/results_writer.h"

namespace rig::harness {

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
