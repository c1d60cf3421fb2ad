#include "controller/boundary/vision/image_ops.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rig::controller::boundary::vision {

Histogram excess_green_histogram(const rig::camera::RgbImage& frame) {
    Histogram histogram{};
    const std::size_t pixels = frame.bytes.size() / 3U;
    for (std::size_t i = 0; i < pixels; ++i) {
        const rig::camera::Rgb pixel{frame.bytes[3 * i], frame.bytes[3 * i + 1], frame.bytes[3 * i + 2]};
        ++histogram[excess_green(pixel)];
    }
    return histogram;
}

std::optional<int> otsu_threshold(const Histogram& histogram) {
    double total = 0.0;
    double total_sum = 0.0;
    for (int value = 0; value < 256; ++value) {
        total += static_cast<double>(histogram[value]);
        total_sum += value * static_cast<double>(histogram[value]);
    }
    if (total == 0.0) return std::nullopt;
    // Sweep T upwards, moving bin T - 1 into the lower class each step.
    double lower_count = 0.0;
    double lower_sum = 0.0;
    double best = 0.0;
    int best_first = -1;
    int best_last = -1;
    for (int threshold = 1; threshold < 256; ++threshold) {
        lower_count += static_cast<double>(histogram[threshold - 1]);
        lower_sum += (threshold - 1) * static_cast<double>(histogram[threshold - 1]);
        const double upper_count = total - lower_count;
        if (lower_count == 0.0 || upper_count == 0.0) continue;
        const double mean_difference = lower_sum / lower_count - (total_sum - lower_sum) / upper_count;
        const double between = lower_count * upper_count * mean_difference * mean_difference;
        // Relative tolerance: the plateau over a gap has equal variances up to rounding.
        if (between > best * (1.0 + 1e-12)) {
            best = between;
            best_first = threshold;
            best_last = threshold;
        } else if (best > 0.0 && between >= best * (1.0 - 1e-12) && best_last == threshold - 1) {
            best_last = threshold;
        }
    }
    if (best_first < 0) return std::nullopt;
    return (best_first + best_last) / 2;
}

Eigen::Matrix3d perspective_transform(const std::array<Eigen::Vector2d, 4>& from, const std::array<Eigen::Vector2d, 4>& to) {
    // u = (h11 x + h12 y + h13) / (h31 x + h32 y + 1), v likewise: two rows per pair.
    Eigen::Matrix<double, 8, 8> a = Eigen::Matrix<double, 8, 8>::Zero();
    Eigen::Matrix<double, 8, 1> b;
    for (int i = 0; i < 4; ++i) {
        const double x = from[i].x();
        const double y = from[i].y();
        const double u = to[i].x();
        const double v = to[i].y();
        a.row(2 * i) << x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y;
        a.row(2 * i + 1) << 0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y;
        b(2 * i) = u;
        b(2 * i + 1) = v;
    }
    const Eigen::FullPivLU<Eigen::Matrix<double, 8, 8>> lu(a);
    if (lu.rank() < 8) throw std::invalid_argument("perspective_transform: degenerate corners (three or more collinear or repeated)");
    const Eigen::Matrix<double, 8, 1> h = lu.solve(b);
    Eigen::Matrix3d m;
    m << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1.0;
    return m;
}

std::optional<std::array<double, 3>> sample_bilinear(const rig::camera::RgbImage& frame, double x, double y) {
    // Pixel centres sit at (u + 0.5, v + 0.5).
    const double gx = x - 0.5;
    const double gy = y - 0.5;
    if (!(gx >= 0.0 && gy >= 0.0 && gx <= frame.width - 1 && gy <= frame.height - 1)) return std::nullopt;
    const int u0 = std::min(static_cast<int>(gx), frame.width - 2 < 0 ? 0 : frame.width - 2);
    const int v0 = std::min(static_cast<int>(gy), frame.height - 2 < 0 ? 0 : frame.height - 2);
    const int u1 = std::min(u0 + 1, frame.width - 1);
    const int v1 = std::min(v0 + 1, frame.height - 1);
    const double fx = gx - u0;
    const double fy = gy - v0;
    std::array<double, 3> colour{};
    for (std::size_t c = 0; c < 3; ++c) {
        const double top = frame.bytes[frame.offset(u0, v0) + c] * (1.0 - fx) + frame.bytes[frame.offset(u1, v0) + c] * fx;
        const double bottom = frame.bytes[frame.offset(u0, v1) + c] * (1.0 - fx) + frame.bytes[frame.offset(u1, v1) + c] * fx;
        colour[c] = top * (1.0 - fy) + bottom * fy;
    }
    return colour;
}

}  // namespace rig::controller::boundary::vision
