#pragma once
// `rig diff --html` (docs/diff.md): one self-contained page (inline CSS and
// SVG, no script, no network) with what `rig diff` printed and the key
// signals of the case's system (harness/systems/system.h KeySignal) of both
// runs over each other around the instant they part. Drawn by gnuplot as the
// report's figures are (harness/plot/gnuplot_panel.h).
#include <optional>
#include <string>
#include <vector>

#include "harness/plot/gnuplot_panel.h"
#include "harness/report/html_report.h"
#include "harness/systems/system.h"

namespace rig::harness {

struct DiffPage {
    std::string case_name;
    std::string report_text;  // what `rig diff` printed
    std::string a_label;      // where run A came from (its trace or run directory)
    std::string b_label;
    std::vector<KeySignal> a_signals;
    std::vector<KeySignal> b_signals;
    // Where each run ends (s): a held signal is drawn at its last value up to there.
    double a_end_s = 0.0;
    double b_end_s = 0.0;
    // The stretch of simulated time drawn (s).
    double from_s = 0.0;
    double to_s = 0.0;
    // Where the runs part, marked on every signal; none when they do not.
    std::optional<double> parted_at_s;
    std::string parted_topic;
};

// Never throws for a figure that cannot be drawn: it is in `problems` and in
// its place on the page.
HtmlReport render_diff_page(const DiffPage& page, const GnuplotOptions& options);

}  // namespace rig::harness
