#include "emulators/vision/camera_emulator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include "emulators/field2d/counter_hash.h"
#include "rig/camera/parameter_check.h"

namespace rig::emulators::vision {

namespace {

using rig::camera::finite_within;
using rig::camera::require_parameter;

using rig::camera::Rgb;
using rig::camera::RgbImage;
using rig::field2d::CropCoverMap;
using rig::field2d::Vec2;

// render()'s cover window: at most 24 M cells (24 MB, 4.9 x 4.9 m of ground)
// and 8000 cells a side (the fixed-point maps hold coordinates in 16 bits);
// the seed-001 view is about 3.2 x 1.7 m. A margin of 0.5 m all round lets a
// boom at 1.5 m/s keep one window for several frames (30 cm a frame at 5 fps).
constexpr std::int64_t kMaxWindowCells = 24'000'000;
constexpr std::int64_t kMaxWindowSide = 8'000;
constexpr std::int64_t kWindowMarginCells = 500;
// A map coordinate that sees no ground is clamped here (relative to the boom
// centre's cell), so it stays a finite 16-bit number after the window's offset.
constexpr float kFarCells = 16'000.0F;
static_assert(kFarCells < 32'768.0F && kMaxWindowSide + 2 * 64 < 32'768, "rows and the bits' row length fit 16 bits (sample_row_nearest)");
// Rows of samples render() works through at a time: 2^16 samples, a band that
// stays in cache and that OpenCV does on the calling thread (it splits a call
// into stripes of 2^16 pixels; one stripe runs where it was called).
constexpr int kBandSamples = 1 << 16;
// Noise: a frame's window into the table starts at one of 256 x 256 shifts.
constexpr int kNoiseShifts = 256;
// Colour and noise are summed in 1/64 DN and rounded once, as a sensor's ADC
// sees light plus noise: rounding the lit colour on its own first would shift
// a colour by up to half a DN everywhere (the low-sun leaf's ExG of 42 sits
// at the controller's floor of 40, where that shows).
constexpr double kSubDn = 64.0;

// A lit colour in 1/64 DN. Above 511 DN (the most 16 bits hold) it is held
// at 511: noise (at most 3.47 x 50 DN) cannot bring it below 255 there, so
// the frame still reads 255, as it would unheld; and the sum saturates at
// 32767 (511.98 DN), which reads 255 too.
std::int16_t sub_dn(double dn) { return static_cast<std::int16_t>(std::lround(std::clamp(dn, 0.0, 511.0) * kSubDn)); }

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

void require_boom_height(const std::string& name, const BoomPose& pose) {
    if (finite_within(pose.boom_height_m, 1e-9, 5.0)) return;
    std::ostringstream message;
    message << name << ": boom height " << pose.boom_height_m << " m is outside (0, 5] m";
    throw std::invalid_argument(message.str());
}

// What a dead camera delivers: nothing, or a black frame.
std::optional<RgbImage> dead_camera_frame(DeadCamera dead, int width, int height) {
    if (dead == DeadCamera::no_frame) return std::nullopt;
    return RgbImage(width, height);
}

// The scene's colours as the camera sees them under the light and cast.
struct LitColours {
    double red_gain;
    double green_gain;
    double blue_gain;
};

LitColours lit_colours(const CameraEmulatorParams& params) {
    const double gain = params.lighting_gain;
    return LitColours{gain * params.lighting_cast.red * params.faults.colour_cast.red,
                      gain * params.lighting_cast.green * params.faults.colour_cast.green,
                      gain * params.lighting_cast.blue * params.faults.colour_cast.blue};
}


// The colour table's entry for pixels whose rays miss the ground.
constexpr int kSkyEntry = 256;

// The block of the crop truth a one-sample frame's samples read, a bit a
// cell (CropCoverMap::copy_cell_bits), from the view's first cell: cell
// (col, row) of the view, 0 <= col < cols and 0 <= row < rows_held, is bit
// row * bits_per_row + first_col + col counted from `words` (bit k of a word
// is its k-th); bit zero_bit is in a word of soil past the window.
struct CoverBitsView {
    const std::uint64_t* words = nullptr;
    int bits_per_row = 0;
    int first_col = 0;
    int cols = 0;
    int rows_held = 0;
    int zero_bit = 0;
};

// A bit of the view as a cover byte: 0 or kPlantCell (the byte copy_cells() has there).
std::uint8_t cover_of_bit(const std::uint64_t* words, int bit) {
    static_assert(CropCoverMap::kPlantCell == 255, "a plant bit reads as all eight bits set");
    const auto at = static_cast<unsigned>(bit);
    return static_cast<std::uint8_t>(0U - static_cast<unsigned>((words[at / 64U] >> (at % 64U)) & 1U));
}

// One row of one-sample pixels: each pixel centre's undistorted point
// (x, y) through the homography h (row-major) to the view's cells, and the
// cell it falls in, 0 outside the view. The arithmetic is OpenCV's
// fixed-point remap's on single-precision maps: the point in single
// precision, ((h0 x + h1 y) + h2) / depth with the depth held below the
// horizon, clamped to +-kFarCells, rounded to the nearest cell (ties to
// even, as cvRound), then the nearest cell read. The cells' bit numbers
// four pixels at a time, without a branch (a cell outside the view reads the
// soil word past it), into `bits` (width values); then the reads, none
// waiting on another.
void sample_row_nearest(const float* xs, const float* ys, int width, const float h[9], const CoverBitsView& view, int* bits,
                        std::uint8_t* out) {
    const cv::v_float32x4 h00 = cv::v_setall_f32(h[0]), h01 = cv::v_setall_f32(h[1]), h02 = cv::v_setall_f32(h[2]);
    const cv::v_float32x4 h10 = cv::v_setall_f32(h[3]), h11 = cv::v_setall_f32(h[4]), h12 = cv::v_setall_f32(h[5]);
    const cv::v_float32x4 h20 = cv::v_setall_f32(h[6]), h21 = cv::v_setall_f32(h[7]), h22 = cv::v_setall_f32(h[8]);
    const cv::v_float32x4 horizon = cv::v_setall_f32(-1e-6F);
    const cv::v_float32x4 far_low = cv::v_setall_f32(-kFarCells), far_high = cv::v_setall_f32(kFarCells);
    const cv::v_int32x4 zero = cv::v_setzero_s32();
    const cv::v_int32x4 cols_held = cv::v_setall_s32(view.cols), rows_held = cv::v_setall_s32(view.rows_held);
    // Each 32-bit lane (bits_per_row, 0) as 16-bit halves: a row (clamped to
    // +-kFarCells, so it fits 16 bits) times it is one multiply-add of halves.
    const cv::v_int16x8 bits_per_row = cv::v_reinterpret_as_s16(cv::v_setall_s32(view.bits_per_row));
    const cv::v_int32x4 first_col = cv::v_setall_s32(view.first_col);
    const cv::v_int32x4 soil_bit = cv::v_setall_s32(view.zero_bit);
    int u = 0;
    for (; u + 4 <= width; u += 4) {
        const cv::v_float32x4 x = cv::v_load(xs + u);
        const cv::v_float32x4 y = cv::v_load(ys + u);
        const cv::v_float32x4 depth = cv::v_min(h20 * x + h21 * y + h22, horizon);
        const cv::v_int32x4 col = cv::v_round(cv::v_min(cv::v_max((h00 * x + h01 * y + h02) / depth, far_low), far_high));
        const cv::v_int32x4 row = cv::v_round(cv::v_min(cv::v_max((h10 * x + h11 * y + h12) / depth, far_low), far_high));
        const cv::v_int32x4 inside = (col >= zero) & (col < cols_held) & (row >= zero) & (row < rows_held);
        const cv::v_int32x4 row_start = cv::v_dotprod(cv::v_reinterpret_as_s16(row), bits_per_row);
        cv::v_store(bits + u, cv::v_select(inside, row_start + first_col + col, soil_bit));
    }
    for (; u < width; ++u) {
        const float depth = std::min(h[6] * xs[u] + h[7] * ys[u] + h[8], -1e-6F);
        const int col = cvRound(std::min(std::max((h[0] * xs[u] + h[1] * ys[u] + h[2]) / depth, -kFarCells), kFarCells));
        const int row = cvRound(std::min(std::max((h[3] * xs[u] + h[4] * ys[u] + h[5]) / depth, -kFarCells), kFarCells));
        const bool inside = static_cast<unsigned>(col) < static_cast<unsigned>(view.cols) &&
                            static_cast<unsigned>(row) < static_cast<unsigned>(view.rows_held);
        bits[u] = inside ? row * view.bits_per_row + view.first_col + col : view.zero_bit;
    }
    for (u = 0; u < width; ++u) out[u] = cover_of_bit(view.words, bits[u]);
}

// One row of the frame from its pixels' cover (0 soil .. 255 plant): each
// pixel's colour from the table (sky where `sky` is set), plus its noise (if
// any), both in 1/64 DN and summed saturating at 16 bits, then rounded to a
// DN (ties to even) and clipped to 0-255. `lit` holds 3 x width + 1 values.
// With `two_levels` every cover is 0 or 255 (one sample a pixel) and the
// colours are picked eight pixels at a time.
void colour_row(const std::uint8_t* cover, const std::uint8_t* sky, const std::int16_t* table, const std::int16_t* noise, int width,
                bool two_levels, std::int16_t* lit, std::uint8_t* out) {
    int lit_pixels = 0;
    if (two_levels) {
        auto channel = [table](int entry, int c) { return cv::v_setall_u16(static_cast<std::uint16_t>(table[4 * entry + c])); };
        const cv::v_uint16x8 soil[3] = {channel(0, 0), channel(0, 1), channel(0, 2)};
        const cv::v_uint16x8 plant[3] = {channel(255, 0), channel(255, 1), channel(255, 2)};
        const cv::v_uint16x8 sky_colour[3] = {channel(kSkyEntry, 0), channel(kSkyEntry, 1), channel(kSkyEntry, 2)};
        const cv::v_uint16x8 zero = cv::v_setzero_u16();
        for (; lit_pixels + 8 <= width; lit_pixels += 8) {
            const cv::v_uint16x8 is_plant = cv::v_load_expand(cover + lit_pixels) != zero;
            cv::v_uint16x8 rgb[3];
            for (int c = 0; c < 3; ++c) rgb[c] = cv::v_select(is_plant, plant[c], soil[c]);
            if (sky != nullptr) {
                const cv::v_uint16x8 is_sky = cv::v_load_expand(sky + lit_pixels) != zero;
                for (int c = 0; c < 3; ++c) rgb[c] = cv::v_select(is_sky, sky_colour[c], rgb[c]);
            }
            // The table's values are 0..32767: the same bits as int16.
            cv::v_store_interleave(reinterpret_cast<std::uint16_t*>(lit + 3 * lit_pixels), rgb[0], rgb[1], rgb[2]);
        }
    }
    for (int u = lit_pixels; u < width; ++u) {
        const int entry = sky != nullptr && sky[u] != 0 ? kSkyEntry : cover[u];
        std::memcpy(lit + 3 * u, table + 4 * entry, 4 * sizeof(std::int16_t));  // the fourth is overwritten by the next pixel
    }
    const int values = 3 * width;
    const cv::v_int16x8 low_bits = cv::v_setall_s16(63);
    const cv::v_int16x8 half = cv::v_setall_s16(32);
    const cv::v_int16x8 one = cv::v_setall_s16(1);
    auto to_dn = [&](cv::v_int16x8 sub) {
        // sub / 64 rounded half to even: the floor, plus one above half or at half with an odd floor.
        const cv::v_int16x8 whole = sub >> 6;
        const cv::v_int16x8 rest = sub & low_bits;
        const cv::v_int16x8 up = (rest > half) | ((rest == half) & ((whole & one) == one));
        return whole - up;  // up is -1 (all bits) where it rounds up
    };
    int i = 0;
    for (; i + 16 <= values; i += 16) {
        cv::v_int16x8 a = cv::v_load(lit + i);
        cv::v_int16x8 b = cv::v_load(lit + i + 8);
        if (noise != nullptr) {
            a = a + cv::v_load(noise + i);  // saturating, as cv::add on 16-bit values
            b = b + cv::v_load(noise + i + 8);
        }
        cv::v_store(out + i, cv::v_pack_u(to_dn(a), to_dn(b)));  // clipped to 0-255
    }
    for (; i < values; ++i) {
        const int sum = lit[i] + (noise != nullptr ? noise[i] : 0);
        const int sub = std::clamp(sum, -32768, 32767);
        int dn = sub >> 6;
        const int rest = sub & 63;
        if (rest > 32 || (rest == 32 && (dn & 1) != 0)) ++dn;
        out[i] = static_cast<std::uint8_t>(std::clamp(dn, 0, 255));
    }
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

std::shared_ptr<const CameraEmulator::CornerRays> CameraEmulator::corner_rays_of(const rig::camera::PinholeCamera& camera) {
    // The lens, exactly: a table is reused only for the same numbers, so a
    // frame's bytes never depend on which camera built it.
    const rig::camera::CameraIntrinsics& k = camera.model().intrinsics;
    const rig::camera::BrownConradyDistortion& distortion = camera.model().distortion;
    const std::array<double, 11> lens{static_cast<double>(k.width_px), static_cast<double>(k.height_px), k.fx_px, k.fy_px,
                                      k.cx_px, k.cy_px, distortion.k1, distortion.k2, distortion.k3, distortion.p1,
                                      distortion.p2};
    // The last few lenses built (a table is 16 MB at 1280 x 720); cases built
    // at once on several threads wait for one another here, not for long.
    static std::mutex mutex;
    static std::vector<std::pair<std::array<double, 11>, std::shared_ptr<const CornerRays>>> built;
    constexpr std::size_t kLensesKept = 2;
    const std::lock_guard lock(mutex);
    for (const auto& [key, table] : built) {
        if (std::memcmp(key.data(), lens.data(), sizeof lens) == 0) return table;
    }
    auto table = std::make_shared<CornerRays>();
    const int width = k.width_px;
    const int height = k.height_px;
    table->ray.resize(static_cast<std::size_t>(width + 1) * static_cast<std::size_t>(height + 1));
    table->valid.resize(table->ray.size(), 0);
    for (int v = 0; v <= height; ++v) {
        for (int u = 0; u <= width; ++u) {
            const std::size_t i = static_cast<std::size_t>(v) * static_cast<std::size_t>(width + 1) + static_cast<std::size_t>(u);
            const auto normalized =
                rig::camera::undistort_normalized(distortion, camera.pixel_to_distorted_normalized(Eigen::Vector2d(u, v)));
            if (!normalized) continue;
            table->ray[i] = *normalized;
            table->valid[i] = 1;
        }
    }
    if (built.size() == kLensesKept) built.erase(built.begin());
    built.emplace_back(lens, table);
    return table;
}

CameraEmulator::CameraEmulator(CameraEmulatorParams params, std::uint64_t seed, std::uint64_t stream, std::string name)
    : params_((validate(params, name), std::move(params))),
      noise_key_(rig::field2d::hash_key(seed, 0xca3e7a00ULL, stream)),
      name_(std::move(name)),
      camera_(with_pitch_fault(params_.camera, params_.faults.pitch_offset_deg), name_) {
    const int width = camera_.width_px();
    const int height = camera_.height_px();
    corner_rays_ = corner_rays_of(camera_);
    const std::vector<Eigen::Vector2d>& rays = corner_rays_->ray;
    const std::vector<std::uint8_t>& ray_valid = corner_rays_->valid;

    // render()'s fixed part. The boom frame is level, so which corner rays
    // meet the ground depends on the mounting alone, not on the pose.
    const Eigen::Matrix3d& axes = camera_.axes_in_boom();
    corner_x_.assign(rays.size(), 0.0F);
    corner_y_.assign(rays.size(), 0.0F);
    std::vector<std::uint8_t> corner_hits(rays.size(), 0);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (ray_valid[i] == 0) continue;
        const double down = axes.row(2).dot(Eigen::Vector3d(rays[i].x(), rays[i].y(), 1.0));
        if (down >= -1e-9) continue;  // at or above the horizon, as render_scene() has it
        corner_x_[i] = static_cast<float>(rays[i].x());
        corner_y_[i] = static_cast<float>(rays[i].y());
        corner_hits[i] = 1;
    }
    const std::size_t stride = static_cast<std::size_t>(width) + 1U;
    if (params_.samples_per_axis == 1) {
        // One sample a pixel, at its centre (the mean of its corners, as n x n has it).
        centre_x_.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
        centre_y_.resize(centre_x_.size());
        for (int v = 0; v < height; ++v) {
            for (int u = 0; u < width; ++u) {
                const std::size_t i00 = static_cast<std::size_t>(v) * stride + static_cast<std::size_t>(u);
                const std::size_t pixel = static_cast<std::size_t>(v) * static_cast<std::size_t>(width) + static_cast<std::size_t>(u);
                const float top_x = corner_x_[i00] + 0.5F * (corner_x_[i00 + 1] - corner_x_[i00]);
                const float bottom_x = corner_x_[i00 + stride] + 0.5F * (corner_x_[i00 + stride + 1] - corner_x_[i00 + stride]);
                const float top_y = corner_y_[i00] + 0.5F * (corner_y_[i00 + 1] - corner_y_[i00]);
                const float bottom_y = corner_y_[i00 + stride] + 0.5F * (corner_y_[i00 + stride + 1] - corner_y_[i00 + stride]);
                centre_x_[pixel] = top_x + 0.5F * (bottom_x - top_x);
                centre_y_[pixel] = top_y + 0.5F * (bottom_y - top_y);
            }
        }
    }
    sky_pixels_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0);
    for (int v = 0; v < height; ++v) {
        for (int u = 0; u < width; ++u) {
            const std::size_t i00 = static_cast<std::size_t>(v) * stride + static_cast<std::size_t>(u);
            if (corner_hits[i00] && corner_hits[i00 + 1] && corner_hits[i00 + stride] && corner_hits[i00 + stride + 1]) continue;
            sky_pixels_[static_cast<std::size_t>(v) * static_cast<std::size_t>(width) + static_cast<std::size_t>(u)] = 255;
            any_sky_ = true;
        }
    }
    auto sees_ground = [&](int u, int v) {
        return u >= 0 && v >= 0 && u < width && v < height &&
               sky_pixels_[static_cast<std::size_t>(v) * static_cast<std::size_t>(width) + static_cast<std::size_t>(u)] == 0;
    };
    for (int v = 0; v <= height; ++v) {
        for (int u = 0; u <= width; ++u) {
            const int touching_ground = sees_ground(u - 1, v - 1) + sees_ground(u, v - 1) + sees_ground(u - 1, v) + sees_ground(u, v);
            if (touching_ground > 0 && touching_ground < 4) {
                outline_corners_.push_back(static_cast<std::size_t>(v) * stride + static_cast<std::size_t>(u));
            }
        }
    }

