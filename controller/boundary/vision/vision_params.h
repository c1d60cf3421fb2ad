#pragma once
// The controller vision's own parameters (Sec. 2.1, 4.1; S7), with units,
// defaults, bounds and where each value comes from. A plain struct without
// Eigen or pixels, so the controller's configuration (boundary_node_config.h)
// can read and check them; controller/boundary/vision/nozzle_vision.h uses them.
#include <string>

namespace rig::controller::boundary::vision {

struct VisionParams {
    // Sec. 2.1: the ROI is w = 600 mm across, from h1 = 200 mm to h1 + h2 =
    // 600 mm ahead of the nozzle (Sec. 5.2 marks the same 60 x 40 cm frames).
    double roi_width_m = 0.600;              // (0, 5] m
    double roi_near_m = 0.200;               // [-2, 5] m
    double roi_depth_m = 0.400;              // (0, 5] m
    // The warped rectangle's pixel size on the ground. Assumed 2 mm: about the
    // ground footprint of a pixel across the ROI at 1280 x 720 (1.7-2.5 mm),
    // so the warp neither throws away nor invents detail. The paper gives none.
    double warp_mm_per_px = 2.0;             // [0.5, 50] mm
    // S7: the least ExG counted as plant whatever Otsu finds. Assumed 40: bare
    // soil's ExG is about 0 with a noise SD near 15 DN at 6 DN per channel, a
    // seedling leaf's about 150.
    int exg_floor = 40;                      // [0, 255]
    // A frame whose mean byte is at most this is dark (a dead or covered
    // camera): no density, not D = 0. Assumed 8 DN (soil in shade is ~40).
    double dark_frame_mean_max_dn = 8.0;     // [0, 255]
    // A nozzle gets a density only when this share of its warped ROI lies
    // inside the frame (assumed).
    double min_roi_share_in_frame = 0.95;    // (0, 1]
};

// Throws std::invalid_argument "vision.<field>: <what>".
void validate(const VisionParams& params);

}  // namespace rig::controller::boundary::vision
