#include "controller/boundary/vision/nozzle_calibration.h"

#include <algorithm>
#include <cmath>
#include <span>

#include "controller/boundary/vision/image_ops.h"

namespace rig::controller::boundary::vision {

namespace {

std::uint8_t clipped(int value) { return static_cast<std::uint8_t>(std::clamp(value, 0, 255)); }
// Sec. 2.2.1's colour indices.
std::uint8_t green_index(rig::camera::Rgb p) { return clipped(2 * p.g - p.b - p.r); }
std::uint8_t red_index(rig::camera::Rgb p) { return clipped(2 * p.r - p.g - p.b); }

// Total least squares: the line through the centroid along the principal axis.
ImageLine fit_line(const std::vector<Eigen::Vector2d>& points) {
    ImageLine line;
    line.pixels = static_cast<long>(points.size());
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& p : points) centroid += p;
    centroid /= static_cast<double>(points.size());
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    for (const Eigen::Vector2d& p : points) scatter += (p - centroid) * (p - centroid).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(scatter);
    line.point = centroid;
    line.direction = solver.eigenvectors().col(1).normalized();  // the larger eigenvalue's
    const double along = solver.eigenvalues()(1);
    line.spread_ratio = along > 0.0 ? std::sqrt(std::max(0.0, solver.eigenvalues()(0)) / along) : 1.0;
    return line;
}

std::optional<Eigen::Vector2d> intersect(const ImageLine& a, const ImageLine& b) {
    Eigen::Matrix2d m;
    m.col(0) = a.direction;
    m.col(1) = -b.direction;
    if (std::abs(m.determinant()) < 1e-9) return std::nullopt;
    const Eigen::Vector2d t = m.inverse() * (b.point - a.point);
    return a.point + t.x() * a.direction;
}

// Board pixels this close to the frame's edge mean the board is cut off.
constexpr int kEdgePx = 2;
// Boards are 0.3 as wide as long; above this the pixels are not one board.
constexpr double kMaxSpreadRatio = 0.5;

int threshold_of(std::span<const std::uint8_t> values, int floor) { return std::max(otsu_threshold(values).value_or(256), floor); }

}  // namespace

NozzleCalibration find_nozzle_points(const rig::camera::RgbImage& frame, const rig::camera::PinholeCamera& model,
                                     std::size_t nozzle_count, int colour_floor) {
    NozzleCalibration result;
    if (const auto problem = rig::camera::frame_size_problem(frame, model.model().intrinsics)) {
        result.problem = *problem;
        return result;
    }
    const std::size_t pixel_count = frame.bytes.size() / 3U;
    std::vector<std::uint8_t> green(pixel_count);
    std::vector<std::uint8_t> red(pixel_count);
    for (std::size_t i = 0; i < pixel_count; ++i) {
        const rig::camera::Rgb p{frame.bytes[3 * i], frame.bytes[3 * i + 1], frame.bytes[3 * i + 2]};
        green[i] = green_index(p);
        red[i] = red_index(p);
    }
    result.green_threshold = threshold_of(green, colour_floor);
    result.red_threshold = threshold_of(red, colour_floor);

    // The selected pixels' centres, then undistorted with the camera's calibration.
    std::vector<Eigen::Vector2d> green_points;
    std::vector<Eigen::Vector2d> red_points;
    bool green_at_edge = false;
    bool red_at_edge = false;
    for (int v = 0; v < frame.height; ++v) {
        for (int u = 0; u < frame.width; ++u) {
            const std::size_t i = static_cast<std::size_t>(v) * static_cast<std::size_t>(frame.width) + static_cast<std::size_t>(u);
            const bool is_green = green[i] >= result.green_threshold;
            const bool is_red = red[i] >= result.red_threshold;
            if (!is_green && !is_red) continue;
            // A board cut by the frame's edge gives a line through its visible part only.
            const bool at_edge = u < kEdgePx || v < kEdgePx || u >= frame.width - kEdgePx || v >= frame.height - kEdgePx;
            green_at_edge = green_at_edge || (is_green && at_edge);
            red_at_edge = red_at_edge || (is_red && at_edge);
            (is_green ? green_points : red_points).emplace_back(u + 0.5, v + 0.5);
        }
    }
    const rig::camera::CameraModel& calibration = model.model();
    green_points = undistort_pixels(green_points, calibration.intrinsics, calibration.distortion);
    red_points = undistort_pixels(red_points, calibration.intrinsics, calibration.distortion);
    if (green_points.size() < 50) {
        result.problem = "no boom board: " + std::to_string(green_points.size()) + " pixels at 2G - B - R >= " + std::to_string(result.green_threshold);
        return result;
    }
    result.boom_line = fit_line(green_points);
    if (result.boom_line->spread_ratio > kMaxSpreadRatio) {
        result.problem = "the green pixels do not form one board (spread across / along " +
                         std::to_string(result.boom_line->spread_ratio) + " > 0.5): crop or other green in view?";
        return result;
    }
    if (green_at_edge || red_at_edge) {
        result.problem = std::string("the ") + (green_at_edge ? "green boom" : "red nozzle") +
                         " board runs off the frame's edge (camera knocked or mounted elsewhere?)";
        return result;
    }

    // Split the red pixels into boards at the gaps between their columns.
    std::sort(red_points.begin(), red_points.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() < b.x(); });
    std::vector<std::vector<Eigen::Vector2d>> boards;
    constexpr double kGapPx = 20.0;  // boards 0.5 m apart are ~470 px apart; a board is ~50 px wide
    for (const Eigen::Vector2d& p : red_points) {
        if (boards.empty() || p.x() - boards.back().back().x() > kGapPx) boards.emplace_back();
        boards.back().push_back(p);
    }
    // Specks of noise are not boards.
    std::erase_if(boards, [](const std::vector<Eigen::Vector2d>& board) { return board.size() < 50; });
    if (boards.size() != nozzle_count) {
        result.problem = "found " + std::to_string(boards.size()) + " red nozzle boards, expected " + std::to_string(nozzle_count);
        return result;
    }
    for (const std::vector<Eigen::Vector2d>& board : boards) {
        const ImageLine line = fit_line(board);
        if (line.spread_ratio > kMaxSpreadRatio) {
            result.problem = "red pixels around column " + std::to_string(static_cast<int>(line.point.x())) +
                             " do not form one board (spread across / along " + std::to_string(line.spread_ratio) + " > 0.5)";
            return result;
        }
        const std::optional<Eigen::Vector2d> crossing = intersect(*result.boom_line, line);
        if (!crossing) {
            result.problem = "a nozzle board's line runs parallel to the boom board's";
            return result;
        }
        result.nozzle_lines.push_back(line);
        result.nozzle_pixels.push_back({crossing->x(), crossing->y()});
    }
    result.ok = true;
    return result;
}

}  // namespace rig::controller::boundary::vision
