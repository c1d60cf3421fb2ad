#pragma once
// Seed 001's vision half as the controller computes it (Sec. 2, 4.1): from a
// camera's frame, each nozzle's plant cover D and its spray level. The
// controller sees pixels only: what it knows of the camera is its calibration
// (a rig::camera::CameraModel: intrinsics, distortion, mounting as it
// believes them) and the nozzle points found in the calibration image.
//
//   Eq. 5    boom-plane point = H^-1 (u, v, 1): the homography of the boom
//            plane (z = 0 of the boom frame), here from the calibrated model
//            (the paper estimates it from a chessboard on that plane)
//   Eq. 6    ground point = the boom-plane point dropped by the laser height
//            h: the paper chains the boom-plane and ground chessboards'
//            extrinsics; with both planes level (the model's assumption) the
//            chain is (X, Y, 0) -> (X, Y, -h)
//   Eq. 7-8  ROI corners: turn the nozzle's ground point into the frame of the
//            projected boom line (angle alpha through the outer nozzles),
//            offset by -+ w/2 across and h1, h1 + h2 ahead, turn back. (Eq. 8
//            as printed repeats a corner, (X' + w/2, Y' + h1 + h2), where
//            (X' + w/2, Y' + h1) is meant; its rotation signs belong to the
//            paper's axes, here x right, y forward.)
//   warp     the ROI's image quadrilateral to a w x h2 rectangle (a
//            perspective transform with the lens undone in the same
//            resampling: OpenCV's undistortion map and fixed-point remap,
//            image_ops.h)
//   Eq. 15   ExG = 2G - R - B, clipped 0..255
//   Eq. 16   plant where ExG >= T, T = max(Otsu over the whole frame (OpenCV), floor)
//            (S7: Otsu alone splits bare soil's noise into "plants")
//   Eq. 17   D = plant pixels / ROI pixels
//   Eq. 14   the level of D at the current speed
//            (controller/boundary/boundary_equations.h)
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "controller/boundary/boundary_config.h"
#include "controller/boundary/vision/vision_params.h"
#include "rig/camera/pinhole_camera.h"
#include "rig/camera/rgb_image.h"

namespace rig::controller::boundary::vision {

struct PixelPoint {
    double u_px = 0.0;
    double v_px = 0.0;
};

struct VisionCameraConfig {
    std::string name = "camera";             // non-empty, for messages
    rig::camera::CameraModel model;          // the calibration: what the controller believes
    std::vector<int> nozzles;                // the nozzles this camera sees, left to right; >= 1
    // The nozzles' design positions across the boom (m right of its centre),
    // one per nozzle: where nozzle_pixels come from when none are given.
    std::vector<double> nozzle_right_m;
    // Eq. 1-4's nozzle intersections in the undistorted calibration image, one
    // per nozzle; empty: the model's projection of (nozzle_right_m, 0, 0).
    std::vector<PixelPoint> nozzle_pixels;
};


// Throws std::invalid_argument "vision.cameras[i] '<name>'.<field>: ...".
void validate(const VisionCameraConfig& camera, std::size_t index);

// Sec. 1.1's two cameras (left sees the first half of the nozzles, right the
// rest), at rig::camera::seed001_boom_camera's calibration, the nozzles where
// `boundary` puts them (count, spacing; left to right), no calibration points.
std::vector<VisionCameraConfig> seed001_vision_cameras(const BoundaryControllerConfig& boundary);

struct NozzleRoi {
    int nozzle = 0;
    Eigen::Vector2d nozzle_pixel;             // Eq. 1-4 (undistorted image)
    Eigen::Vector2d nozzle_boom_plane;        // Eq. 5 (boom frame x right, y forward, m)
    Eigen::Vector2d nozzle_ground;            // Eq. 6 (the same axes on the ground)
    // Eq. 7-8, on the ground (boom frame x, y), in the image without and
    // with distortion; corners near-left, near-right, far-right, far-left.
    std::array<Eigen::Vector2d, 4> ground;
    std::array<Eigen::Vector2d, 4> undistorted_px;
    std::array<Eigen::Vector2d, 4> image_px;
};

enum class FrameStatus {
    ok,
    no_frame,      // the camera delivered nothing
    dark_frame,    // a black (dead or covered) frame
    wrong_size,    // not the calibrated resolution
};
const char* frame_status_name(FrameStatus status);

struct NozzleDensity {
    int nozzle = 0;
    bool measured = false;       // false: no density (see FrameDensities::status, or the ROI left the frame)
    double density = 0.0;        // Eq. 17, 0..1, when measured
    long plant_px = 0;           // c_o
    long roi_px = 0;             // A_r (the ROI's warped pixels inside the frame)
    long roi_px_outside = 0;     // warped pixels that fell outside the frame
    NozzleRoi roi;
};

struct FrameDensities {
    FrameStatus status = FrameStatus::no_frame;
    std::string detail;                  // why, when status != ok
    std::optional<int> otsu_threshold;   // Eq. 16's T from the frame's histogram
    int threshold = 0;                   // the one used: max(Otsu, exg_floor)
    std::vector<NozzleDensity> nozzles;  // one per nozzle of the camera, when status == ok
};

class CameraVision {
public:
    // Throws std::invalid_argument for bad parameters, a calibration the model
    // rejects, or nozzle points that do not map onto the boom plane.
    CameraVision(VisionCameraConfig camera, VisionParams params, std::size_t index = 0);

    // Eq. 5-8 at boom height h (the L4's reading, m). Throws
    // std::invalid_argument for h outside (0, 5] m.
    std::vector<NozzleRoi> rois(double boom_height_m) const;
    // Eq. 15-17 on a frame (nullptr: the camera delivered none). What the
    // frame holds never throws (a missing, dark or wrong-sized frame is a
    // status); a boom height outside (0, 5] m throws std::invalid_argument.
    FrameDensities measure(const rig::camera::RgbImage* frame, double boom_height_m) const;
    // A ROI warped to its rectangle (w x h2 at warp_mm_per_px; far edge at the
    // top), pixels outside the frame black: for reports and tests.
    rig::camera::RgbImage warp_roi(const rig::camera::RgbImage& frame, const NozzleRoi& roi) const;

    const VisionCameraConfig& camera() const { return camera_; }
    const rig::camera::PinholeCamera& model() const { return model_; }
    const VisionParams& params() const { return params_; }

private:
    int warp_width_px() const;
    int warp_height_px() const;
    VisionCameraConfig camera_;
    VisionParams params_;
    rig::camera::PinholeCamera model_;
    std::vector<Eigen::Vector2d> nozzle_boom_plane_;  // Eq. 5 of each nozzle point, fixed with the boom
};

// Eq. 14's level (0, 1, 2) of a measured density at `speed_m_s`; nullopt when
// the nozzle has no density (the caller decides what a blind nozzle does).
std::optional<int> vision_spray_level(const BoundaryControllerConfig& config, const NozzleDensity& nozzle, double speed_m_s);

}  // namespace rig::controller::boundary::vision
