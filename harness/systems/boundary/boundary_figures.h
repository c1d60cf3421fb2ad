#pragma once
// Seed 001's figures for the report (report.html): each camera's frame from
// the middle of the run with every nozzle's true ROI outlined, and the cover
// of every ROI of every frame as two maps, truth and as the controller
// measured it; made by the judge from the trace alone.
#include <filesystem>
#include <string>
#include <vector>

#include "harness/judge/case_figures.h"

namespace rig::harness {

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

class BoundaryFigures final : public SystemFigures {
public:
    std::string html(FigurePage& page, const FigureContext& where, const CaseResult& result) const override;

    std::vector<VisionRoiSample> rois;       // every frame's
    std::vector<VisionFrameImage> frames;    // the frames kept for the report
};

}  // namespace rig::harness
