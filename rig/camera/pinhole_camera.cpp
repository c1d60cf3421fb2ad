#include "rig/camera/pinhole_camera.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "rig/camera/parameter_check.h"

namespace rig::camera {

namespace {

double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

}  // namespace

void validate(const CameraModel& model, const std::string& where) {
    const CameraIntrinsics& k = model.intrinsics;
    require_parameter(k.width_px >= 16 && k.width_px <= 8192, where, "intrinsics.width_px", k.width_px, "[16, 8192]");
    require_parameter(k.height_px >= 16 && k.height_px <= 8192, where, "intrinsics.height_px", k.height_px, "[16, 8192]");
    require_parameter(finite_within(k.fx_px, 1e-9, 1e5), where, "intrinsics.fx_px", k.fx_px, "(0, 100000]");
    require_parameter(finite_within(k.fy_px, 1e-9, 1e5), where, "intrinsics.fy_px", k.fy_px, "(0, 100000]");
    require_parameter(finite_within(k.cx_px, 0.0, k.width_px), where, "intrinsics.cx_px", k.cx_px, "[0, width_px]");
    require_parameter(finite_within(k.cy_px, 0.0, k.height_px), where, "intrinsics.cy_px", k.cy_px, "[0, height_px]");
    const BrownConradyDistortion& d = model.distortion;
    require_parameter(finite_within(d.k1, -1.0, 1.0), where, "distortion.k1", d.k1, "[-1, 1]");
    require_parameter(finite_within(d.k2, -1.0, 1.0), where, "distortion.k2", d.k2, "[-1, 1]");
    require_parameter(finite_within(d.k3, -1.0, 1.0), where, "distortion.k3", d.k3, "[-1, 1]");
    require_parameter(finite_within(d.p1, -1.0, 1.0), where, "distortion.p1", d.p1, "[-1, 1]");
    require_parameter(finite_within(d.p2, -1.0, 1.0), where, "distortion.p2", d.p2, "[-1, 1]");
    const CameraMounting& m = model.mounting;
    require_parameter(finite_within(m.right_m, -10.0, 10.0), where, "mounting.right_m", m.right_m, "[-10, 10] m");
    require_parameter(finite_within(m.forward_m, -2.0, 2.0), where, "mounting.forward_m", m.forward_m, "[-2, 2] m");
    require_parameter(finite_within(m.above_boom_m, 1e-9, 5.0), where, "mounting.above_boom_m", m.above_boom_m, "(0, 5] m");
    require_parameter(finite_within(m.pitch_deg, 0.0, 85.0), where, "mounting.pitch_deg", m.pitch_deg, "[0, 85] deg");
    require_parameter(finite_within(m.roll_deg, -45.0, 45.0), where, "mounting.roll_deg", m.roll_deg, "[-45, 45] deg");
    require_parameter(finite_within(m.yaw_deg, -45.0, 45.0), where, "mounting.yaw_deg", m.yaw_deg, "[-45, 45] deg");
}

CameraModel seed001_boom_camera(bool right_camera) {
    CameraModel model;
    model.mounting.right_m = right_camera ? 0.65 : -0.65;
    return model;
}

std::optional<std::string> frame_size_problem(const RgbImage& frame, const CameraIntrinsics& intrinsics) {
    if (frame.width == intrinsics.width_px && frame.height == intrinsics.height_px &&
        frame.bytes.size() == static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height) * 3U) {
        return std::nullopt;
    }
    return "frame " + std::to_string(frame.width) + " x " + std::to_string(frame.height) + " (" + std::to_string(frame.bytes.size()) +
           " bytes) is not the calibrated " + std::to_string(intrinsics.width_px) + " x " + std::to_string(intrinsics.height_px);
}

Eigen::Vector2d distort_normalized(const BrownConradyDistortion& d, const Eigen::Vector2d& p) {
    const double x = p.x();
    const double y = p.y();
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
    return {x * radial + 2.0 * d.p1 * x * y + d.p2 * (r2 + 2.0 * x * x),
            y * radial + d.p1 * (r2 + 2.0 * y * y) + 2.0 * d.p2 * x * y};
}

std::optional<Eigen::Vector2d> undistort_normalized(const BrownConradyDistortion& d, const Eigen::Vector2d& distorted) {
    Eigen::Vector2d p = distorted;  // the distortion is mild: the distorted point is a close first guess
    for (int step = 0; step < 50; ++step) {
        const Eigen::Vector2d residual = distort_normalized(d, p) - distorted;
        if (residual.norm() < 1e-12) return p;
        const double x = p.x();
        const double y = p.y();
        const double r2 = x * x + y * y;
        const double radial = 1.0 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
        const double dradial_dr2 = d.k1 + r2 * (2.0 * d.k2 + 3.0 * r2 * d.k3);
        Eigen::Matrix2d jacobian;
        jacobian(0, 0) = radial + 2.0 * x * x * dradial_dr2 + 2.0 * d.p1 * y + 6.0 * d.p2 * x;
        jacobian(0, 1) = 2.0 * x * y * dradial_dr2 + 2.0 * d.p1 * x + 2.0 * d.p2 * y;
        jacobian(1, 0) = 2.0 * x * y * dradial_dr2 + 2.0 * d.p1 * x + 2.0 * d.p2 * y;
        jacobian(1, 1) = radial + 2.0 * y * y * dradial_dr2 + 6.0 * d.p1 * y + 2.0 * d.p2 * x;
        if (std::abs(jacobian.determinant()) < 1e-12) return std::nullopt;  // the lens model folds over here
        p -= jacobian.inverse() * residual;
        if (!p.allFinite()) return std::nullopt;
    }
    return std::nullopt;
}

