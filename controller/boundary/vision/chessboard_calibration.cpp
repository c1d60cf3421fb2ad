#include "controller/boundary/vision/chessboard_calibration.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "controller/boundary/vision/image_ops.h"

namespace rig::controller::boundary::vision {

namespace {

// cornerSubPix's search window: 5 px either way, within half the smallest
// square the placements give (40 mm at ~1.1 m, ~30 px) so no neighbouring
// corner falls inside it.
constexpr int kSubPixelHalfWindowPx = 5;
// The corners must lie on the fitted plane grid to this RMS.
constexpr double kMaxRmsPx = 1.0;

double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }

Eigen::Vector2d apply(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) {
    const Eigen::Vector3d q = h * Eigen::Vector3d(p.x(), p.y(), 1.0);
    return {q.x() / q.z(), q.y() / q.z()};
}

// The DLT's solution: the right singular vector of A's smallest singular
// value. Throws std::invalid_argument `degenerate` when the next smallest is
// also (near) zero: the points do not fix the solution.
Eigen::VectorXd null_vector(const Eigen::MatrixXd& a, const char* degenerate) {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
    const Eigen::VectorXd& sv = svd.singularValues();
    const Eigen::Index n = a.cols();
    if (sv(n - 2) < 1e-9 * sv(0)) throw std::invalid_argument(degenerate);
    return svd.matrixV().col(n - 1);
}

// The points' centroid and their mean distance from it (Hartley's normalisation).
std::pair<Eigen::Vector3d, double> centroid_and_spread(const std::vector<Eigen::Vector3d>& points) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : points) centroid += p;
    centroid /= static_cast<double>(points.size());
    double mean_distance = 0.0;
    for (const Eigen::Vector3d& p : points) mean_distance += (p - centroid).norm();
    return {centroid, mean_distance / static_cast<double>(points.size())};
}

}  // namespace

ChessboardView find_chessboard(const rig::camera::RgbImage& frame, const rig::camera::PinholeCamera& model,
                               const ChessboardPlacement& placement) {
    use_fixed_opencv_threads();
    ChessboardView view;
    if (const auto problem = rig::camera::frame_size_problem(frame, model.model().intrinsics)) {
        view.problem = *problem;
        return view;
    }
    if (placement.inner_cols < 2 || placement.inner_rows < 2 || !(placement.square_m > 0.0)) {
        view.problem = "chessboard placement: needs 2 x 2 or more inner corners and a square > 0";
        return view;
    }
    const cv::Mat rgb(frame.height, frame.width, CV_8UC3, const_cast<std::uint8_t*>(frame.bytes.data()));
    cv::Mat grey;
    cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
    const cv::Size pattern(placement.inner_cols, placement.inner_rows);
    const std::string declared = std::to_string(placement.inner_cols) + " x " + std::to_string(placement.inner_rows) + " inner corners (" +
                                 std::to_string(placement.inner_cols * placement.inner_rows) + ")";
    std::vector<cv::Point2f> found;
    // NORMALIZE_IMAGE: the board lies in the field's light, not on a scanner.
    // FAST_CHECK: a frame without a board is refused in milliseconds.
    // Not ADAPTIVE_THRESH: on a frame of a board with fewer corners than
    // declared it searched for 20 s of CPU (measured on this rig's rendered
    // frames; 5 ms without it), a hang for a calibration step; the rig's
    // lighting is even over a frame, where a global threshold suffices.
    if (!cv::findChessboardCorners(grey, pattern, found, cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK)) {
        view.problem = "no chessboard of " + declared + " in the frame (none in view, partly hidden, or another size)";
        return view;
    }
    // The saddle point to sub-pixel precision: every grey-level gradient near
    // a corner is perpendicular to the line from the corner (Foerstner).
    cv::cornerSubPix(grey, found, cv::Size(kSubPixelHalfWindowPx, kSubPixelHalfWindowPx), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 0.001));

    // OpenCV's order: rows of inner_cols corners, starting at any of the
    // board's ends. Ours (the placement's): i across (boom x, right in the
    // image), j ahead (boom y, up in the image), index j * inner_cols + i.
    // A square pattern's rows may also run ahead: then they are our columns.
    const int cols = placement.inner_cols;
    const int rows = placement.inner_rows;
    auto at = [&](int col, int row) { return found[static_cast<std::size_t>(row * cols + col)]; };
    const cv::Point2f along_row = at(cols - 1, 0) - at(0, 0);
    const cv::Point2f along_column = at(0, rows - 1) - at(0, 0);
    const bool rows_run_across = std::abs(along_row.x) >= std::abs(along_row.y);
    if (!rows_run_across && cols != rows) {
        view.problem = "the chessboard's " + std::to_string(cols) + "-corner rows run ahead, not across: it lies turned from its declared placement";
        return view;
    }
    std::vector<Eigen::Vector2d> distorted(found.size());
    for (int row = 0; row < rows; ++row) {
        for (int col = 0; col < cols; ++col) {
            int i = rows_run_across ? col : row;
            int j = rows_run_across ? row : col;
            const bool i_reversed = rows_run_across ? along_row.x < 0.0F : along_column.x < 0.0F;
            const bool j_reversed = rows_run_across ? along_column.y > 0.0F : along_row.y > 0.0F;
            if (i_reversed) i = cols - 1 - i;
            if (j_reversed) j = rows - 1 - j;
            // OpenCV's pixel centres lie on integers, rig::camera's at +0.5.
            distorted[static_cast<std::size_t>(j * cols + i)] = Eigen::Vector2d(at(col, row).x + 0.5, at(col, row).y + 0.5);
        }
    }
    view.corners_px = undistort_pixels(distorted, model.model().intrinsics, model.model().distortion);

    std::vector<Eigen::Vector2d> plane_points;
    for (int j = 0; j < rows; ++j) {
        for (int i = 0; i < cols; ++i) {
            plane_points.emplace_back(placement.origin_right_m + i * placement.square_m, placement.origin_ahead_m + j * placement.square_m);
        }
    }
    try {
        view.plane_to_pixel = fit_homography(plane_points, view.corners_px);
    } catch (const std::invalid_argument& error) {
        view.problem = std::string("the chessboard corners found fix no homography: ") + error.what();
        return view;
    }
    double squared = 0.0;
    for (std::size_t n = 0; n < plane_points.size(); ++n) squared += (apply(view.plane_to_pixel, plane_points[n]) - view.corners_px[n]).squaredNorm();
    view.rms_px = std::sqrt(squared / static_cast<double>(plane_points.size()));
    if (view.rms_px > kMaxRmsPx) {
        view.problem = "the corners found are not a chessboard's grid (RMS " + std::to_string(view.rms_px) + " px from the fitted homography)";
        return view;
    }
    view.ok = true;
    return view;
}

