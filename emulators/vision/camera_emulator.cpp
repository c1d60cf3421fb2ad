#include "emulators/vision/camera_emulator.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "emulators/field2d/counter_hash.h"
#include "rig/camera/parameter_check.h"

namespace rig::emulators::vision {

namespace {

using rig::camera::finite_within;
using rig::camera::require_parameter;

using rig::camera::Rgb;
using rig::camera::RgbImage;
using rig::field2d::Vec2;

void require_gains(const ChannelGains& gains, const std::string& where, const char* which) {
    const std::string prefix = where + "." + which;
    require_parameter(finite_within(gains.red, 0.0, 4.0), prefix, "red", gains.red, "[0, 4]");
    require_parameter(finite_within(gains.green, 0.0, 4.0), prefix, "green", gains.green, "[0, 4]");
    require_parameter(finite_within(gains.blue, 0.0, 4.0), prefix, "blue", gains.blue, "[0, 4]");
}

rig::camera::CameraModel with_pitch_fault(rig::camera::CameraModel model, double pitch_offset_deg) {
    model.mounting.pitch_deg += pitch_offset_deg;
    return model;
}

// Approximately N(0, 1) from one 64-bit hash: the sum of four 16-bit uniforms
// (Irwin-Hall, variance 4/12) centred and scaled. Bounded at +-3.46, which a
// sensor's clipped noise is anyway; Box-Muller per channel would triple the
// frame's cost for a tail nobody measures.
double unit_noise(std::uint64_t bits) {
    double sum = 0.0;
    for (int i = 0; i < 4; ++i) sum += static_cast<double>((bits >> (16 * i)) & 0xffffU) * (1.0 / 65536.0);
    return (sum - 2.0) * 1.7320508075688772;  // sqrt(3)
}

// Rounded to the nearest byte and clipped (half away from zero, as lround;
// written out because lround is a libm call and this runs three times a pixel).
std::uint8_t to_byte(double value) {
    if (!(value > 0.0)) return 0;
    if (value >= 255.0) return 255;
    return static_cast<std::uint8_t>(value + 0.5);
}

}  // namespace

void validate(const CameraEmulatorParams& p, const std::string& where) {
    rig::camera::validate(p.camera, where + ".camera");
    require_parameter(finite_within(p.noise_sd_dn, 0.0, 50.0), where, "noise_sd_dn", p.noise_sd_dn, "[0, 50] DN");
    require_parameter(finite_within(p.lighting_gain, 0.0, 4.0), where, "lighting_gain", p.lighting_gain, "[0, 4]");
    require_gains(p.lighting_cast, where, "lighting_cast");
    require_parameter(p.samples_per_axis >= 1 && p.samples_per_axis <= 8, where, "samples_per_axis", p.samples_per_axis, "[1, 8]");
    require_parameter(finite_within(p.frame_rate_hz, 1e-9, 120.0), where, "frame_rate_hz", p.frame_rate_hz, "(0, 120] Hz");
    require_parameter(finite_within(p.faults.pitch_offset_deg, -30.0, 30.0), where, "faults.pitch_offset_deg", p.faults.pitch_offset_deg, "[-30, 30] deg");
    require_parameter(p.faults.blur_radius_px >= 0 && p.faults.blur_radius_px <= 50, where, "faults.blur_radius_px", p.faults.blur_radius_px, "[0, 50] px");
    require_gains(p.faults.colour_cast, where, "faults.colour_cast");
    // The knocked camera must still be a camera the model can hold.
    rig::camera::validate(with_pitch_fault(p.camera, p.faults.pitch_offset_deg), where + ".camera (with faults.pitch_offset_deg)");
}

BoomPose boom_pose_of(const rig::field2d::SprayerTruth& truth) {
    return BoomPose{truth.boom_centre, truth.pose.heading_deg, truth.boom_height_m};
}

CameraEmulatorParams seed001_camera_params(bool right_camera) {
    CameraEmulatorParams params;
    params.camera = rig::camera::seed001_boom_camera(right_camera);
    return params;
}

CameraEmulator::CameraEmulator(CameraEmulatorParams params, std::uint64_t seed, std::uint64_t stream, std::string name)
    : params_((validate(params, name), std::move(params))),
      noise_key_(rig::field2d::hash_key(seed, 0xca3e7a00ULL, stream)),
      name_(std::move(name)),
      camera_(with_pitch_fault(params_.camera, params_.faults.pitch_offset_deg), name_) {
    const int width = camera_.width_px();
    const int height = camera_.height_px();
    corner_rays_.resize(static_cast<std::size_t>(width + 1) * static_cast<std::size_t>(height + 1));
    corner_ray_valid_.resize(corner_rays_.size(), 0);
    for (int v = 0; v <= height; ++v) {
        for (int u = 0; u <= width; ++u) {
            const std::size_t i = static_cast<std::size_t>(v) * static_cast<std::size_t>(width + 1) + static_cast<std::size_t>(u);
            const auto normalized = rig::camera::undistort_normalized(
                params_.camera.distortion, camera_.pixel_to_distorted_normalized(Eigen::Vector2d(u, v)));
            if (!normalized) continue;
            corner_rays_[i] = *normalized;
            corner_ray_valid_[i] = 1;
        }
    }
}

std::optional<Vec2> CameraEmulator::ground_seen(const BoomPose& pose, double u, double v) const {
    const std::optional<Eigen::Vector2d> boom_xy = camera_.pixel_to_plane(Eigen::Vector2d(u, v), -pose.boom_height_m);
    if (!boom_xy) return std::nullopt;
    return rig::field2d::body_to_field(pose.boom_centre_ground, pose.heading_deg, boom_xy->x(), boom_xy->y());
}

std::optional<RgbImage> CameraEmulator::render(const rig::field2d::CropCoverMap& crop, const BoomPose& pose,
                                               std::uint64_t frame_index) const {
    return render_scene(crop, pose, nullptr, nullptr, frame_index);
}

namespace {

// The board (if any) at a boom-plane point, as its colour.
std::optional<Rgb> board_at(const CalibrationBoards& boards, double x, double y) {
    if (std::abs(x - boards.boom_board_right_m) <= 0.5 * boards.boom_board_length_m && std::abs(y) <= 0.5 * boards.boom_board_width_m) {
        return boards.green;
    }
    for (const double nozzle_x : boards.nozzle_right_m) {
        if (std::abs(x - nozzle_x) <= 0.5 * boards.nozzle_board_width_m &&
            std::abs(y - boards.nozzle_board_ahead_m) <= 0.5 * boards.nozzle_board_length_m) {
            return boards.red;
        }
    }
    return std::nullopt;
}

}  // namespace

std::optional<RgbImage> CameraEmulator::render_calibration(const rig::field2d::CropCoverMap& crop, const BoomPose& pose,
                                                           const CalibrationBoards& boards, std::uint64_t frame_index) const {
    const std::string where = name_ + ".calibration_boards";
    require_parameter(finite_within(boards.boom_board_length_m, 1e-3, 5.0), where, "boom_board_length_m", boards.boom_board_length_m, "[0.001, 5] m");
    require_parameter(finite_within(boards.boom_board_width_m, 1e-3, 1.0), where, "boom_board_width_m", boards.boom_board_width_m, "[0.001, 1] m");
    require_parameter(finite_within(boards.boom_board_right_m, -10.0, 10.0), where, "boom_board_right_m", boards.boom_board_right_m, "[-10, 10] m");
    require_parameter(finite_within(boards.nozzle_board_length_m, 1e-3, 1.0), where, "nozzle_board_length_m", boards.nozzle_board_length_m, "[0.001, 1] m");
    require_parameter(finite_within(boards.nozzle_board_width_m, 1e-3, 1.0), where, "nozzle_board_width_m", boards.nozzle_board_width_m, "[0.001, 1] m");
    require_parameter(finite_within(boards.nozzle_board_ahead_m, -2.0, 2.0), where, "nozzle_board_ahead_m", boards.nozzle_board_ahead_m, "[-2, 2] m");
    for (const double x : boards.nozzle_right_m) require_parameter(finite_within(x, -10.0, 10.0), where, "nozzle_right_m[]", x, "[-10, 10] m");
    const PlaneOverlay on_boom_plane = [&boards](double x, double y) { return board_at(boards, x, y); };
    return render_scene(crop, pose, &on_boom_plane, nullptr, frame_index);
}

std::optional<RgbImage> CameraEmulator::render_chessboard(const rig::field2d::CropCoverMap& crop, const BoomPose& pose,
                                                          const Chessboard& board, std::uint64_t frame_index) const {
    const std::string where = name_ + ".chessboard";
    require_parameter(board.inner_cols >= 2 && board.inner_cols <= 50, where, "inner_cols", board.inner_cols, "[2, 50]");
    require_parameter(board.inner_rows >= 2 && board.inner_rows <= 50, where, "inner_rows", board.inner_rows, "[2, 50]");
    require_parameter(finite_within(board.square_m, 0.005, 0.5), where, "square_m", board.square_m, "[0.005, 0.5] m");
    require_parameter(finite_within(board.origin_right_m, -10.0, 10.0), where, "origin_right_m", board.origin_right_m, "[-10, 10] m");
    require_parameter(finite_within(board.origin_ahead_m, -10.0, 10.0), where, "origin_ahead_m", board.origin_ahead_m, "[-10, 10] m");
    const PlaneOverlay squares = [&board](double x, double y) -> std::optional<Rgb> {
        // Square indices: square (0, 0) is right-ahead of inner corner (0, 0).
        const double i = std::floor((x - board.origin_right_m) / board.square_m);
        const double j = std::floor((y - board.origin_ahead_m) / board.square_m);
        // The checkered squares run -1 .. inner (one more than the inner corners each way), the margin one more.
        if (i < -2.0 || j < -2.0 || i > board.inner_cols + 0.0 || j > board.inner_rows + 0.0) return std::nullopt;
        if (i < -1.0 || j < -1.0 || i > board.inner_cols - 1.0 || j > board.inner_rows - 1.0) return board.white;
        const bool black = (static_cast<long>(i) + static_cast<long>(j)) % 2 == 0;
        return black ? board.black : board.white;
    };
    return board.on_ground ? render_scene(crop, pose, nullptr, &squares, frame_index)
                           : render_scene(crop, pose, &squares, nullptr, frame_index);
}


std::optional<RgbImage> CameraEmulator::render_scene(const rig::field2d::CropCoverMap& crop, const BoomPose& pose,
                                                     const PlaneOverlay* boom_plane, const PlaneOverlay* ground,
                                                     std::uint64_t frame_index) const {
    if (!finite_within(pose.boom_height_m, 1e-9, 5.0)) {
        std::ostringstream message;
        message << name_ << ": boom height " << pose.boom_height_m << " m is outside (0, 5] m";
        throw std::invalid_argument(message.str());
    }
    const CameraFaults& faults = params_.faults;
    if (faults.dead == DeadCamera::no_frame) return std::nullopt;
    const int width = camera_.width_px();
    const int height = camera_.height_px();
    RgbImage image(width, height);
    if (faults.dead == DeadCamera::black_frame) return image;

    // Each corner ray met with the ground (z = -h in the boom frame), as
    // east/north offsets from the boom centre's ground point (and, for a
    // ground overlay, in boom-frame x, y), and (for a boom-plane overlay) with
    // the boom plane z = 0, in boom-frame x, y.
    const Eigen::Matrix3d& axes = camera_.axes_in_boom();
    const Eigen::Vector3d& position = camera_.position_in_boom();
    const Vec2 right_axis = rig::field2d::right_of(pose.heading_deg);
    const Vec2 forward_axis = rig::field2d::forward_of(pose.heading_deg);
    std::vector<Vec2> corner_ground(corner_rays_.size());
    std::vector<Vec2> corner_boom_plane(boom_plane != nullptr ? corner_rays_.size() : 0);
    std::vector<Vec2> corner_ground_boom(ground != nullptr ? corner_rays_.size() : 0);
    std::vector<std::uint8_t> corner_hits(corner_rays_.size(), 0);
    const double drop = -pose.boom_height_m - position.z();
    for (std::size_t i = 0; i < corner_rays_.size(); ++i) {
        if (corner_ray_valid_[i] == 0) continue;
        const Eigen::Vector3d direction = axes * Eigen::Vector3d(corner_rays_[i].x(), corner_rays_[i].y(), 1.0);
        if (direction.z() >= -1e-9) continue;  // at or above the horizon
        const double scale = drop / direction.z();
        const double x = position.x() + scale * direction.x();
        const double y = position.y() + scale * direction.y();
        corner_ground[i] = x * right_axis + y * forward_axis;
        if (ground != nullptr) corner_ground_boom[i] = Vec2{x, y};
        if (boom_plane != nullptr) {
            const double to_boom_plane = -position.z() / direction.z();
            corner_boom_plane[i] = Vec2{position.x() + to_boom_plane * direction.x(), position.y() + to_boom_plane * direction.y()};
        }
        corner_hits[i] = 1;
    }

    const double gain = params_.lighting_gain;
    const double red_gain = gain * params_.lighting_cast.red * faults.colour_cast.red;
    const double green_gain = gain * params_.lighting_cast.green * faults.colour_cast.green;
    const double blue_gain = gain * params_.lighting_cast.blue * faults.colour_cast.blue;
    const Rgb soil = params_.soil_rgb;
    const Rgb plant = params_.plant_rgb;
    const Rgb sky = params_.sky_rgb;
    const int n = params_.samples_per_axis;
    const double per_sample = 1.0 / (n * n);
    const double noise_sd = params_.noise_sd_dn;
    const std::size_t stride = static_cast<std::size_t>(width) + 1U;
    const std::uint64_t frame_key = rig::field2d::hash_finalise(noise_key_ ^ rig::field2d::hash_finalise(frame_index));
    // Bilinear between a pixel's four corners: its footprint on a plane is
    // nearly a parallelogram.
    auto inside_pixel = [](const std::vector<Vec2>& corners, std::size_t i00, std::size_t i10, std::size_t i01, std::size_t i11,
                           double fx, double fy) {
        const Vec2 top = corners[i00] + fx * (corners[i10] - corners[i00]);
        const Vec2 bottom = corners[i01] + fx * (corners[i11] - corners[i01]);
        return top + fy * (bottom - top);
    };

    for (int v = 0; v < height; ++v) {
        for (int u = 0; u < width; ++u) {
            const std::size_t i00 = static_cast<std::size_t>(v) * stride + static_cast<std::size_t>(u);
            const std::size_t i10 = i00 + 1;
            const std::size_t i01 = i00 + stride;
            const std::size_t i11 = i01 + 1;
            double r = 0.0;
            double g = 0.0;
            double b = 0.0;
            if (corner_hits[i00] && corner_hits[i10] && corner_hits[i01] && corner_hits[i11]) {
                for (int sy = 0; sy < n; ++sy) {
                    const double fy = (sy + 0.5) / n;
                    for (int sx = 0; sx < n; ++sx) {
                        const double fx = (sx + 0.5) / n;
                        Rgb seen = soil;
                        std::optional<Rgb> board;
                        if (boom_plane != nullptr) {
                            const Vec2 at = inside_pixel(corner_boom_plane, i00, i10, i01, i11, fx, fy);
                            board = (*boom_plane)(at.east_m, at.north_m);  // boom-frame x, y in a Vec2
                        }
                        if (!board && ground != nullptr) {
                            const Vec2 at = inside_pixel(corner_ground_boom, i00, i10, i01, i11, fx, fy);
                            board = (*ground)(at.east_m, at.north_m);
                        }
                        if (board) {
                            seen = *board;  // a board in the boom plane is nearer than the ground; one on the ground covers it
                        } else if (crop.is_plant(pose.boom_centre_ground + inside_pixel(corner_ground, i00, i10, i01, i11, fx, fy))) {
                            seen = plant;
                        }
                        r += seen.r;
                        g += seen.g;
                        b += seen.b;
                    }
                }
                r *= per_sample * red_gain;
                g *= per_sample * green_gain;
                b *= per_sample * blue_gain;
            } else {
                r = sky.r * red_gain;
                g = sky.g * green_gain;
                b = sky.b * blue_gain;
            }
            if (noise_sd > 0.0) {
                const std::uint64_t pixel_key = frame_key ^ (static_cast<std::uint64_t>(v) * static_cast<std::uint64_t>(width) + static_cast<std::uint64_t>(u)) * 3U;
                r += noise_sd * unit_noise(rig::field2d::hash_finalise(pixel_key));
                g += noise_sd * unit_noise(rig::field2d::hash_finalise(pixel_key + 1U));
                b += noise_sd * unit_noise(rig::field2d::hash_finalise(pixel_key + 2U));
            }
            image.set(u, v, Rgb{to_byte(r), to_byte(g), to_byte(b)});
        }
    }
    if (faults.blur_radius_px > 0) box_blur(image, faults.blur_radius_px);
    return image;
}

void box_blur(RgbImage& image, int radius_px) {
    if (radius_px <= 0 || image.width <= 0 || image.height <= 0) return;
    const int width = image.width;
    const int height = image.height;
    const int window = 2 * radius_px + 1;
    std::vector<std::uint8_t> source = image.bytes;
    // One pass along a line of `count` pixels `step` bytes apart, from `from` into `to`.
    auto blur_line = [&](const std::vector<std::uint8_t>& from, std::vector<std::uint8_t>& to, std::size_t start,
                         std::size_t step, int count) {
        for (int channel = 0; channel < 3; ++channel) {
            auto value_at = [&](int index) {
                const int clamped = std::clamp(index, 0, count - 1);
                return static_cast<int>(from[start + static_cast<std::size_t>(clamped) * step + static_cast<std::size_t>(channel)]);
            };
            int sum = 0;
            for (int k = -radius_px; k <= radius_px; ++k) sum += value_at(k);
            for (int index = 0; index < count; ++index) {
                to[start + static_cast<std::size_t>(index) * step + static_cast<std::size_t>(channel)] =
                    static_cast<std::uint8_t>((sum + window / 2) / window);
                sum += value_at(index + radius_px + 1) - value_at(index - radius_px);
            }
        }
    };
    std::vector<std::uint8_t> across(source.size());
    for (int v = 0; v < height; ++v) blur_line(source, across, image.offset(0, v), 3U, width);
    for (int u = 0; u < width; ++u) blur_line(across, image.bytes, image.offset(u, 0), static_cast<std::size_t>(width) * 3U, height);
}

}  // namespace rig::emulators::vision
