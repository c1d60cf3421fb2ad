#include "controller/boundary/vision/chessboard_calibration.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>

#include "controller/boundary/vision/image_ops.h"

namespace rig::controller::boundary::vision {

namespace {

// The ChESS ring: 16 samples at radius 5 px, every 22.5 deg.
constexpr int kRingRadius = 5;
constexpr std::array<std::array<int, 2>, 16> kRing{{{5, 0}, {5, 2}, {4, 4}, {2, 5}, {0, 5}, {-2, 5}, {-4, 4}, {-5, 2},
                                                    {-5, 0}, {-5, -2}, {-4, -4}, {-2, -5}, {0, -5}, {2, -5}, {4, -4}, {5, -2}}};
// A corner must be the largest response within this many px either way.
constexpr int kSuppressRadius = 4;
// ... and at least this share of the frame's strongest, and this strong
// outright: a corner between squares 20 DN apart gives about 4 x 2 x 20 = 160,
// a board's (~200 DN apart) about 1600, sensor noise (~3.5 DN grey) tens.
constexpr double kResponseShare = 0.3;
constexpr float kMinResponse = 160.0F;
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
template <int N>
std::pair<Eigen::Matrix<double, N, 1>, double> centroid_and_spread(const std::vector<Eigen::Matrix<double, N, 1>>& points) {
    Eigen::Matrix<double, N, 1> centroid = Eigen::Matrix<double, N, 1>::Zero();
    for (const auto& p : points) centroid += p;
    centroid /= static_cast<double>(points.size());
    double mean_distance = 0.0;
    for (const auto& p : points) mean_distance += (p - centroid).norm();
    return {centroid, mean_distance / static_cast<double>(points.size())};
}

// Hartley's normalisation: centroid to the origin, mean distance sqrt(2).
Eigen::Matrix3d normalising(const std::vector<Eigen::Vector2d>& points) {
    const auto [centroid, mean_distance] = centroid_and_spread(points);
    const double scale = mean_distance > 0.0 ? std::sqrt(2.0) / mean_distance : 1.0;
    Eigen::Matrix3d t;
    t << scale, 0.0, -scale * centroid.x(), 0.0, scale, -scale * centroid.y(), 0.0, 0.0, 1.0;
    return t;
}

}  // namespace

Eigen::Matrix3d fit_homography(const std::vector<Eigen::Vector2d>& from, const std::vector<Eigen::Vector2d>& to) {
    if (from.size() != to.size() || from.size() < 4) {
        throw std::invalid_argument("fit_homography: needs 4 or more point pairs, got " + std::to_string(from.size()) + " and " +
                                    std::to_string(to.size()));
    }
    const Eigen::Matrix3d t_from = normalising(from);
    const Eigen::Matrix3d t_to = normalising(to);
    Eigen::MatrixXd a(2 * from.size(), 9);
    for (std::size_t i = 0; i < from.size(); ++i) {
        const Eigen::Vector2d p = apply(t_from, from[i]);
        const Eigen::Vector2d q = apply(t_to, to[i]);
        const auto r = static_cast<Eigen::Index>(2 * i);
        a.row(r) << p.x(), p.y(), 1.0, 0.0, 0.0, 0.0, -q.x() * p.x(), -q.x() * p.y(), -q.x();
        a.row(r + 1) << 0.0, 0.0, 0.0, p.x(), p.y(), 1.0, -q.y() * p.x(), -q.y() * p.y(), -q.y();
    }
    const Eigen::VectorXd h = null_vector(a, "fit_homography: degenerate points (collinear or repeated)");
    Eigen::Matrix3d normalised;
    normalised << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
    Eigen::Matrix3d result = t_to.inverse() * normalised * t_from;
    if (std::abs(result(2, 2)) > 1e-12) result /= result(2, 2);
    return result;
}

ChessboardView find_chessboard(const rig::camera::RgbImage& frame, const rig::camera::PinholeCamera& model,
                               const ChessboardPlacement& placement) {
    ChessboardView view;
    if (const auto problem = rig::camera::frame_size_problem(frame, model.model().intrinsics)) {
        view.problem = *problem;
        return view;
    }
    if (placement.inner_cols < 2 || placement.inner_rows < 2 || !(placement.square_m > 0.0)) {
        view.problem = "chessboard placement: needs 2 x 2 or more inner corners and a square > 0";
        return view;
    }
    const int width = frame.width;
    const int height = frame.height;
    std::vector<float> grey(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
    for (std::size_t i = 0; i < grey.size(); ++i) {
        grey[i] = static_cast<float>(frame.bytes[3 * i] + frame.bytes[3 * i + 1] + frame.bytes[3 * i + 2]) / 3.0F;
    }
    auto at = [&](int u, int v) { return grey[static_cast<std::size_t>(v) * static_cast<std::size_t>(width) + static_cast<std::size_t>(u)]; };

    // The ChESS response of every pixel far enough from the border.
    std::vector<float> response(grey.size(), 0.0F);
    float strongest = 0.0F;
    for (int v = kRingRadius + 1; v < height - kRingRadius - 1; ++v) {
        for (int u = kRingRadius + 1; u < width - kRingRadius - 1; ++u) {
            std::array<float, 16> ring;
            float ring_sum = 0.0F;
            for (std::size_t n = 0; n < 16; ++n) {
                ring[n] = at(u + kRing[n][0], v + kRing[n][1]);
                ring_sum += ring[n];
            }
            float sum_response = 0.0F;
            for (std::size_t n = 0; n < 4; ++n) sum_response += std::abs(ring[n] + ring[n + 8] - ring[n + 4] - ring[n + 12]);
            float diff_response = 0.0F;
            for (std::size_t n = 0; n < 8; ++n) diff_response += std::abs(ring[n] - ring[n + 8]);
            float local = 0.0F;
            for (int dv = -1; dv <= 1; ++dv) {
                for (int du = -1; du <= 1; ++du) local += at(u + du, v + dv);
            }
            const float mean_response = std::abs(ring_sum / 16.0F - local / 9.0F);
            const float r = sum_response - diff_response - 16.0F * mean_response;
            response[static_cast<std::size_t>(v) * static_cast<std::size_t>(width) + static_cast<std::size_t>(u)] = r;
            strongest = std::max(strongest, r);
        }
    }
    if (strongest <= 0.0F) {
        view.problem = "no chessboard corner in the frame";
        return view;
    }
    auto response_at = [&](int u, int v) {
        return response[static_cast<std::size_t>(v) * static_cast<std::size_t>(width) + static_cast<std::size_t>(u)];
    };

    // A saddle point to sub-pixel precision (Foerstner's corner operator): at
    // the true corner p every grey-level gradient g(q) in the window is
    // perpendicular to q - p, so p solves sum(g g^T) p = sum(g g^T q).
    auto refine_saddle = [&](Eigen::Vector2d p) {
        constexpr int kHalf = 4;
        for (int step = 0; step < 5; ++step) {
            const int cu = static_cast<int>(std::floor(p.x()));
            const int cv = static_cast<int>(std::floor(p.y()));
            Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
            Eigen::Vector2d right = Eigen::Vector2d::Zero();
            for (int dv = -kHalf; dv <= kHalf; ++dv) {
                for (int du = -kHalf; du <= kHalf; ++du) {
                    const int qu = cu + du;
                    const int qv = cv + dv;
                    if (qu < 1 || qv < 1 || qu >= width - 1 || qv >= height - 1) continue;
                    const Eigen::Vector2d g(0.5 * (at(qu + 1, qv) - at(qu - 1, qv)), 0.5 * (at(qu, qv + 1) - at(qu, qv - 1)));
                    const Eigen::Matrix2d gg = g * g.transpose();
                    normal += gg;
                    right += gg * Eigen::Vector2d(qu + 0.5, qv + 0.5);
                }
            }
            if (std::abs(normal.determinant()) < 1e-6) break;
            const Eigen::Vector2d next = normal.inverse() * right;
            if ((next - p).norm() > 3.0) break;  // left the corner: keep the last estimate
            const bool settled = (next - p).norm() < 0.01;
            p = next;
            if (settled) break;
        }
        return p;
    };

    // Local maxima above a share of the strongest, refined to the saddle.
    struct Candidate {
        Eigen::Vector2d undistorted;
        float strength;
    };
    std::vector<Candidate> candidates;
    const float floor = std::max(kMinResponse, static_cast<float>(kResponseShare) * strongest);
    const int margin = kRingRadius + 1 + kSuppressRadius;
    for (int v = margin; v < height - margin; ++v) {
        for (int u = margin; u < width - margin; ++u) {
            const float r = response_at(u, v);
            if (r < floor) continue;
            bool is_max = true;
            for (int dv = -kSuppressRadius; dv <= kSuppressRadius && is_max; ++dv) {
                for (int du = -kSuppressRadius; du <= kSuppressRadius; ++du) {
                    if (du == 0 && dv == 0) continue;
                    const float other = response_at(u + du, v + dv);
                    // Ties go to the first in raster order.
                    if (other > r || (other == r && (dv < 0 || (dv == 0 && du < 0)))) {
                        is_max = false;
                        break;
                    }
                }
            }
            if (!is_max) continue;
            const Eigen::Vector2d refined = refine_saddle(Eigen::Vector2d(u + 0.5, v + 0.5));
            const auto normalized = rig::camera::undistort_normalized(model.model().distortion, model.pixel_to_distorted_normalized(refined));
            if (!normalized) continue;
            candidates.push_back({model.undistorted_pixel(*normalized), r});
        }
    }
    const std::size_t expected = static_cast<std::size_t>(placement.inner_cols) * static_cast<std::size_t>(placement.inner_rows);
    if (candidates.size() < expected) {
        view.problem = "found " + std::to_string(candidates.size()) + " chessboard corners, expected " + std::to_string(expected);
        return view;
    }

    // The grid's four extreme corners: (0, 0) nearest-left (smallest u - v),
    // (cols-1, 0) nearest-right (largest u + v), (cols-1, rows-1) farthest-
    // right (largest u - v), (0, rows-1) farthest-left (smallest u + v).
    auto extreme = [&](auto key) {
        return std::max_element(candidates.begin(), candidates.end(), [&](const Candidate& a, const Candidate& b) { return key(a) < key(b); })
            ->undistorted;
    };
    const double cols = placement.inner_cols - 1;
    const double rows = placement.inner_rows - 1;
    const std::array<Eigen::Vector2d, 4> grid_corners{Eigen::Vector2d(0, 0), Eigen::Vector2d(cols, 0), Eigen::Vector2d(cols, rows),
                                                      Eigen::Vector2d(0, rows)};
    const std::array<Eigen::Vector2d, 4> image_corners{
        extreme([](const Candidate& c) { return c.undistorted.y() - c.undistorted.x(); }),
        extreme([](const Candidate& c) { return c.undistorted.x() + c.undistorted.y(); }),
        extreme([](const Candidate& c) { return c.undistorted.x() - c.undistorted.y(); }),
        extreme([](const Candidate& c) { return -c.undistorted.x() - c.undistorted.y(); })};
    Eigen::Matrix3d grid_to_pixel;
    try {
        grid_to_pixel = perspective_transform(grid_corners, image_corners);
    } catch (const std::invalid_argument&) {
        view.problem = "the chessboard corners found do not span a grid";
        return view;
    }
    // Every grid corner matched to the nearest candidate within a third of a square.
    std::vector<Eigen::Vector2d> plane_points;
    std::vector<Eigen::Vector2d> image_points;
    std::vector<bool> used(candidates.size(), false);
    for (int j = 0; j < placement.inner_rows; ++j) {
        for (int i = 0; i < placement.inner_cols; ++i) {
            const Eigen::Vector2d predicted = apply(grid_to_pixel, Eigen::Vector2d(i, j));
            const double square_px = (apply(grid_to_pixel, Eigen::Vector2d(i + 1, j)) - predicted).norm();
            std::size_t best = candidates.size();
            double best_distance = square_px / 3.0;
            for (std::size_t c = 0; c < candidates.size(); ++c) {
                const double d = (candidates[c].undistorted - predicted).norm();
                if (!used[c] && d < best_distance) {
                    best = c;
                    best_distance = d;
                }
            }
            if (best == candidates.size()) {
                view.problem = "chessboard corner (" + std::to_string(i) + ", " + std::to_string(j) + ") not found near (" +
                               std::to_string(predicted.x()) + ", " + std::to_string(predicted.y()) + ") px";
                return view;
            }
            used[best] = true;
            view.corners_px.push_back(candidates[best].undistorted);
            plane_points.emplace_back(placement.origin_right_m + i * placement.square_m, placement.origin_ahead_m + j * placement.square_m);
            image_points.push_back(candidates[best].undistorted);
        }
    }
    view.plane_to_pixel = fit_homography(plane_points, image_points);
    double squared = 0.0;
    for (std::size_t n = 0; n < plane_points.size(); ++n) squared += (apply(view.plane_to_pixel, plane_points[n]) - image_points[n]).squaredNorm();
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
