#pragma once
// The few image operations seed 001's vision needs (Sec. 4.1), written out
// here rather than taken from OpenCV (not a dependency of the rig):
//   Eq. 15  ExG = 2G - R - B, clipped to 0..255
//   Eq. 16  Otsu's threshold T on the ExG histogram; plant where ExG >= T
//   the perspective transform of a quadrilateral to a rectangle (the ROI warp)
//   bilinear sampling of an RGB frame (continuous pixel coordinates, see
//   rig/camera/rgb_image.h)
#include <array>
#include <cstdint>
#include <optional>

#include <Eigen/Dense>

#include "rig/camera/rgb_image.h"

namespace rig::controller::boundary::vision {

// Eq. 15, clipped to 0..255 (S7: the negative values of bare soil become 0).
inline std::uint8_t excess_green(rig::camera::Rgb pixel) {
    const int value = 2 * pixel.g - pixel.r - pixel.b;
    return static_cast<std::uint8_t>(value < 0 ? 0 : (value > 255 ? 255 : value));
}

using Histogram = std::array<std::uint64_t, 256>;

// The ExG histogram of a whole frame.
Histogram excess_green_histogram(const rig::camera::RgbImage& frame);

// Eq. 16: Otsu's threshold, the T in 1..255 that maximises the between-class
// variance w0 w1 (m0 - m1)^2 of the classes {value < T} and {value >= T}.
// Where several T share the maximum (a gap between two modes) the middle of
// that run is taken, so the split lies midway in the gap. An empty histogram,
// or one with a single value (no split exists), gives nullopt.
std::optional<int> otsu_threshold(const Histogram& histogram);

// The homography taking each `from` point to the `to` point of the same index
// (four pairs, no three collinear): the 3 x 3 matrix with h33 = 1, from the
// 8 x 8 linear system of the direct linear transform. Throws
// std::invalid_argument for a degenerate configuration.
Eigen::Matrix3d perspective_transform(const std::array<Eigen::Vector2d, 4>& from, const std::array<Eigen::Vector2d, 4>& to);

// The frame's colour at continuous pixel coordinates (x, y), bilinear between
// the four nearest pixel centres; nullopt outside the pixel centres' hull.
std::optional<std::array<double, 3>> sample_bilinear(const rig::camera::RgbImage& frame, double x, double y);

}  // namespace rig::controller::boundary::vision
