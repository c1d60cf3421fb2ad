// Seed 001 Sec. 2.2.2 on the rig: the camera emulator renders a chessboard in
// the boom plane (or on the ground), the controller finds its corners
// (OpenCV's findChessboardCorners and cornerSubPix), fits the plane's
// homography (Eq. 5) and recovers the camera's pose on the boom, so a camera
// knocked off its pitch can be recalibrated. Checked against the emulator's
// true camera.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "controller/boundary/vision/chessboard_calibration.h"
#include "controller/boundary/vision/nozzle_calibration.h"
#include "controller/boundary/vision/nozzle_vision.h"
#include "emulators/field2d/crop_cover_map.h"
#include "emulators/vision/camera_emulator.h"

namespace {

using namespace rig::controller::boundary::vision;
using rig::camera::CameraModel;
using rig::camera::CameraMounting;
using rig::camera::PinholeCamera;
using rig::controller::boundary::BoundaryControllerConfig;
using rig::emulators::vision::BoomPose;
using rig::emulators::vision::CameraEmulator;
using rig::emulators::vision::CameraEmulatorParams;
using rig::emulators::vision::Chessboard;
using rig::field2d::CoverClass;
using rig::field2d::CropCoverMap;
using rig::field2d::CropCoverParams;

Eigen::Vector2d apply(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) {
    const Eigen::Vector3d q = h * Eigen::Vector3d(p.x(), p.y(), 1.0);
    return {q.x() / q.z(), q.y() / q.z()};
}

CropCoverMap bare_field() {
    CropCoverParams params;
    params.default_cover = CoverClass::bare;
    return CropCoverMap(params, 1);
}

// The boards the tests lay out for the left camera (x = -0.65 m): 7 x 5 inner
// corners, 40 mm squares in the boom plane just ahead of the boom; 60 mm
// squares on the ground where the ROIs are.
Chessboard boom_plane_board() {
    Chessboard board;
    board.origin_right_m = -0.65 - 3 * 0.040;
    board.origin_ahead_m = 0.10;
    return board;
}
Chessboard ground_board() {
    Chessboard board;
    board.square_m = 0.060;
    board.origin_right_m = -0.65 - 3 * 0.060;
    board.origin_ahead_m = 0.25;
    board.on_ground = true;
    return board;
}
ChessboardPlacement placement_of(const Chessboard& board, double boom_height_m) {
    return {board.inner_cols, board.inner_rows, board.square_m, board.origin_right_m, board.origin_ahead_m,
            board.on_ground ? -boom_height_m : 0.0};
}

TEST(FitHomography, RecoversAnExactMapAndRefusesDegeneratePoints) {
    const PinholeCamera camera(rig::camera::seed001_boom_camera(true));
    const Eigen::Matrix3d truth = camera.plane_to_undistorted_pixel(0.0);
    std::vector<Eigen::Vector2d> plane;
    std::vector<Eigen::Vector2d> image;
    for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 5; ++i) {
            plane.emplace_back(0.4 + 0.05 * i, 0.1 + 0.05 * j);
            image.push_back(apply(truth, plane.back()));
        }
    }
    const Eigen::Matrix3d fitted = fit_homography(plane, image);
    // OpenCV fits in single precision (findHomography converts the points to
    // float: ~1e-7 relative, 1e-4 px at 1000 px), and these points lie well
    // outside the fitted patch; a calibration's corners carry ~0.1 px of noise.
    for (const Eigen::Vector2d& p : {Eigen::Vector2d(0.3, 0.0), Eigen::Vector2d(1.0, 0.4)}) {
        EXPECT_NEAR((apply(fitted, p) - apply(truth, p)).norm(), 0.0, 1e-3);
    }
    for (std::size_t n = 0; n < plane.size(); ++n) EXPECT_NEAR((apply(fitted, plane[n]) - image[n]).norm(), 0.0, 1e-4);
    const std::vector<Eigen::Vector2d> line{Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1), Eigen::Vector2d(2, 2), Eigen::Vector2d(3, 3),
                                            Eigen::Vector2d(4, 4)};
    EXPECT_THROW(fit_homography(line, line), std::invalid_argument);
    EXPECT_THROW(fit_homography(plane, std::vector<Eigen::Vector2d>(3)), std::invalid_argument);
}

TEST(MountingFromHomography, RoundTripsAPoseWithRollAndYaw) {
    CameraModel model = rig::camera::seed001_boom_camera(false);
    model.mounting = CameraMounting{-0.60, -0.08, 1.05, 27.0, 2.0, -3.0};
    const PinholeCamera camera(model);
    for (const double plane_z : {0.0, -0.5}) {
        const CameraMounting got = mounting_from_plane_homography(model.intrinsics, camera.plane_to_undistorted_pixel(plane_z), plane_z);
        EXPECT_NEAR(got.right_m, -0.60, 1e-9);
        EXPECT_NEAR(got.forward_m, -0.08, 1e-9);
        EXPECT_NEAR(got.above_boom_m, 1.05, 1e-9);
        EXPECT_NEAR(got.pitch_deg, 27.0, 1e-9);
        EXPECT_NEAR(got.roll_deg, 2.0, 1e-9);
        EXPECT_NEAR(got.yaw_deg, -3.0, 1e-9);
    }
}

