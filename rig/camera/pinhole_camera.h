#pragma once
// A camera on the sprayer's boom: pinhole intrinsics, Brown-Conrady lens
// distortion and its mounting on the boom. The same math serves the camera
// emulators (with the plant's true values) and the seed-001 controller (with
// its calibration, the values it believes), so a case can give the two
// different numbers and the rig sees what the difference costs.
//
// Frames (seed 001 Sec. 1.1, Fig. 5):
//   boom frame   x right, y forward (travel), z up; origin at the boom centre
//                in the boom plane (the plane of the nozzles, `h` above the
//                ground as the L4 laser measures it). The ground is z = -h.
//   camera frame x right in the image (u), y down in the image (v), z along
//                the optical axis.
// A camera with pitch 0 looks straight down with the top of its image
// forward; pitch p tilts the optical axis forward by p (Sec. 1.1: "about
// 25 deg"; S7 reads it as from the vertical: at 25 deg below the horizon the
// boom, 1 m under the camera, would be 65 deg off the axis, far outside any
// frame that also shows the ground ahead).
//
// Brown-Conrady on normalised coordinates (x, y) = (X / Z, Y / Z), r^2 = x^2 + y^2:
//   x_d = x (1 + k1 r^2 + k2 r^4 + k3 r^6) + 2 p1 x y + p2 (r^2 + 2 x^2)
//   y_d = y (1 + k1 r^2 + k2 r^4 + k3 r^6) + p1 (r^2 + 2 y^2) + 2 p2 x y
//   u = fx x_d + cx,  v = fy y_d + cy
#include <optional>
#include <string>

#include <Eigen/Dense>

#include "rig/camera/rgb_image.h"

namespace rig::camera {

struct CameraIntrinsics {
    // Resolution: the paper gives none; 1280 x 720 is assumed (S7: the pixel
    // coordinates of Eq. 1-4, up to 1044 across and 662 down, fit it).
    int width_px = 1280;                 // [16, 8192]
    int height_px = 720;                 // [16, 8192]
    // Focal lengths: assumed 900 px (71 deg across). With the Sec. 1.1
    // mounting below it puts the three nozzles a camera sees about 470 px apart
    // at row 640-660, as Eq. 1-4's intersections are (107, 580, 1044 px at
    // rows 660-662).
    double fx_px = 900.0;                // (0, 100000]
    double fy_px = 900.0;                // (0, 100000]
    double cx_px = 640.0;                // [0, width_px]; assumed: the image centre
    double cy_px = 360.0;                // [0, height_px]
};

struct BrownConradyDistortion {
    // Assumed: mild barrel distortion, -1.4 % at the image corner (r = 0.82),
    // within Table 1's "distortion < 2 %" for the SY002HD. Each in [-1, 1].
    double k1 = -0.025;
    double k2 = 0.005;
    double k3 = 0.0;
    double p1 = 0.0005;
    double p2 = -0.0003;
};

struct CameraMounting {
    // Across the boom, from its centre: Sec. 1.1 puts the two cameras about
    // 1.30 m apart, so +-0.65 m (each sees 3 of the 6 nozzles). [-10, 10] m.
    double right_m = 0.65;
    // Along travel, from the boom line (negative: behind it). Assumed -0.11 m:
    // with fx = fy = 900 px it reproduces Eq. 1-4's nozzle row (about 660)
    // and spacing (about 470 px); the paper gives no number. [-2, 2] m.
    double forward_m = -0.11;
    // Above the boom plane: Sec. 1.1 H2 "about 100 cm" over the boom bottom. (0, 5] m.
    double above_boom_m = 1.00;
    // Optical axis forward of straight down (Sec. 1.1: about 25 deg). [0, 85] deg.
    double pitch_deg = 25.0;
    // About the optical axis, positive turning the image clockwise as seen
    // through the camera; and about the vertical, positive turning the view to
    // the right. Assumed 0 (the paper mounts the cameras square). [-45, 45] deg.
    double roll_deg = 0.0;
    double yaw_deg = 0.0;
};

struct CameraModel {
    CameraIntrinsics intrinsics;
    BrownConradyDistortion distortion;
    CameraMounting mounting;
};

// Sec. 1.1's two cameras, left (right_m = -0.65) or right (+0.65), every
// other value at its default: the plant's truth and the controller's belief
// both start from these.
CameraModel seed001_boom_camera(bool right_camera);

// Throws std::invalid_argument "<where>.<field>: <what>" for the first value
// out of the bounds given beside each field.
void validate(const CameraModel& model, const std::string& where);

// Why a frame cannot be this camera's (its size or byte count differ from the
// intrinsics' resolution), naming both; nullopt when it can.
std::optional<std::string> frame_size_problem(const RgbImage& frame, const CameraIntrinsics& intrinsics);

// Brown-Conrady forward (above).
Eigen::Vector2d distort_normalized(const BrownConradyDistortion& distortion, const Eigen::Vector2d& undistorted);
// Its inverse by Newton's method on the 2x2 Jacobian; nullopt where it does not
// converge to 1e-12 in 50 steps (far outside the lens's valid field).
std::optional<Eigen::Vector2d> undistort_normalized(const BrownConradyDistortion& distortion, const Eigen::Vector2d& distorted);

// Columns: the camera's x, y and z axes in the boom frame.
Eigen::Matrix3d camera_axes_in_boom(const CameraMounting& mounting);

class PinholeCamera {
public:
    // Throws std::invalid_argument as validate(model, where) does.
    explicit PinholeCamera(CameraModel model, const std::string& where = "camera");

    const CameraModel& model() const { return model_; }
    int width_px() const { return model_.intrinsics.width_px; }
    int height_px() const { return model_.intrinsics.height_px; }
    const Eigen::Vector3d& position_in_boom() const { return position_; }
    const Eigen::Matrix3d& axes_in_boom() const { return axes_; }

    // Normalised (undistorted) coordinates <-> pixels, without / with distortion.
    Eigen::Vector2d normalized_to_pixel(const Eigen::Vector2d& normalized) const;
    Eigen::Vector2d pixel_to_distorted_normalized(const Eigen::Vector2d& pixel) const;
    Eigen::Vector2d undistorted_pixel(const Eigen::Vector2d& normalized) const;

    // The pixel (with distortion) that sees a boom-frame point; nullopt for a
    // point at or behind the camera's image plane.
    std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& boom_point) const;
    // The direction (boom frame, not unit: camera z component 1) seen by a
    // pixel; nullopt where the distortion cannot be inverted.
    std::optional<Eigen::Vector3d> ray(const Eigen::Vector2d& pixel) const;
    // Where a pixel's ray meets the horizontal plane z = plane_z (boom frame):
    // x, y of that point; nullopt when the ray is parallel to it or points away.
    std::optional<Eigen::Vector2d> pixel_to_plane(const Eigen::Vector2d& pixel, double plane_z) const;
    // The homography from the horizontal plane z = plane_z (its x, y, 1) to
    // undistorted pixels: K [r1 r2 t] with the camera's pose relative to that
    // plane (seed 001 Eq. 5 is its inverse for the boom plane, z = 0).
    Eigen::Matrix3d plane_to_undistorted_pixel(double plane_z) const;

private:
    CameraModel model_;
    Eigen::Matrix3d axes_;
    Eigen::Vector3d position_;
};

}  // namespace rig::camera