namespace {

// The mounting of a camera whose frame takes boom-frame points P to
// camera_from_boom P + t (rig/camera/pinhole_camera.cpp's conventions:
// axes = Yaw(-yaw) LookingDown(pitch) Roll(roll)), checked against the model's bounds.
rig::camera::CameraMounting mounting_from_pose(const rig::camera::CameraIntrinsics& intrinsics, const Eigen::Matrix3d& camera_from_boom,
                                               const Eigen::Vector3d& t) {
    const Eigen::Matrix3d axes = camera_from_boom.transpose();  // camera axes in the boom frame
    const Eigen::Vector3d position = -axes * t;
    rig::camera::CameraMounting mounting;
    mounting.right_m = position.x();
    mounting.forward_m = position.y();
    mounting.above_boom_m = position.z();
    const Eigen::Vector3d optical_axis = axes.col(2);
    mounting.pitch_deg = degrees(std::acos(std::clamp(-optical_axis.z(), -1.0, 1.0)));
    const double horizontal = std::hypot(optical_axis.x(), optical_axis.y());
    mounting.yaw_deg = horizontal > 1e-9 ? degrees(std::atan2(optical_axis.x(), optical_axis.y())) : 0.0;
    rig::camera::CameraMounting untwisted;
    untwisted.pitch_deg = mounting.pitch_deg;
    untwisted.roll_deg = 0.0;
    untwisted.yaw_deg = 0.0;
    const Eigen::Matrix3d roll = rig::camera::camera_axes_in_boom(untwisted).transpose() *
                                 Eigen::AngleAxisd(mounting.yaw_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix() * axes;
    mounting.roll_deg = degrees(std::atan2(roll(1, 0), roll(0, 0)));
    rig::camera::CameraModel check;
    check.intrinsics = intrinsics;
    check.mounting = mounting;
    rig::camera::validate(check, "chessboard pose");
    return mounting;
}

// The rotation nearest a matrix (SVD), and the mean of its singular values.
Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& m, double* mean_scale) {
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
    if (mean_scale != nullptr) *mean_scale = svd.singularValues().mean();
    return svd.matrixU() * svd.matrixV().transpose();
}

}  // namespace

