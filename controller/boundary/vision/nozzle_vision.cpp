#include "controller/boundary/vision/nozzle_vision.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "controller/boundary/boundary_equations.h"
#include "controller/boundary/vision/image_ops.h"
#include "rig/camera/parameter_check.h"

namespace rig::controller::boundary::vision {

namespace {

using rig::camera::finite_within;
using rig::camera::require_parameter;

std::string camera_where(const VisionCameraConfig& camera, std::size_t index) {
    return "vision.cameras[" + std::to_string(index) + "] '" + camera.name + "'";
}

void require_boom_height(double boom_height_m) {
    if (!finite_within(boom_height_m, 1e-9, 5.0)) {
        std::ostringstream message;
        message << "vision: boom height " << boom_height_m << " m is outside (0, 5] m";
        throw std::invalid_argument(message.str());
    }
}

Eigen::Vector2d rotate(const Eigen::Vector2d& p, double angle_rad) {
    const double c = std::cos(angle_rad);
    const double s = std::sin(angle_rad);
    return {c * p.x() - s * p.y(), s * p.x() + c * p.y()};
}

Eigen::Vector2d apply(const Eigen::Matrix3d& homography, const Eigen::Vector2d& p) {
    const Eigen::Vector3d h = homography * Eigen::Vector3d(p.x(), p.y(), 1.0);
    return {h.x() / h.z(), h.y() / h.z()};
}

}  // namespace


void validate(const VisionCameraConfig& camera, std::size_t index) {
    const std::string where = camera_where(camera, index);
    if (camera.name.empty()) throw std::invalid_argument(where + ".name: empty");
    rig::camera::validate(camera.model, where + ".model");
    if (camera.nozzles.empty()) throw std::invalid_argument(where + ".nozzles: empty (a camera sees at least one nozzle)");
    for (std::size_t i = 0; i < camera.nozzles.size(); ++i) {
        require_parameter(camera.nozzles[i] >= 0 && camera.nozzles[i] < 32, where, ("nozzles[" + std::to_string(i) + "]").c_str(),
                camera.nozzles[i], "[0, 31]");
    }
    if (camera.nozzle_pixels.empty()) {
        if (camera.nozzle_right_m.size() != camera.nozzles.size()) {
            throw std::invalid_argument(where + ".nozzle_right_m: " + std::to_string(camera.nozzle_right_m.size()) +
                                        " positions for " + std::to_string(camera.nozzles.size()) + " nozzles");
        }
        for (std::size_t i = 0; i < camera.nozzle_right_m.size(); ++i) {
            require_parameter(finite_within(camera.nozzle_right_m[i], -20.0, 20.0), where, ("nozzle_right_m[" + std::to_string(i) + "]").c_str(),
                    camera.nozzle_right_m[i], "[-20, 20] m");
        }
    } else if (camera.nozzle_pixels.size() != camera.nozzles.size()) {
        throw std::invalid_argument(where + ".nozzle_pixels: " + std::to_string(camera.nozzle_pixels.size()) +
                                    " points for " + std::to_string(camera.nozzles.size()) + " nozzles");
    } else {
        for (std::size_t i = 0; i < camera.nozzle_pixels.size(); ++i) {
            const PixelPoint& p = camera.nozzle_pixels[i];
            const std::string field = "nozzle_pixels[" + std::to_string(i) + "].";
            require_parameter(finite_within(p.u_px, -1e4, 1e4), where, (field + "u_px").c_str(), p.u_px, "[-10000, 10000] px");
            require_parameter(finite_within(p.v_px, -1e4, 1e4), where, (field + "v_px").c_str(), p.v_px, "[-10000, 10000] px");
        }
    }
}

std::vector<VisionCameraConfig> seed001_vision_cameras(const BoundaryControllerConfig& boundary) {
    std::vector<VisionCameraConfig> cameras(2);
    cameras[0].name = "left";
    cameras[1].name = "right";
    cameras[0].model = rig::camera::seed001_boom_camera(false);
    cameras[1].model = rig::camera::seed001_boom_camera(true);
    const int left_count = (boundary.nozzle_count + 1) / 2;
    for (int nozzle = 0; nozzle < boundary.nozzle_count; ++nozzle) {
        VisionCameraConfig& camera = cameras[nozzle < left_count ? 0 : 1];
        camera.nozzles.push_back(nozzle);
        camera.nozzle_right_m.push_back((nozzle - 0.5 * (boundary.nozzle_count - 1)) * boundary.nozzle_spacing_m);
    }
    return cameras;
}

const char* frame_status_name(FrameStatus status) {
    switch (status) {
        case FrameStatus::ok: return "ok";
        case FrameStatus::no_frame: return "no_frame";
        case FrameStatus::dark_frame: return "dark_frame";
        case FrameStatus::wrong_size: return "wrong_size";
    }
    return "unknown";
}

CameraVision::CameraVision(VisionCameraConfig camera, VisionParams params, std::size_t index)
    : camera_((validate(camera, index), std::move(camera))),
      params_((validate(params), params)),
      model_(camera_.model, camera_where(camera_, index) + ".model") {
    const std::string where = camera_where(camera_, index);
    // Eq. 5: the boom plane's homography, inverted, takes the calibration
    // image's nozzle points onto the boom plane.
    const Eigen::Matrix3d boom_plane_to_pixel = model_.plane_to_undistorted_pixel(0.0);
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(boom_plane_to_pixel);
    if (!lu.isInvertible()) throw std::invalid_argument(where + ".model: the camera looks along the boom plane (Eq. 5 has no inverse)");
    const Eigen::Matrix3d pixel_to_boom_plane = lu.inverse();
    for (std::size_t i = 0; i < camera_.nozzles.size(); ++i) {
        Eigen::Vector2d pixel;
        if (camera_.nozzle_pixels.empty()) {
            pixel = apply(boom_plane_to_pixel, Eigen::Vector2d(camera_.nozzle_right_m[i], 0.0));
        } else {
            pixel = Eigen::Vector2d(camera_.nozzle_pixels[i].u_px, camera_.nozzle_pixels[i].v_px);
        }
        const Eigen::Vector3d h = pixel_to_boom_plane * Eigen::Vector3d(pixel.x(), pixel.y(), 1.0);
        // A pixel whose ray never meets the boom plane (above that plane's
        // horizon) still maps somewhere under H^-1: onto the plane behind the
        // camera. Refuse it rather than put a ROI there.
        const Eigen::Vector3d in_camera = model_.axes_in_boom().transpose() *
                                          (Eigen::Vector3d(h.x() / h.z(), h.y() / h.z(), 0.0) - model_.position_in_boom());
        if (!std::isfinite(h.x() / h.z()) || in_camera.z() <= 0.0) {
            throw std::invalid_argument(where + ": nozzle " + std::to_string(camera_.nozzles[i]) + "'s point (" +
                                        std::to_string(pixel.x()) + ", " + std::to_string(pixel.y()) +
                                        ") px does not see the boom plane");
        }
        nozzle_boom_plane_.emplace_back(h.x() / h.z(), h.y() / h.z());
    }
}

int CameraVision::warp_width_px() const { return std::max(1, static_cast<int>(std::lround(params_.roi_width_m * 1000.0 / params_.warp_mm_per_px))); }
int CameraVision::warp_height_px() const { return std::max(1, static_cast<int>(std::lround(params_.roi_depth_m * 1000.0 / params_.warp_mm_per_px))); }

std::vector<NozzleRoi> CameraVision::rois(double boom_height_m) const {
    require_boom_height(boom_height_m);
    const Eigen::Matrix3d boom_plane_to_pixel = model_.plane_to_undistorted_pixel(0.0);
    const Eigen::Matrix3d ground_to_pixel = model_.plane_to_undistorted_pixel(-boom_height_m);
    // Eq. 6: each nozzle point dropped onto the ground (x, y keep; z = -h).
    std::vector<Eigen::Vector2d> ground_points = nozzle_boom_plane_;
    // Eq. 7: the projected boom line's angle, through the outermost nozzles.
    double alpha = 0.0;
    if (ground_points.size() >= 2) {
        const Eigen::Vector2d along = ground_points.back() - ground_points.front();
        alpha = std::atan2(along.y(), along.x());
    }
    const double half = 0.5 * params_.roi_width_m;
    const double near = params_.roi_near_m;
    const double far = params_.roi_near_m + params_.roi_depth_m;
    std::vector<NozzleRoi> rois;
    for (std::size_t i = 0; i < ground_points.size(); ++i) {
        NozzleRoi roi;
        roi.nozzle = camera_.nozzles[i];
        roi.nozzle_boom_plane = nozzle_boom_plane_[i];
        roi.nozzle_pixel = apply(boom_plane_to_pixel, nozzle_boom_plane_[i]);
        roi.nozzle_ground = ground_points[i];
        const Eigen::Vector2d turned = rotate(ground_points[i], -alpha);  // Eq. 7
        const std::array<Eigen::Vector2d, 4> offsets{Eigen::Vector2d(-half, near), Eigen::Vector2d(half, near),
                                                     Eigen::Vector2d(half, far), Eigen::Vector2d(-half, far)};
        for (std::size_t c = 0; c < 4; ++c) {
            roi.ground[c] = rotate(turned + offsets[c], alpha);  // Eq. 8
            roi.undistorted_px[c] = apply(ground_to_pixel, roi.ground[c]);
            const std::optional<Eigen::Vector2d> pixel = model_.project(Eigen::Vector3d(roi.ground[c].x(), roi.ground[c].y(), -boom_height_m));
            roi.image_px[c] = pixel ? *pixel : Eigen::Vector2d(std::nan(""), std::nan(""));
        }
        rois.push_back(roi);
    }
    return rois;
}

namespace {

// The ROI's quadrilateral warped to its rectangle (Sec. 4.1's "perspective
// transformation"), the lens undone in the same resampling. Far edge at the
// rectangle's top row.
RectangleWarp warp_roi_rectangle(const rig::camera::PinholeCamera& model, const rig::camera::RgbImage& frame, const NozzleRoi& roi,
                                 int width, int height) {
    // Rectangle corners in the order of roi's (near-left, near-right, far-right, far-left).
    const std::vector<Eigen::Vector2d> rectangle{Eigen::Vector2d(0.0, height), Eigen::Vector2d(width, height), Eigen::Vector2d(width, 0.0),
                                                 Eigen::Vector2d(0.0, 0.0)};
    const std::vector<Eigen::Vector2d> quadrilateral(roi.undistorted_px.begin(), roi.undistorted_px.end());
    return warp_to_rectangle(frame, model.model().intrinsics, model.model().distortion, fit_homography(rectangle, quadrilateral), width,
                             height);
}

}  // namespace

FrameDensities CameraVision::measure(const rig::camera::RgbImage* frame, double boom_height_m) const {
    FrameDensities result;
    if (frame == nullptr) {
        result.status = FrameStatus::no_frame;
        result.detail = camera_.name + ": no frame from the camera";
        return result;
    }
    if (const auto problem = rig::camera::frame_size_problem(*frame, model_.model().intrinsics)) {
        result.status = FrameStatus::wrong_size;
        result.detail = camera_.name + ": " + *problem;
        return result;
    }
    // Summed as integers (exact, and the compiler can vectorise it; a chain
    // of double additions took 1.7 ms of CPU a frame, this 0.24 ms): the same
    // mean as before.
    std::uint64_t byte_sum = 0;
    for (const std::uint8_t byte : frame->bytes) byte_sum += byte;
    const double mean_byte = static_cast<double>(byte_sum) / static_cast<double>(frame->bytes.size());
    if (mean_byte <= params_.dark_frame_mean_max_dn) {
        result.status = FrameStatus::dark_frame;
        std::ostringstream detail;
        detail << camera_.name << ": dark frame (mean " << mean_byte << " DN <= " << params_.dark_frame_mean_max_dn << ")";
        result.detail = detail.str();
        return result;
    }
    result.status = FrameStatus::ok;
    result.otsu_threshold = otsu_threshold(excess_green_values(*frame));
    result.threshold = std::max(result.otsu_threshold.value_or(0), params_.exg_floor);
    const int width = warp_width_px();
    const int height = warp_height_px();
    for (const NozzleRoi& roi : rois(boom_height_m)) {
        NozzleDensity nozzle;
        nozzle.nozzle = roi.nozzle;
        nozzle.roi = roi;
        bool corners_in_view = true;
        for (const Eigen::Vector2d& corner : roi.image_px) corners_in_view = corners_in_view && corner.allFinite();
        if (!corners_in_view) {
            // A corner behind the camera (a boom far too high or low for this
            // mounting): the ROI is not in the frame at all.
            nozzle.roi_px_outside = static_cast<long>(width) * height;
            result.nozzles.push_back(nozzle);
            continue;
        }
        const RectangleWarp warp = warp_roi_rectangle(model_, *frame, roi, width, height);
        nozzle.roi_px = warp.inside_px;
        nozzle.roi_px_outside = static_cast<long>(warp.inside.size()) - warp.inside_px;
        for (std::size_t n = 0; n < warp.inside.size(); ++n) {
            if (warp.inside[n] == 0) continue;
            const rig::camera::Rgb pixel{warp.image.bytes[3 * n], warp.image.bytes[3 * n + 1], warp.image.bytes[3 * n + 2]};
            if (excess_green(pixel) >= result.threshold) ++nozzle.plant_px;  // Eq. 16
        }
        const double inside_share = static_cast<double>(nozzle.roi_px) / static_cast<double>(nozzle.roi_px + nozzle.roi_px_outside);
        nozzle.measured = inside_share >= params_.min_roi_share_in_frame;
        if (nozzle.measured) nozzle.density = static_cast<double>(nozzle.plant_px) / static_cast<double>(nozzle.roi_px);  // Eq. 17
        result.nozzles.push_back(nozzle);
    }
    return result;
}

rig::camera::RgbImage CameraVision::warp_roi(const rig::camera::RgbImage& frame, const NozzleRoi& roi) const {
    return warp_roi_rectangle(model_, frame, roi, warp_width_px(), warp_height_px()).image;
}

std::optional<int> vision_spray_level(const BoundaryControllerConfig& config, const NozzleDensity& nozzle, double speed_m_s) {
    if (!nozzle.measured) return std::nullopt;
    return spray_level(config, eq14_theoretical_duty_pct(config, nozzle.density, speed_m_s));
}

}  // namespace rig::controller::boundary::vision
