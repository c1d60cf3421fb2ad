#pragma once
// Sec. 2.2.2's chessboards: the camera's pose on the boom from one image of a
// chessboard lying in a known place, in the boom plane (Eq. 5's homography)
// or on the ground under it (Eq. 6's second board, with the laser's h). The
// paper estimates both with a calibration library it does not name; here
// OpenCV (image_ops.h):
//   corners   cv::findChessboardCorners (the grid and its order), refined to
//             the grey-level saddle by cv::cornerSubPix, then undistorted
//             (cv::undistortPoints) with the camera's calibration
//   H         cv::findHomography over all corners (least squares, refined)
//   pose      K^-1 H = [r1 r2 t] up to scale; r3 = r1 x r2, made a rotation
//             by SVD; the camera's position and pitch / roll / yaw on the boom;
//             or, from both boards at once (the paper's two planes), the DLT
//             of [R | t] over all their corners
// With the pose estimated (and the intrinsics and distortion from the
// pre-test calibration, as in the paper), the controller's CameraModel is
// its calibration: a camera knocked off its pitch is recalibrated.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "controller/boundary/vision/image_ops.h"  // fit_homography
#include "rig/camera/pinhole_camera.h"
#include "rig/camera/rgb_image.h"

namespace rig::controller::boundary::vision {

// Where the board lies (the calibration procedure's declared placement): inner
// corner (i, j) at (origin_right_m + i square_m, origin_ahead_m + j square_m)
// in the boom frame, on the plane z = plane_z_m (0 the boom plane, -h the ground).
struct ChessboardPlacement {
    int inner_cols = 7;
    int inner_rows = 5;
    double square_m = 0.040;
    double origin_right_m = 0.0;
    double origin_ahead_m = 0.05;
    double plane_z_m = 0.0;
};

struct ChessboardView {
    bool ok = false;
    std::string problem;                      // why not, when !ok
    std::vector<Eigen::Vector2d> corners_px;  // undistorted, index j * inner_cols + i
    Eigen::Matrix3d plane_to_pixel = Eigen::Matrix3d::Identity();  // board-plane (x, y) m -> undistorted px
    double rms_px = 0.0;                      // corners against the fitted homography
};

// Finds the board's inner corners in a frame and fits the homography from
// the board's plane to the undistorted image. `model` supplies the intrinsics
// and distortion (its mounting is not used). Never throws for what the frame
// holds: no board, a partly hidden one or a corner count that does not match
// gives ok = false and says why. The board lies as declared: its rows of
// inner_cols corners run across the image (roll and yaw within
// CameraMounting's 45 deg); a square pattern may be seen either way round.
ChessboardView find_chessboard(const rig::camera::RgbImage& frame, const rig::camera::PinholeCamera& model,
                               const ChessboardPlacement& placement);

// The camera's mounting on the boom from the homography of the horizontal
// plane z = plane_z_m (boom frame) to undistorted pixels. Throws
// std::invalid_argument when H does not decompose into a camera in front of
// the plane or the pose is outside CameraMounting's bounds.
rig::camera::CameraMounting mounting_from_plane_homography(const rig::camera::CameraIntrinsics& intrinsics,
                                                           const Eigen::Matrix3d& plane_to_pixel, double plane_z_m);

// The mounting from points on two or more planes at once (the paper's two
// boards: the boom plane's and the ground's with the laser's h), by the
// direct linear transform of K^-1 x ~ [R | t] P, R made a rotation by SVD.
// Better conditioned than one plane: pitch and the forward offset no longer
// trade off. Throws std::invalid_argument for fewer than 6 pairs, coplanar
// points or a pose outside CameraMounting's bounds.
rig::camera::CameraMounting mounting_from_points(const rig::camera::CameraIntrinsics& intrinsics,
                                                 const std::vector<Eigen::Vector3d>& boom_points,
                                                 const std::vector<Eigen::Vector2d>& undistorted_px);

}  // namespace rig::controller::boundary::vision
