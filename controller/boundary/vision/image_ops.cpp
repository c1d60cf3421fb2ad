#include "controller/boundary/vision/image_ops.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace rig::controller::boundary::vision {

namespace {

// OpenCV's camera matrix for rig::camera's intrinsics. `centre_shift` is
// what is added to rig::camera's pixel coordinates to get OpenCV's: -0.5 where
// OpenCV indexes pixels (maps, images), 0 where only normalised coordinates
// matter (undistortPoints in and out in rig::camera's convention).
cv::Matx33d camera_matrix(const rig::camera::CameraIntrinsics& k, double centre_shift) {
    return {k.fx_px, 0.0, k.cx_px + centre_shift, 0.0, k.fy_px, k.cy_px + centre_shift, 0.0, 0.0, 1.0};
}

// OpenCV's order of Brown-Conrady's coefficients: k1, k2, p1, p2, k3 (the
// same polynomial as rig/camera/pinhole_camera.h's).
cv::Matx<double, 1, 5> distortion_coefficients(const rig::camera::BrownConradyDistortion& d) { return {d.k1, d.k2, d.p1, d.p2, d.k3}; }

// True when the points span more than a line: the smaller principal spread is
// not negligible against the larger.
bool spans_a_plane(const std::vector<Eigen::Vector2d>& points) {
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& p : points) centroid += p;
    centroid /= static_cast<double>(points.size());
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    for (const Eigen::Vector2d& p : points) scatter += (p - centroid) * (p - centroid).transpose();
    const Eigen::Vector2d spreads = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvalues();
    return spreads(1) > 0.0 && spreads(0) > 1e-12 * spreads(1);
}

}  // namespace

void use_fixed_opencv_threads() {
    static std::once_flag once;
    std::call_once(once, [] { cv::setNumThreads(1); });
}

std::vector<std::uint8_t> excess_green_values(const rig::camera::RgbImage& frame) {
    const std::size_t pixels = frame.bytes.size() / 3U;
    std::vector<std::uint8_t> values(pixels);
    for (std::size_t i = 0; i < pixels; ++i) values[i] = excess_green({frame.bytes[3 * i], frame.bytes[3 * i + 1], frame.bytes[3 * i + 2]});
    return values;
}

std::optional<int> otsu_threshold(std::span<const std::uint8_t> values) {
    use_fixed_opencv_threads();
    std::array<bool, 256> present{};
    for (const std::uint8_t value : values) present[value] = true;
    const auto levels = std::count(present.begin(), present.end(), true);
    if (levels < 2) return std::nullopt;
    // One row of 8-bit values; cv::threshold reads it, never writes it.
    const cv::Mat row(1, static_cast<int>(values.size()), CV_8UC1, const_cast<std::uint8_t*>(values.data()));
    cv::Mat classes;
    // OpenCV's split is {value <= t} / {value > t}.
    const int t = static_cast<int>(cv::threshold(row, classes, 0.0, 255.0, cv::THRESH_BINARY | cv::THRESH_OTSU));
    if (t < 0 || t > 254) return std::nullopt;  // no split with both classes filled
    // Every T from just above the lower class's top value to the upper
    // class's bottom value splits these values alike (Otsu's criterion is
    // flat across the empty gap between them). The ROI's bilinear samples
    // fall in such gaps (a frame at one sample a pixel has few values
    // between soil and leaf), so where T lies in the gap decides them: its
    // middle, as far from both classes as the gap allows, not OpenCV's
    // first T (which moved the density of seed-001's vision cases by up to
    // 1.5 points).
    int lower_top = t;
    while (lower_top > 0 && !present[static_cast<std::size_t>(lower_top)]) --lower_top;
    int upper_bottom = t + 1;
    while (upper_bottom < 255 && !present[static_cast<std::size_t>(upper_bottom)]) ++upper_bottom;
    if (!present[static_cast<std::size_t>(lower_top)] || !present[static_cast<std::size_t>(upper_bottom)]) return std::nullopt;
    return (lower_top + 1 + upper_bottom) / 2;
}

Eigen::Matrix3d fit_homography(const std::vector<Eigen::Vector2d>& from, const std::vector<Eigen::Vector2d>& to) {
    use_fixed_opencv_threads();
    if (from.size() != to.size() || from.size() < 4) {
        throw std::invalid_argument("fit_homography: needs 4 or more point pairs, got " + std::to_string(from.size()) + " and " +
                                    std::to_string(to.size()));
    }
    if (!spans_a_plane(from) || !spans_a_plane(to)) throw std::invalid_argument("fit_homography: degenerate points (collinear or repeated)");
    std::vector<cv::Point2d> cv_from;
    std::vector<cv::Point2d> cv_to;
    for (std::size_t i = 0; i < from.size(); ++i) {
        cv_from.emplace_back(from[i].x(), from[i].y());
        cv_to.emplace_back(to[i].x(), to[i].y());
    }
    // Method 0: every pair counts (no RANSAC: the points are the caller's, not matches with outliers).
    const cv::Mat h = cv::findHomography(cv_from, cv_to, 0);
    if (h.empty()) throw std::invalid_argument("fit_homography: no homography fits the points (degenerate configuration)");
    Eigen::Matrix3d result;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) result(r, c) = h.at<double>(r, c);
    }
    if (!result.allFinite() || std::abs(result.determinant()) < 1e-300) {
        throw std::invalid_argument("fit_homography: the fitted homography is singular (degenerate points)");
    }
    return result;
}