Eigen::Matrix3d camera_axes_in_boom(const CameraMounting& mounting) {
    const double pitch = radians(mounting.pitch_deg);
    Eigen::Matrix3d looking_down;
    looking_down.col(0) = Eigen::Vector3d(1.0, 0.0, 0.0);
    looking_down.col(1) = Eigen::Vector3d(0.0, -std::cos(pitch), -std::sin(pitch));
    looking_down.col(2) = Eigen::Vector3d(0.0, std::sin(pitch), -std::cos(pitch));
    const Eigen::Matrix3d roll = Eigen::AngleAxisd(radians(mounting.roll_deg), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    // A positive yaw turns the view clockwise seen from above (to the right).
    const Eigen::Matrix3d yaw = Eigen::AngleAxisd(-radians(mounting.yaw_deg), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    return yaw * looking_down * roll;
}

PinholeCamera::PinholeCamera(CameraModel model, const std::string& where) : model_(std::move(model)) {
    validate(model_, where);
    axes_ = camera_axes_in_boom(model_.mounting);
    position_ = Eigen::Vector3d(model_.mounting.right_m, model_.mounting.forward_m, model_.mounting.above_boom_m);
}

Eigen::Vector2d PinholeCamera::undistorted_pixel(const Eigen::Vector2d& normalized) const {
    const CameraIntrinsics& k = model_.intrinsics;
    return {k.fx_px * normalized.x() + k.cx_px, k.fy_px * normalized.y() + k.cy_px};
}

Eigen::Vector2d PinholeCamera::normalized_to_pixel(const Eigen::Vector2d& normalized) const {
    return undistorted_pixel(distort_normalized(model_.distortion, normalized));
}

Eigen::Vector2d PinholeCamera::pixel_to_distorted_normalized(const Eigen::Vector2d& pixel) const {
    const CameraIntrinsics& k = model_.intrinsics;
    return {(pixel.x() - k.cx_px) / k.fx_px, (pixel.y() - k.cy_px) / k.fy_px};
}

std::optional<Eigen::Vector2d> PinholeCamera::project(const Eigen::Vector3d& boom_point) const {
    const Eigen::Vector3d in_camera = axes_.transpose() * (boom_point - position_);
    if (in_camera.z() <= 1e-9) return std::nullopt;
    return normalized_to_pixel(Eigen::Vector2d(in_camera.x() / in_camera.z(), in_camera.y() / in_camera.z()));
}

std::optional<Eigen::Vector3d> PinholeCamera::ray(const Eigen::Vector2d& pixel) const {
    const std::optional<Eigen::Vector2d> normalized = undistort_normalized(model_.distortion, pixel_to_distorted_normalized(pixel));
    if (!normalized) return std::nullopt;
    return axes_ * Eigen::Vector3d(normalized->x(), normalized->y(), 1.0);
}

std::optional<Eigen::Vector2d> PinholeCamera::pixel_to_plane(const Eigen::Vector2d& pixel, double plane_z) const {
    const std::optional<Eigen::Vector3d> direction = ray(pixel);
    if (!direction || std::abs(direction->z()) < 1e-12) return std::nullopt;
    const double scale = (plane_z - position_.z()) / direction->z();
    if (scale <= 0.0) return std::nullopt;
    const Eigen::Vector3d hit = position_ + scale * *direction;
    return Eigen::Vector2d(hit.x(), hit.y());
}

Eigen::Matrix3d PinholeCamera::plane_to_undistorted_pixel(double plane_z) const {
    const CameraIntrinsics& k = model_.intrinsics;
    Eigen::Matrix3d intrinsic_matrix;
    intrinsic_matrix << k.fx_px, 0.0, k.cx_px, 0.0, k.fy_px, k.cy_px, 0.0, 0.0, 1.0;
    Eigen::Matrix3d plane_to_camera;
    plane_to_camera.col(0) = axes_.transpose() * Eigen::Vector3d::UnitX();
    plane_to_camera.col(1) = axes_.transpose() * Eigen::Vector3d::UnitY();
    plane_to_camera.col(2) = axes_.transpose() * (Eigen::Vector3d(0.0, 0.0, plane_z) - position_);
    return intrinsic_matrix * plane_to_camera;
}

}  // namespace rig::camera