    if (params_.noise_sd_dn > 0.0) {
        const std::size_t table_values =
            3U * static_cast<std::size_t>(width + kNoiseShifts - 1) * static_cast<std::size_t>(height + kNoiseShifts - 1);
        noise_.resize(table_values);
        const std::uint64_t table_key = rig::field2d::hash_finalise(noise_key_ ^ 0x7ab1e000ULL);
        for (std::size_t i = 0; i < table_values; ++i) {
            const double draw = params_.noise_sd_dn * unit_noise(rig::field2d::hash_finalise(table_key + i));
            noise_[i] = static_cast<std::int16_t>(std::lround(draw * kSubDn));
        }
    }
}

Eigen::Matrix3d CameraEmulator::normalized_to_ground_cells(const BoomPose& pose, double east_origin, double north_origin) const {
    // A ray d = axes (x, y, 1) from the camera at p meets the ground z = -h at
    // p + (drop / d_z) d, drop = -h - p_z: in the boom frame, homogeneously,
    // (p_x d_z + drop d_x, p_y d_z + drop d_y, d_z), linear in (x, y, 1).
    const Eigen::Matrix3d& axes = camera_.axes_in_boom();
    const Eigen::Vector3d& position = camera_.position_in_boom();
    const double drop = -pose.boom_height_m - position.z();
    Eigen::Matrix3d boom_ground;
    boom_ground.row(0) = drop * axes.row(0) + position.x() * axes.row(2);
    boom_ground.row(1) = drop * axes.row(1) + position.y() * axes.row(2);
    boom_ground.row(2) = axes.row(2);
    // Boom frame to the truth's cells (field2d::body_to_field, over kCellM,
    // less half a cell: cell i's centre sits at i).
    const Vec2 right = rig::field2d::right_of(pose.heading_deg);
    const Vec2 forward = rig::field2d::forward_of(pose.heading_deg);
    const double per_cell = 1.0 / CropCoverMap::kCellM;
    Eigen::Matrix3d to_cells;
    to_cells << right.east_m * per_cell, forward.east_m * per_cell, pose.boom_centre_ground.east_m * per_cell - 0.5 - east_origin,
        right.north_m * per_cell, forward.north_m * per_cell, pose.boom_centre_ground.north_m * per_cell - 0.5 - north_origin,
        0.0, 0.0, 1.0;
    return to_cells * boom_ground;
}

void CameraEmulator::hold_cells(const CropCoverMap& crop, std::int64_t east_first, std::int64_t east_last, std::int64_t north_first,
                                std::int64_t north_last, CellForm form) const {
    CoverWindow& w = window_;
    if (w.crop_identity == crop.identity() && w.form == form && east_first >= w.east_cell && north_first >= w.north_cell &&
        east_last < w.east_cell + w.cols && north_last < w.north_cell + w.rows) {
        return;
    }
    const std::int64_t cols = east_last - east_first + 1;
    const std::int64_t rows = north_last - north_first + 1;
    std::int64_t margin = kWindowMarginCells;
    while (margin > 0 && ((cols + 2 * margin) * (rows + 2 * margin) > kMaxWindowCells || cols + 2 * margin > kMaxWindowSide ||
                          rows + 2 * margin > kMaxWindowSide)) {
        margin /= 2;
    }
    w.crop_identity = 0;  // holds nothing until the copy below has finished
    w.form = form;
    w.north_cell = north_first - margin;
    w.rows = static_cast<int>(rows + 2 * margin);
    if (form == CellForm::bytes) {
        w.east_cell = east_first - margin;
        w.cols = static_cast<int>(cols + 2 * margin);
        w.cells.resize(static_cast<std::size_t>(w.cols) * static_cast<std::size_t>(w.rows));
        crop.copy_cells(w.east_cell, w.north_cell, w.cols, w.rows, w.cells.data(), static_cast<std::size_t>(w.cols));
    } else {
        // Whole words from a multiple of 64 cells (copy_cell_bits' words start there).
        constexpr std::int64_t word = CropCoverMap::kCellsPerWord;
        const std::int64_t east_low = east_first - margin;
        w.east_cell = (east_low >= 0 ? east_low : east_low - (word - 1)) / word * word;
        const std::int64_t words = (east_last + margin + 1 - w.east_cell + word - 1) / word;
        w.cols = static_cast<int>(words * word);
        w.bits.assign(static_cast<std::size_t>(words) * static_cast<std::size_t>(w.rows) + 1U, 0);  // + a soil word past the last row
        crop.copy_cell_bits(w.east_cell, w.north_cell, static_cast<int>(words), w.rows, w.bits.data(), static_cast<std::size_t>(words));
    }
    w.crop_identity = crop.identity();
}

std::optional<Vec2> CameraEmulator::ground_seen(const BoomPose& pose, double u, double v) const {
    const std::optional<Eigen::Vector2d> boom_xy = camera_.pixel_to_plane(Eigen::Vector2d(u, v), -pose.boom_height_m);
    if (!boom_xy) return std::nullopt;
    return rig::field2d::body_to_field(pose.boom_centre_ground, pose.heading_deg, boom_xy->x(), boom_xy->y());
}

std::optional<RgbImage> CameraEmulator::render(const CropCoverMap& crop, const BoomPose& pose, std::uint64_t frame_index) const {
    require_boom_height(name_, pose);
    if (!(std::abs(pose.boom_centre_ground.east_m) < 1e6 && std::abs(pose.boom_centre_ground.north_m) < 1e6)) {
        std::ostringstream message;
        message << name_ << ": boom centre (" << pose.boom_centre_ground.east_m << ", " << pose.boom_centre_ground.north_m
                << ") m is not a ground point within 1000 km of the origin";
        throw std::invalid_argument(message.str());
    }
    const CameraFaults& faults = params_.faults;
    const int width = camera_.width_px();
    const int height = camera_.height_px();
    if (faults.dead != DeadCamera::none) return dead_camera_frame(faults.dead, width, height);
    RgbImage image(width, height);

    // The view's extent in cells, from its outline: a homography maps the
    // inside of a closed curve inside the curve's image (all corners on the
    // ground side of the horizon), and a sample is a convex mix of its
    // pixel's corners. Around the boom centre's cell first, for small numbers.
    const double per_cell = 1.0 / CropCoverMap::kCellM;
    const double centre_east = std::floor(pose.boom_centre_ground.east_m * per_cell);
    const double centre_north = std::floor(pose.boom_centre_ground.north_m * per_cell);
    const Eigen::Matrix3d around_centre = normalized_to_ground_cells(pose, centre_east, centre_north);
    double east_min = std::numeric_limits<double>::infinity();
    double east_max = -east_min;
    double north_min = east_min;
    double north_max = -east_min;
    for (const std::size_t i : outline_corners_) {
        const Eigen::Vector3d p = around_centre * Eigen::Vector3d(corner_x_[i], corner_y_[i], 1.0);
        east_min = std::min(east_min, p.x() / p.z());
        east_max = std::max(east_max, p.x() / p.z());
        north_min = std::min(north_min, p.y() / p.z());
        north_max = std::max(north_max, p.y() / p.z());
    }
    const bool sees_ground = !outline_corners_.empty();
    // The cells a bilinear sample may read (its cell and the next, and a cell
    // more each way for single-precision rounding of the samples' positions).
    double view_east = 0.0;
    double view_north = 0.0;
    if (sees_ground) {
        const double cols = std::floor(east_max) - std::floor(east_min) + 4.0;
        const double rows = std::floor(north_max) - std::floor(north_min) + 4.0;
        if (!(cols <= static_cast<double>(kMaxWindowSide) && rows <= static_cast<double>(kMaxWindowSide) &&
              cols * rows <= static_cast<double>(kMaxWindowCells))) {
            return render_scene(crop, pose, nullptr, nullptr, frame_index);  // a view reaching far: the exact path
        }
        view_east = centre_east + std::floor(east_min) - 1.0;
        view_north = centre_north + std::floor(north_min) - 1.0;
        hold_cells(crop, static_cast<std::int64_t>(view_east), static_cast<std::int64_t>(view_east + cols - 1.0),
                   static_cast<std::int64_t>(view_north), static_cast<std::int64_t>(view_north + rows - 1.0),
                   params_.samples_per_axis == 1 ? CellForm::bits : CellForm::bytes);
    }
    // The maps count from the view's first cell, a function of the pose alone:
    // a frame's bytes do not depend on where the window happens to lie.
    const Eigen::Matrix3d to_view = normalized_to_ground_cells(pose, view_east, view_north);
    const Eigen::Matrix3f h = to_view.cast<float>();

    // Colour by cover (0 soil .. 255 plant) under this camera's light, and
    // sky (entry kSkyEntry), four 1/64 DN values an entry (the fourth unused).
    const LitColours light = lit_colours(params_);
    std::array<std::int16_t, 4 * (kSkyEntry + 1)> colour_table{};
    for (int cover = 0; cover < 256; ++cover) {
        const double plant_share = cover / 255.0;
        const Rgb soil = params_.soil_rgb;
        const Rgb plant = params_.plant_rgb;
        std::int16_t* entry = colour_table.data() + 4 * cover;
        entry[0] = sub_dn((soil.r + plant_share * (plant.r - soil.r)) * light.red_gain);
        entry[1] = sub_dn((soil.g + plant_share * (plant.g - soil.g)) * light.green_gain);
        entry[2] = sub_dn((soil.b + plant_share * (plant.b - soil.b)) * light.blue_gain);
    }
    std::int16_t* sky_entry = colour_table.data() + 4 * kSkyEntry;
    sky_entry[0] = sub_dn(params_.sky_rgb.r * light.red_gain);
    sky_entry[1] = sub_dn(params_.sky_rgb.g * light.green_gain);
    sky_entry[2] = sub_dn(params_.sky_rgb.b * light.blue_gain);

    // This frame's window into the noise table.
    const std::uint64_t frame_key = rig::field2d::hash_finalise(noise_key_ ^ rig::field2d::hash_finalise(frame_index));
    const int noise_u = static_cast<int>(frame_key % kNoiseShifts);
    const int noise_v = static_cast<int>((frame_key >> 32) % kNoiseShifts);
    const std::size_t noise_row_values = 3U * static_cast<std::size_t>(width + kNoiseShifts - 1);
    // The maps count from the view's first cell: the samples read the window from there.
    CoverBitsView bits_view;
    cv::Mat view_mat;
    if (sees_ground) {
        const auto first_col = static_cast<std::size_t>(static_cast<std::int64_t>(view_east) - window_.east_cell);
        const auto first_row = static_cast<std::size_t>(static_cast<std::int64_t>(view_north) - window_.north_cell);
        const int view_cols = window_.cols - static_cast<int>(first_col);
        const int view_rows = window_.rows - static_cast<int>(first_row);
        if (window_.form == CellForm::bits) {
            // Bit numbers fit an int: the window holds at most kMaxWindowCells cells (and a word a row).
            const auto words_per_row = static_cast<std::size_t>(window_.cols / CropCoverMap::kCellsPerWord);
            bits_view.words = window_.bits.data() + first_row * words_per_row;
            bits_view.bits_per_row = window_.cols;
            bits_view.first_col = static_cast<int>(first_col);
            bits_view.cols = view_cols;
            bits_view.rows_held = view_rows;
            bits_view.zero_bit = view_rows * window_.cols;  // the soil word after the window's last row
        } else {
            // A header over the window, only read (OpenCV has no const Mat over const data).
            view_mat = cv::Mat(view_rows, view_cols, CV_8UC1, window_.cells.data() + first_row * static_cast<std::size_t>(window_.cols) + first_col,
                               static_cast<std::size_t>(window_.cols));
        }
    }

    const int n = params_.samples_per_axis;
    const auto pixels_per_row = static_cast<std::size_t>(width);
    std::vector<std::uint8_t> cover_row(pixels_per_row);
    std::vector<std::int16_t> lit_row(3 * pixels_per_row + 1);  // + 1: each pixel's colour is copied as four values
    auto finish_row = [&](int v, const std::uint8_t* cover) {
        const std::uint8_t* sky = any_sky_ ? sky_pixels_.data() + static_cast<std::size_t>(v) * pixels_per_row : nullptr;
        const std::int16_t* noise =
            noise_.empty() ? nullptr
                           : noise_.data() + static_cast<std::size_t>(noise_v + v) * noise_row_values + 3U * static_cast<std::size_t>(noise_u);
        colour_row(cover, sky, colour_table.data(), noise, width, n == 1, lit_row.data(),
                   image.bytes.data() + static_cast<std::size_t>(v) * 3U * pixels_per_row);
    };
    if (!sees_ground) {
        std::fill(cover_row.begin(), cover_row.end(), std::uint8_t{0});
        for (int v = 0; v < height; ++v) finish_row(v, cover_row.data());
    } else if (n == 1) {
        const float h_rows[9] = {h(0, 0), h(0, 1), h(0, 2), h(1, 0), h(1, 1), h(1, 2), h(2, 0), h(2, 1), h(2, 2)};
        std::vector<int> bit_row(pixels_per_row);
        for (int v = 0; v < height; ++v) {
            const std::size_t first = static_cast<std::size_t>(v) * pixels_per_row;
            sample_row_nearest(centre_x_.data() + first, centre_y_.data() + first, width, h_rows, bits_view, bit_row.data(), cover_row.data());
            finish_row(v, cover_row.data());
        }
    } else {
        render_cover_bands(h, view_mat, [&](int v0, const cv::Mat& cover) {
            for (int r = 0; r < cover.rows; ++r) finish_row(v0 + r, cover.ptr<std::uint8_t>(r));
        });
    }
    if (faults.blur_radius_px > 0) box_blur(image, faults.blur_radius_px);
    return image;
}
void CameraEmulator::render_cover_bands(const Eigen::Matrix3f& h, const cv::Mat& view,
                                        const std::function<void(int, const cv::Mat&)>& each_band) const {
    const int width = camera_.width_px();
    const int height = camera_.height_px();
    const int n = params_.samples_per_axis;
    const int band_rows = std::max(1, kBandSamples / (width * n * n));
    const std::size_t stride = static_cast<std::size_t>(width) + 1U;
    cv::Mat map_x(band_rows * n, width * n, CV_32FC1);
    cv::Mat map_y(band_rows * n, width * n, CV_32FC1);
    cv::Mat fixed_xy;
    cv::Mat samples;
    cv::Mat cover;
    Eigen::ArrayXf row_x(width + 1);
    Eigen::ArrayXf row_y(width + 1);
    Eigen::ArrayXf sample_x(width);
    Eigen::ArrayXf sample_y(width);
    Eigen::ArrayXf depth(width);
    Eigen::ArrayXf seen_x(width);
    Eigen::ArrayXf seen_y(width);
    using Row = Eigen::Map<const Eigen::ArrayXf>;
    using Strided = Eigen::Map<Eigen::ArrayXf, 0, Eigen::InnerStride<>>;
    for (int v0 = 0; v0 < height; v0 += band_rows) {
        const int rows = std::min(band_rows, height - v0);
        const int sample_rows = rows * n;
        for (int sample_row = 0; sample_row < sample_rows; ++sample_row) {
            const auto v = static_cast<std::size_t>(v0 + sample_row / n);
            const float down = (static_cast<float>(sample_row % n) + 0.5F) / static_cast<float>(n);
            const Row top_x(corner_x_.data() + v * stride, width + 1);
            const Row top_y(corner_y_.data() + v * stride, width + 1);
            const Row bottom_x(corner_x_.data() + (v + 1) * stride, width + 1);
            const Row bottom_y(corner_y_.data() + (v + 1) * stride, width + 1);
            row_x = top_x + down * (bottom_x - top_x);
            row_y = top_y + down * (bottom_y - top_y);
            for (int sample_col = 0; sample_col < n; ++sample_col) {
                const float across = (static_cast<float>(sample_col) + 0.5F) / static_cast<float>(n);
                sample_x = row_x.head(width) + across * (row_x.tail(width) - row_x.head(width));
                sample_y = row_y.head(width) + across * (row_y.tail(width) - row_y.head(width));
                // Below the horizon the depth is negative; a sky pixel's
                // samples are pushed far off the window (it is painted sky).
                depth = (h(2, 0) * sample_x + h(2, 1) * sample_y + h(2, 2)).min(-1e-6F);
                seen_x = ((h(0, 0) * sample_x + h(0, 1) * sample_y + h(0, 2)) / depth).max(-kFarCells).min(kFarCells);
                seen_y = ((h(1, 0) * sample_x + h(1, 1) * sample_y + h(1, 2)) / depth).max(-kFarCells).min(kFarCells);
                Strided(map_x.ptr<float>(sample_row) + sample_col, width, Eigen::InnerStride<>(n)) = seen_x;
                Strided(map_y.ptr<float>(sample_row) + sample_col, width, Eigen::InnerStride<>(n)) = seen_y;
            }
        }
        // Each sample reads the truth cell it falls in (the nearest cell
        // centre), as render_scene's samples do: a pixel's mix at a leaf
        // edge comes from its n x n samples, not from blurring the truth.
        cv::convertMaps(map_x.rowRange(0, sample_rows), map_y.rowRange(0, sample_rows), fixed_xy, cv::noArray(), CV_16SC2, true);
        cv::remap(view, samples, fixed_xy, cv::noArray(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
        cv::resize(samples, cover, cv::Size(width, rows), 0.0, 0.0, cv::INTER_AREA);  // the mean of n x n
        each_band(v0, cover);
    }
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
    require_boom_height(name_, pose);
    const CameraFaults& faults = params_.faults;
    const int width = camera_.width_px();
    const int height = camera_.height_px();
    if (faults.dead != DeadCamera::none) return dead_camera_frame(faults.dead, width, height);
    RgbImage image(width, height);

    // Each corner ray met with the ground (z = -h in the boom frame), as
    // east/north offsets from the boom centre's ground point (and, for a
    // ground overlay, in boom-frame x, y), and (for a boom-plane overlay) with
    // the boom plane z = 0, in boom-frame x, y.
    const Eigen::Matrix3d& axes = camera_.axes_in_boom();
    const Eigen::Vector3d& position = camera_.position_in_boom();
    const Vec2 right_axis = rig::field2d::right_of(pose.heading_deg);
    const Vec2 forward_axis = rig::field2d::forward_of(pose.heading_deg);
    const std::vector<Eigen::Vector2d>& rays = corner_rays_->ray;
    std::vector<Vec2> corner_ground(rays.size());
    std::vector<Vec2> corner_boom_plane(boom_plane != nullptr ? rays.size() : 0);
    std::vector<Vec2> corner_ground_boom(ground != nullptr ? rays.size() : 0);
    std::vector<std::uint8_t> corner_hits(rays.size(), 0);
    const double drop = -pose.boom_height_m - position.z();
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (corner_rays_->valid[i] == 0) continue;
        const Eigen::Vector3d direction = axes * Eigen::Vector3d(rays[i].x(), rays[i].y(), 1.0);
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

    const LitColours light = lit_colours(params_);
    const double red_gain = light.red_gain;
    const double green_gain = light.green_gain;
    const double blue_gain = light.blue_gain;
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
    const int window = 2 * radius_px + 1;
    const cv::Mat source(image.height, image.width, CV_8UC3, image.bytes.data());
    cv::Mat blurred;
    cv::blur(source, blurred, cv::Size(window, window), cv::Point(-1, -1), cv::BORDER_REPLICATE);
    std::copy(blurred.datastart, blurred.dataend, image.bytes.begin());
}

}  // namespace rig::emulators::vision