rig::camera::CameraMounting mounting_from_plane_homography(const rig::camera::CameraIntrinsics& intrinsics,
                                                           const Eigen::Matrix3d& plane_to_pixel, double plane_z_m) {
    Eigen::Matrix3d k;
    k << intrinsics.fx_px, 0.0, intrinsics.cx_px, 0.0, intrinsics.fy_px, intrinsics.cy_px, 0.0, 0.0, 1.0;
    const Eigen::Matrix3d m = k.inverse() * plane_to_pixel;
    const double scale = 2.0 / (m.col(0).norm() + m.col(1).norm());
    Eigen::Vector3d r1 = scale * m.col(0);
    Eigen::Vector3d r2 = scale * m.col(1);
    Eigen::Vector3d t_plane = scale * m.col(2);
    if (t_plane.z() < 0.0) {  // the plane's origin lies in front of the camera
        r1 = -r1;
        r2 = -r2;
        t_plane = -t_plane;
    }
    Eigen::Matrix3d approximate;
    approximate.col(0) = r1;
    approximate.col(1) = r2;
    approximate.col(2) = r1.cross(r2);
    // The columns of K^-1 H are orthonormal only up to noise.
    const Eigen::Matrix3d camera_from_boom = nearest_rotation(approximate, nullptr);
    if (camera_from_boom.determinant() < 0.0) throw std::invalid_argument("mounting_from_plane_homography: H is a reflection, not a camera");
    // The plane's origin is (0, 0, plane_z): t_plane = t + plane_z r3.
    return mounting_from_pose(intrinsics, camera_from_boom, t_plane - plane_z_m * camera_from_boom.col(2));
}

rig::camera::CameraMounting mounting_from_points(const rig::camera::CameraIntrinsics& intrinsics,
                                                 const std::vector<Eigen::Vector3d>& boom_points,
                                                 const std::vector<Eigen::Vector2d>& undistorted_px) {
    if (boom_points.size() != undistorted_px.size() || boom_points.size() < 6) {
        throw std::invalid_argument("mounting_from_points: needs 6 or more point pairs, got " + std::to_string(boom_points.size()) +
                                    " and " + std::to_string(undistorted_px.size()));
    }
    // Normalise the 3-D points (centroid to 0, mean distance sqrt(3)); the
    // image points become normalised camera coordinates through K.
    const auto [centroid, mean_distance] = centroid_and_spread(boom_points);
    const double s = std::sqrt(3.0) / mean_distance;
    Eigen::MatrixXd a(2 * boom_points.size(), 12);
    for (std::size_t i = 0; i < boom_points.size(); ++i) {
        const Eigen::Vector3d p = s * (boom_points[i] - centroid);
        const double x = (undistorted_px[i].x() - intrinsics.cx_px) / intrinsics.fx_px;
        const double y = (undistorted_px[i].y() - intrinsics.cy_px) / intrinsics.fy_px;
        const auto r = static_cast<Eigen::Index>(2 * i);
        a.row(r) << p.x(), p.y(), p.z(), 1.0, 0.0, 0.0, 0.0, 0.0, -x * p.x(), -x * p.y(), -x * p.z(), -x;
        a.row(r + 1) << 0.0, 0.0, 0.0, 0.0, p.x(), p.y(), p.z(), 1.0, -y * p.x(), -y * p.y(), -y * p.z(), -y;
    }
    const Eigen::VectorXd v = null_vector(a, "mounting_from_points: degenerate points (all on one plane or a line)");
    // [M | m] on normalised points: x ~ M p' + m with p' = s (P - c), so in
    // boom coordinates x ~ (s M) P + (m - s M c).
    Eigen::Matrix3d m_normalised;
    m_normalised << v(0), v(1), v(2), v(4), v(5), v(6), v(8), v(9), v(10);
    const Eigen::Vector3d m_offset(v(3), v(7), v(11));
    Eigen::Matrix3d rotation_scaled = s * m_normalised;
    Eigen::Vector3d t_scaled = m_offset - s * m_normalised * centroid;
    if (rotation_scaled.determinant() < 0.0) {
        rotation_scaled = -rotation_scaled;
        t_scaled = -t_scaled;
    }
    double scale = 1.0;
    const Eigen::Matrix3d camera_from_boom = nearest_rotation(rotation_scaled, &scale);
    const Eigen::Vector3d t = t_scaled / scale;
    if ((camera_from_boom * centroid + t).z() <= 0.0) {
        throw std::invalid_argument("mounting_from_points: the points come out behind the camera");
    }
    return mounting_from_pose(intrinsics, camera_from_boom, t);
}

}  // namespace rig::controller::boundary::vision