TEST(ChessboardCalibration, RecalibratesACameraKnockedOffItsPitch) {
    // The camera is truly at 30 deg (knocked 5 deg up); the controller still
    // believes 25. From one frame of the boom-plane board (and one of the
    // ground board, with the laser's h) it recovers the pose; with it and the
    // nozzle boards the ROIs land where Sec. 2.1 puts them again.
    const CropCoverMap crop = bare_field();
    const BoomPose pose{{0.0, 0.0}, 0.0, 0.5};
    CameraEmulatorParams truly = rig::emulators::vision::seed001_camera_params(false);
    truly.faults.pitch_offset_deg = 5.0;
    // 4 x 4 samples a pixel: a real sensor integrates its whole pixel, and at
    // 2 x 2 the board's edges fall on quarter pixels (0.2 px RMS at the corners).
    truly.samples_per_axis = 4;
    const CameraEmulator camera(truly, 5, 0, "left");
    VisionCameraConfig config = seed001_vision_cameras(BoundaryControllerConfig{})[0];
    const PinholeCamera believed(config.model);

    std::vector<Eigen::Vector3d> boom_points;  // both boards' corners, for the joint pose
    std::vector<Eigen::Vector2d> corner_pixels;
    for (const Chessboard& board : {boom_plane_board(), ground_board()}) {
        const auto frame = camera.render_chessboard(crop, pose, board, 0);
        ASSERT_TRUE(frame.has_value());
        const ChessboardPlacement placement = placement_of(board, 0.5);
        const ChessboardView view = find_chessboard(*frame, believed, placement);
        ASSERT_TRUE(view.ok) << view.problem;
        EXPECT_EQ(view.corners_px.size(), 35U);
        EXPECT_LT(view.rms_px, 0.3);
        for (int j = 0; j < placement.inner_rows; ++j) {
            for (int i = 0; i < placement.inner_cols; ++i) {
                boom_points.emplace_back(placement.origin_right_m + i * placement.square_m, placement.origin_ahead_m + j * placement.square_m,
                                         placement.plane_z_m);
                corner_pixels.push_back(view.corners_px[static_cast<std::size_t>(j * placement.inner_cols + i)]);
            }
        }
        const CameraMounting got = mounting_from_plane_homography(config.model.intrinsics, view.plane_to_pixel, placement_of(board, 0.5).plane_z_m);
        // Measured: pitch within 0.30 deg, position within 5.4 mm, roll and yaw within 0.26 deg.
        EXPECT_NEAR(got.pitch_deg, 30.0, 0.6) << (board.on_ground ? "ground" : "boom plane");
        EXPECT_NEAR(got.right_m, -0.65, 0.01);
        EXPECT_NEAR(got.forward_m, -0.11, 0.015);
        EXPECT_NEAR(got.above_boom_m, 1.00, 0.01);
        EXPECT_NEAR(got.roll_deg, 0.0, 0.6);
        EXPECT_NEAR(got.yaw_deg, 0.0, 0.6);
    }

    // Both boards at once, as the paper uses them: better conditioned.
    const CameraMounting joint = mounting_from_points(config.model.intrinsics, boom_points, corner_pixels);
    EXPECT_NEAR(joint.pitch_deg, 30.0, 0.2);
    EXPECT_NEAR(joint.forward_m, -0.11, 0.005);
    EXPECT_NEAR(joint.above_boom_m, 1.00, 0.005);

    // The knocked camera no longer sees the whole boom board (it runs off the
    // frame's bottom edge), so the nozzle boards cannot place the nozzles:
    // refused, not a line through half a board.
    rig::emulators::vision::CalibrationBoards boards;
    boards.boom_board_right_m = config.model.mounting.right_m;
    boards.nozzle_right_m = config.nozzle_right_m;
    const auto board_frame = camera.render_calibration(crop, pose, boards, 0);
    const NozzleCalibration nozzles = find_nozzle_points(*board_frame, PinholeCamera(config.model), 3);
    EXPECT_FALSE(nozzles.ok);
    EXPECT_NE(nozzles.problem.find("runs off the frame"), std::string::npos) << nozzles.problem;

    // The recalibrated model with the nozzles at their design places: the ROIs.
    VisionCameraConfig recalibrated = config;
    recalibrated.model.mounting = joint;

    auto worst_corner_error = [&](const VisionCameraConfig& vision_config) {
        double worst = 0.0;
        for (const NozzleRoi& roi : CameraVision(vision_config, VisionParams{}).rois(0.5)) {
            const auto intended = rig::field2d::nozzle_roi_ground(pose.boom_centre_ground, pose.heading_deg, (roi.nozzle - 2.5) * 0.5);
            for (std::size_t c = 0; c < 4; ++c) {
                const auto seen = camera.ground_seen(pose, roi.image_px[c].x(), roi.image_px[c].y());
                if (!seen) return 1e9;
                worst = std::max(worst, std::hypot(seen->east_m - intended[c].east_m, seen->north_m - intended[c].north_m));
            }
        }
        return worst;
    };
    // Measured: 0.17 m with the old belief, 2.2 mm recalibrated.
    EXPECT_GT(worst_corner_error(config), 0.10);
    EXPECT_LT(worst_corner_error(recalibrated), 0.010);
}

