#include "controller/boundary/vision/vision_params.h"

#include "rig/camera/parameter_check.h"

namespace rig::controller::boundary::vision {

using rig::camera::finite_within;
using rig::camera::require_parameter;

void validate(const VisionParams& p) {
    const std::string where = "vision";
    require_parameter(finite_within(p.roi_width_m, 1e-9, 5.0), where, "roi_width_m", p.roi_width_m, "(0, 5] m");
    require_parameter(finite_within(p.roi_near_m, -2.0, 5.0), where, "roi_near_m", p.roi_near_m, "[-2, 5] m");
    require_parameter(finite_within(p.roi_depth_m, 1e-9, 5.0), where, "roi_depth_m", p.roi_depth_m, "(0, 5] m");
    require_parameter(finite_within(p.warp_mm_per_px, 0.5, 50.0), where, "warp_mm_per_px", p.warp_mm_per_px, "[0.5, 50] mm");
    require_parameter(p.exg_floor >= 0 && p.exg_floor <= 255, where, "exg_floor", p.exg_floor, "[0, 255]");
    require_parameter(finite_within(p.dark_frame_mean_max_dn, 0.0, 255.0), where, "dark_frame_mean_max_dn", p.dark_frame_mean_max_dn, "[0, 255]");
    require_parameter(finite_within(p.min_roi_share_in_frame, 1e-9, 1.0), where, "min_roi_share_in_frame", p.min_roi_share_in_frame, "(0, 1]");
}

}  // namespace rig::controller::boundary::vision
