// rig::camera (rig/camera/pinhole_camera.h): Brown-Conrady both ways, the
// projection of known points worked out by hand, the plane homography (seed
// 001 Eq. 5's matrix) against the projection, and the parameter checks.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "rig/camera/pinhole_camera.h"

namespace {

using rig::camera::BrownConradyDistortion;
using rig::camera::CameraModel;
using rig::camera::PinholeCamera;

CameraModel without_distortion(CameraModel model) {
    model.distortion = BrownConradyDistortion{0.0, 0.0, 0.0, 0.0, 0.0};
    return model;
}

TEST(BrownConrady, DistortThenUndistortRoundTripsOverTheFrame) {
    const CameraModel model = rig::camera::seed001_boom_camera(true);
    const PinholeCamera camera(model);
    double worst = 0.0;
    for (int v = 0; v <= 720; v += 40) {
        for (int u = 0; u <= 1280; u += 40) {
            const Eigen::Vector2d distorted = camera.pixel_to_distorted_normalized(Eigen::Vector2d(u, v));
            const auto undistorted = rig::camera::undistort_normalized(model.distortion, distorted);
            ASSERT_TRUE(undistorted.has_value()) << u << ", " << v;
            const Eigen::Vector2d back = rig::camera::distort_normalized(model.distortion, *undistorted);
            worst = std::max(worst, (back - distorted).norm());
        }
    }
    EXPECT_LT(worst * 900.0, 1e-9);  // in pixels
}

TEST(BrownConrady, DefaultLensStaysUnderTable1sTwoPercent) {
    // Table 1: the SY002HD's distortion is under 2 %. Radial distortion at the
    // image corner, r = sqrt(640^2 + 360^2) / 900 = 0.816: k1 r^2 + k2 r^4 =
    // -0.025 x 0.666 + 0.005 x 0.443 = -1.44 %.
    const CameraModel model = rig::camera::seed001_boom_camera(false);
    double worst = 0.0;
    for (int v = 0; v <= 720; v += 20) {
        for (int u = 0; u <= 1280; u += 20) {
            const Eigen::Vector2d p((u - 640.0) / 900.0, (v - 360.0) / 900.0);
            if (p.norm() < 0.05) continue;
            const Eigen::Vector2d d = rig::camera::distort_normalized(model.distortion, p);
            worst = std::max(worst, std::abs(d.norm() - p.norm()) / p.norm());
        }
    }
    EXPECT_LT(worst, 0.02);
    EXPECT_GT(worst, 0.010);  // and there is distortion to correct
    const Eigen::Vector2d corner(640.0 / 900.0, 360.0 / 900.0);
    EXPECT_NEAR(rig::camera::distort_normalized(BrownConradyDistortion{-0.025, 0.005, 0.0, 0.0, 0.0}, corner).norm() / corner.norm() - 1.0,
                -0.025 * corner.squaredNorm() + 0.005 * std::pow(corner.squaredNorm(), 2), 1e-12);
}

TEST(PinholeCamera, ProjectsKnownGroundPoints) {
    // Right camera, no distortion: 0.65 m right of the boom centre, 0.11 m
    // behind it, 1.00 m above the boom plane, pitched 25 deg; boom 0.5 m up, so
    // the camera is 1.5 m above the ground. Its optical axis meets the ground
    // 1.5 tan 25 = 0.69946 m ahead of the camera, y = 0.58946 m, at 1.5 / cos 25
    // = 1.65506 m: that point is the principal point (640, 360); 0.3 m to its
    // right is 900 x 0.3 / 1.65506 = 163.14 px to the right of it.
    const PinholeCamera camera(without_distortion(rig::camera::seed001_boom_camera(true)));
    const double y_axis = -0.11 + 1.5 * std::tan(25.0 * std::numbers::pi / 180.0);
    const auto centre = camera.project(Eigen::Vector3d(0.65, y_axis, -0.5));
    ASSERT_TRUE(centre.has_value());
    EXPECT_NEAR(centre->x(), 640.0, 1e-9);
    EXPECT_NEAR(centre->y(), 360.0, 1e-9);
    const auto right = camera.project(Eigen::Vector3d(0.95, y_axis, -0.5));
    ASSERT_TRUE(right.has_value());
    EXPECT_NEAR(right->x(), 640.0 + 900.0 * 0.3 / (1.5 / std::cos(25.0 * std::numbers::pi / 180.0)), 1e-9);
    EXPECT_NEAR(right->y(), 360.0, 1e-9);
    // The ground directly below the camera is 25 deg off the axis, behind it:
    // row 360 + 900 tan 25 = 779.7, below the 720-row frame.
    const auto below = camera.project(Eigen::Vector3d(0.65, -0.11, -0.5));
    ASSERT_TRUE(below.has_value());
    EXPECT_NEAR(below->y(), 360.0 + 900.0 * std::tan(25.0 * std::numbers::pi / 180.0), 1e-9);
    // Behind the image plane: nothing.
    EXPECT_FALSE(camera.project(Eigen::Vector3d(0.65, -3.0, 2.0)).has_value());
}

TEST(PinholeCamera, PixelToGroundInvertsProjectionWithDistortion) {
    const PinholeCamera camera(rig::camera::seed001_boom_camera(false));
    for (const double h : {0.4, 0.5, 0.6}) {
        for (const Eigen::Vector2d& ground : {Eigen::Vector2d(-1.25, 0.2), Eigen::Vector2d(-0.25, 0.6), Eigen::Vector2d(-0.95, 0.4)}) {
            const auto pixel = camera.project(Eigen::Vector3d(ground.x(), ground.y(), -h));
            ASSERT_TRUE(pixel.has_value());
            const auto back = camera.pixel_to_plane(*pixel, -h);
            ASSERT_TRUE(back.has_value());
            EXPECT_NEAR((*back - ground).norm(), 0.0, 1e-9) << "h " << h;
        }
    }
}

TEST(PinholeCamera, PlaneHomographyAgreesWithTheProjection) {
    // Eq. 5's matrix for the boom plane (z = 0) and the ground (z = -h): with
    // no distortion the homography and the projection are the same map.
    const PinholeCamera camera(without_distortion(rig::camera::seed001_boom_camera(true)));
    for (const double plane_z : {0.0, -0.5}) {
        const Eigen::Matrix3d h = camera.plane_to_undistorted_pixel(plane_z);
        for (const Eigen::Vector2d& p : {Eigen::Vector2d(0.25, 0.0), Eigen::Vector2d(1.25, 0.0), Eigen::Vector2d(0.6, 0.5)}) {
            const Eigen::Vector3d image = h * Eigen::Vector3d(p.x(), p.y(), 1.0);
            const auto projected = camera.project(Eigen::Vector3d(p.x(), p.y(), plane_z));
            ASSERT_TRUE(projected.has_value());
            EXPECT_NEAR(image.x() / image.z(), projected->x(), 1e-9);
            EXPECT_NEAR(image.y() / image.z(), projected->y(), 1e-9);
        }
    }
}

TEST(PinholeCamera, BadParametersNameTheField) {
    CameraModel model;
    model.intrinsics.fx_px = -1.0;
    try {
        PinholeCamera camera(model, "cameras[1]");
        ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("cameras[1].intrinsics.fx_px"), std::string::npos) << error.what();
    }
    model = CameraModel{};
    model.mounting.pitch_deg = NAN;
    EXPECT_THROW(PinholeCamera{model}, std::invalid_argument);
    model = CameraModel{};
    model.distortion.k1 = 3.0;
    EXPECT_THROW(PinholeCamera{model}, std::invalid_argument);
}

}  // namespace