TEST(MountingFromPoints, RoundTripsAPoseFromTwoPlanes) {
    CameraModel model = rig::camera::seed001_boom_camera(true);
    model.mounting = CameraMounting{0.70, -0.12, 0.95, 31.0, -1.5, 2.5};
    const PinholeCamera camera(model);
    std::vector<Eigen::Vector3d> points;
    std::vector<Eigen::Vector2d> pixels;
    for (const double z : {0.0, -0.5}) {
        for (int j = 0; j < 3; ++j) {
            for (int i = 0; i < 4; ++i) {
                points.emplace_back(0.5 + 0.1 * i, 0.1 + 0.15 * j - z, z);
                const Eigen::Vector3d in_camera = camera.axes_in_boom().transpose() * (points.back() - camera.position_in_boom());
                pixels.push_back(camera.undistorted_pixel(Eigen::Vector2d(in_camera.x() / in_camera.z(), in_camera.y() / in_camera.z())));
            }
        }
    }
    const CameraMounting got = mounting_from_points(model.intrinsics, points, pixels);
    EXPECT_NEAR(got.right_m, 0.70, 1e-9);
    EXPECT_NEAR(got.forward_m, -0.12, 1e-9);
    EXPECT_NEAR(got.above_boom_m, 0.95, 1e-9);
    EXPECT_NEAR(got.pitch_deg, 31.0, 1e-9);
    EXPECT_NEAR(got.roll_deg, -1.5, 1e-9);
    EXPECT_NEAR(got.yaw_deg, 2.5, 1e-9);
    // One plane alone does not fix a 3-D pose by this route.
    points.resize(12);
    pixels.resize(12);
    EXPECT_THROW(mounting_from_points(model.intrinsics, points, pixels), std::invalid_argument);
}

TEST(ChessboardCalibration, SaysWhatIsMissing) {
    const CropCoverMap crop = bare_field();
    const BoomPose pose{{0.0, 0.0}, 0.0, 0.5};
    const CameraEmulator camera(rig::emulators::vision::seed001_camera_params(false), 5, 0, "left");
    const PinholeCamera believed(rig::camera::seed001_boom_camera(false));
    // A working frame of bare soil: no corners.
    const ChessboardView none = find_chessboard(*camera.render(crop, pose, 0), believed, placement_of(boom_plane_board(), 0.5));
    EXPECT_FALSE(none.ok);
    EXPECT_NE(none.problem.find("no chessboard of 7 x 5 inner corners"), std::string::npos) << none.problem;
    // A board with fewer corners than declared.
    Chessboard small = boom_plane_board();
    small.inner_cols = 4;
    const ChessboardView short_board = find_chessboard(*camera.render_chessboard(crop, pose, small, 0), believed, placement_of(boom_plane_board(), 0.5));
    EXPECT_FALSE(short_board.ok);
    EXPECT_NE(short_board.problem.find("7 x 5 inner corners (35)"), std::string::npos) << short_board.problem;
    // The declared board, but half of it beyond the frame's right edge (this
    // camera sees the boom plane to about x = +0.1 m).
    Chessboard away = boom_plane_board();
    away.origin_right_m = 0.0;
    const ChessboardView out_of_view = find_chessboard(*camera.render_chessboard(crop, pose, away, 0), believed, placement_of(away, 0.5));
    EXPECT_FALSE(out_of_view.ok);
    EXPECT_NE(out_of_view.problem.find("no chessboard of 7 x 5"), std::string::npos) << out_of_view.problem;
    // A frame of another size.
    const ChessboardView wrong = find_chessboard(rig::camera::RgbImage(64, 48), believed, placement_of(boom_plane_board(), 0.5));
    EXPECT_FALSE(wrong.ok);
    EXPECT_NE(wrong.problem.find("64 x 48"), std::string::npos) << wrong.problem;
}

}  // namespace
