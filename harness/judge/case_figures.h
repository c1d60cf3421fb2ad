#pragma once
// What a case's report section draws besides its metrics (report.html): the
// figures of the case's system, made by its judge from the trace alone, and
// a real-time run's timing jitter, which every system has.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "harness/judge/case_result.h"
#include "harness/plot/gnuplot_panel.h"

namespace rig::harness {

// Wake-up jitter of one device emulator (real-time runs only).
struct JitterRow {
    std::string device;
    double p50_ms = kNotMeasured;
    double p99_ms = kNotMeasured;
    double max_ms = kNotMeasured;
    double step_max_ms = kNotMeasured;  // its own slowest update
};

// Where a case's figures go on the page.
struct FigureContext {
    std::string anchor;  // the case section's id ("case-3"): a figure's id begins with it
    std::string label;   // "case 3 (name)": names a panel in the page's problem lines
    std::filesystem::path report_dir;  // images beside the traces are linked relative to it; empty: as given
};

// A system's figures of one case (seed 000: Fig. 14 and 15; seed 001: the
// vision maps and frames), drawn onto the page.
class SystemFigures {
public:
    virtual ~SystemFigures() = default;
    // The figures' HTML, their panels placed on `page` (drawn later, all at
    // once); empty when the run recorded nothing to draw.
    virtual std::string html(FigurePage& page, const FigureContext& where, const CaseResult& result) const = 0;
};

struct CaseFigures {
    std::vector<JitterRow> jitter;
    std::shared_ptr<const SystemFigures> system;  // null: nothing of the system's to draw
};

}  // namespace rig::harness