std::vector<Eigen::Vector2d> undistort_pixels(const std::vector<Eigen::Vector2d>& pixels, const rig::camera::CameraIntrinsics& intrinsics,
                                              const rig::camera::BrownConradyDistortion& distortion) {
    use_fixed_opencv_threads();
    if (pixels.empty()) return {};
    std::vector<cv::Point2d> distorted;
    distorted.reserve(pixels.size());
    for (const Eigen::Vector2d& p : pixels) distorted.emplace_back(p.x(), p.y());
    std::vector<cv::Point2d> undistorted;
    const cv::Matx33d k = camera_matrix(intrinsics, 0.0);
    // OpenCV inverts the lens by fixed-point iteration; stop when the point
    // re-distorted lies within 1e-6 px of where it was seen (the old Newton
    // inverse of rig/camera went to 1e-12 in normalised units, ~1e-9 px; the
    // nozzle and corner positions it feeds carry ~0.1 px of noise).
    const cv::TermCriteria until(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-6);
    cv::undistortPoints(distorted, undistorted, k, distortion_coefficients(distortion), cv::noArray(), k, until);
    std::vector<Eigen::Vector2d> result;
    result.reserve(undistorted.size());
    for (std::size_t i = 0; i < undistorted.size(); ++i) {
        if (!std::isfinite(undistorted[i].x) || !std::isfinite(undistorted[i].y)) {
            std::ostringstream message;
            message << "undistort_pixels: pixel (" << pixels[i].x() << ", " << pixels[i].y() << ") has no finite undistorted position";
            throw std::invalid_argument(message.str());
        }
        result.emplace_back(undistorted[i].x, undistorted[i].y);
    }
    return result;
}

RectangleWarp warp_to_rectangle(const rig::camera::RgbImage& frame, const rig::camera::CameraIntrinsics& intrinsics,
                                const rig::camera::BrownConradyDistortion& distortion, const Eigen::Matrix3d& rectangle_to_undistorted,
                                int width, int height) {
    use_fixed_opencv_threads();
    if (const auto problem = rig::camera::frame_size_problem(frame, intrinsics)) throw std::invalid_argument("warp_to_rectangle: " + *problem);
    if (width < 1 || height < 1) {
        throw std::invalid_argument("warp_to_rectangle: a " + std::to_string(width) + " x " + std::to_string(height) + " rectangle");
    }
    // initUndistortRectifyMap takes each destination pixel (i, j) through
    // (P R)^-1 to normalised undistorted coordinates, then through the lens
    // and the camera matrix. With P = I, R^-1 is that first step: rectangle
    // pixel index -> its centre (+0.5) -> undistorted pixel -> normalised (K^-1).
    Eigen::Matrix3d k;
    k << intrinsics.fx_px, 0.0, intrinsics.cx_px, 0.0, intrinsics.fy_px, intrinsics.cy_px, 0.0, 0.0, 1.0;
    Eigen::Matrix3d index_to_centre;
    index_to_centre << 1.0, 0.0, 0.5, 0.0, 1.0, 0.5, 0.0, 0.0, 1.0;
    const Eigen::Matrix3d index_to_normalised = k.inverse() * rectangle_to_undistorted * index_to_centre;
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(index_to_normalised);
    if (!lu.isInvertible()) throw std::invalid_argument("warp_to_rectangle: the rectangle's map to the image is singular");
    const Eigen::Matrix3d rotation_argument = lu.inverse();
    cv::Matx33d r;
    for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 3; ++col) r(row, col) = rotation_argument(row, col);
    }
    cv::Mat map_x;
    cv::Mat map_y;
    cv::initUndistortRectifyMap(camera_matrix(intrinsics, -0.5), distortion_coefficients(distortion), r, cv::Matx33d::eye(),
                                cv::Size(width, height), CV_32FC1, map_x, map_y);

    RectangleWarp warp;
    warp.inside.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0);
    // Inside: the sample lies within the hull of the frame's pixel centres, so
    // bilinear sampling needs no pixel beyond the frame (the fixed-point
    // position, rounded to 1/32 px, stays within the hull too).
    const float last_x = static_cast<float>(frame.width - 1);
    const float last_y = static_cast<float>(frame.height - 1);
    for (int j = 0; j < height; ++j) {
        const float* xs = map_x.ptr<float>(j);
        const float* ys = map_y.ptr<float>(j);
        for (int i = 0; i < width; ++i) {
            const bool inside = xs[i] >= 0.0F && ys[i] >= 0.0F && xs[i] <= last_x && ys[i] <= last_y;
            warp.inside[static_cast<std::size_t>(j) * static_cast<std::size_t>(width) + static_cast<std::size_t>(i)] = inside ? 1 : 0;
            warp.inside_px += inside ? 1 : 0;
        }
    }
    // Fixed-point maps (1/32 px positions, 15-bit weights): remap's exact
    // integer arithmetic, the same on every machine and SIMD width.
    cv::Mat fixed_positions;
    cv::Mat fixed_fractions;
    cv::convertMaps(map_x, map_y, fixed_positions, fixed_fractions, CV_16SC2);
    const cv::Mat source(frame.height, frame.width, CV_8UC3, const_cast<std::uint8_t*>(frame.bytes.data()));
    warp.image = rig::camera::RgbImage(width, height);
    cv::Mat destination(height, width, CV_8UC3, warp.image.bytes.data());
    cv::remap(source, destination, fixed_positions, fixed_fractions, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0, 0, 0));
    for (std::size_t n = 0; n < warp.inside.size(); ++n) {
        if (warp.inside[n] == 0) std::fill_n(warp.image.bytes.begin() + static_cast<std::ptrdiff_t>(3 * n), 3, std::uint8_t{0});
    }
    return warp;
}

}  // namespace rig::controller::boundary::vision
