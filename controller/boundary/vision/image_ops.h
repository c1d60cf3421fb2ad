#pragma once
// The image work of seed 001's vision (Sec. 2.2, 4.1). Eq. 15's index is the
// paper's own and written out here; the rest is what an image library does,
// and OpenCV (Debian's 4.6: core, imgproc, calib3d) does it behind this
// interface, which speaks Eigen and rig::camera so OpenCV stays private to
// rig::boundary_vision:
//   Eq. 16  Otsu's threshold            cv::threshold(THRESH_OTSU)
//   Eq. 5   homographies from points    cv::findHomography (least squares, then
//                                       Levenberg-Marquardt on the reprojection error)
//   the undistortion of pixel positions cv::undistortPoints (Brown-Conrady, the
//                                       model of rig/camera/pinhole_camera.h)
//   the ROI warp (Sec. 4.1)             cv::initUndistortRectifyMap builds one map
//                                       (perspective and lens in one resampling),
//                                       cv::remap samples it, bilinear, fixed point
// OpenCV runs on one thread here (use_fixed_opencv_threads): the rig's runs
// must not depend on the machine's core count, and lockstep leases one CPU.
// Pixel coordinates are rig::camera's (rgb_image.h): pixel (u, v)'s centre
// lies at (u + 0.5, v + 0.5); OpenCV's lie at (u, v), converted inside.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Dense>

#include "rig/camera/pinhole_camera.h"
#include "rig/camera/rgb_image.h"

namespace rig::controller::boundary::vision {

// Eq. 15, clipped to 0..255 (S7: the negative values of bare soil become 0).
inline std::uint8_t excess_green(rig::camera::Rgb pixel) {
    const int value = 2 * pixel.g - pixel.r - pixel.b;
    return static_cast<std::uint8_t>(value < 0 ? 0 : (value > 255 ? 255 : value));
}

// Eq. 15 of every pixel of a frame, row by row.
std::vector<std::uint8_t> excess_green_values(const rig::camera::RgbImage& frame);

// Eq. 16: Otsu's threshold over 8-bit values, the T in 1..255 that maximises
// the between-class variance w0 w1 (m0 - m1)^2 of {value < T} and
// {value >= T} (OpenCV's). Where the split falls in an empty gap between two
// modes, every T in the gap shares the maximum: the middle of the gap.
// Values with fewer than two distinct levels (none, or bare soil all clipped
// to 0) have no split: nullopt.
std::optional<int> otsu_threshold(std::span<const std::uint8_t> values);

// The H with to ~ H from over n >= 4 point pairs (exact for 4). Throws
// std::invalid_argument for fewer than 4 pairs, unequal counts, or points
// that fix no homography (all on one line, repeated).
Eigen::Matrix3d fit_homography(const std::vector<Eigen::Vector2d>& from, const std::vector<Eigen::Vector2d>& to);

// The undistorted pixel positions (the pinhole image of the same rays) of
// pixel positions in a frame. Throws std::invalid_argument naming the first
// position whose undistortion is not finite.
std::vector<Eigen::Vector2d> undistort_pixels(const std::vector<Eigen::Vector2d>& pixels, const rig::camera::CameraIntrinsics& intrinsics,
                                              const rig::camera::BrownConradyDistortion& distortion);

struct RectangleWarp {
    rig::camera::RgbImage image;         // width x height; black where the sample fell outside the frame
    std::vector<std::uint8_t> inside;    // per pixel, row by row: 1 where it fell inside the frame's pixel centres
    long inside_px = 0;
};

// A quadrilateral of the undistorted image warped to a width x height
// rectangle: rectangle point (x, y) (its pixel (i, j) at (i + 0.5, j + 0.5))
// -> undistorted pixel rectangle_to_undistorted (x, y, 1) -> the frame's
// pixel through the lens, sampled bilinearly. The quadrilateral must lie in
// front of the camera (the caller checks its corners). Throws
// std::invalid_argument for a frame that is not the intrinsics' size, a size
// below 1 x 1 or a singular map.
RectangleWarp warp_to_rectangle(const rig::camera::RgbImage& frame, const rig::camera::CameraIntrinsics& intrinsics,
                                const rig::camera::BrownConradyDistortion& distortion, const Eigen::Matrix3d& rectangle_to_undistorted,
                                int width, int height);

// Sets OpenCV's thread count to the rig's fixed one (1), once per process;
// each function here calls it.
void use_fixed_opencv_threads();

}  // namespace rig::controller::boundary::vision
