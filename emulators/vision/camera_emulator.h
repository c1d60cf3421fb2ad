#pragma once
// Seed 001's boom cameras (Sec. 1.1: two SY002HD cameras about 1.30 m apart,
// 1.0 m above the boom, pitched about 25 deg forward, three nozzles each) as
// renderers: an RGB frame of the ground the camera sees, from the crop truth
// (emulators/field2d/crop_cover_map.h) through the camera's true intrinsics,
// lens distortion and mounting (rig/camera/pinhole_camera.h) at the live boom
// height. No DDS: a plain class the harness or a test drives.
//
// A pixel's colour is the soil / plant mix of its footprint (n x n samples of
// the crop truth inside the pixel), times the lighting and colour cast, plus
// seeded noise per channel, clipped to 0-255. The boom and nozzles are not
// drawn: they sit below the ROIs in the image (the nozzles at row ~665, Eq.
// 1-4's ~661, against the ROIs' rows 355-575 with the defaults) and nothing
// measures them in a working frame; render_calibration() draws Sec. 2.2.1's boards.
//
// How render() does it (docs/seed001-vision.md, "Rendering"): the ground is a
// plane, so a sample's undistorted image point maps to the ground by a
// homography that the live boom pose sets; the lens distortion is fixed, its
// inverse computed once per camera at the pixel corners. Per frame the two
// compose into a per-sample map into a cover image (a block of the crop
// truth's 1 mm raster, plant 255, soil 0, kept while the view stays inside
// it), each sample the cell it falls in (OpenCV's fixed-point remap, nearest
// cell; at one sample a pixel the same arithmetic in one pass a row). n x n
// samples average to the pixel (area resize), so a pixel straddling a leaf
// edge is mixed. Colour is a per-frame table from cover to RGB; the noise a
// shifted window of a seeded per-camera table (a frame's shift hashed from
// its index); the two summed in 1/64 DN and rounded in one pass a row. After
// the map it is integer arithmetic, and the map single-precision IEEE
// arithmetic rounded to a cell, so a frame's bytes are a function of the
// case, seed, pose and frame index alone, whatever the machine or the order
// frames are rendered in.
// Views reaching far (the window would exceed 24 M cells, e.g. a camera pitched
// near the horizon) and the calibration scenes (boards, chessboards: a few
// frames a run) take the exact per-sample path instead: corner rays through
// the planes, each sample a look-up of the truth.
//
// Named faults, ArduPilot SITL style (each off at its default):
//   pitch_offset_deg  the camera knocked off the pitch it was calibrated at
//   blur_radius_px    a dirty lens: box blur of this radius (kernel 2r + 1)
//   colour_cast       a low sun: per-channel gains on top of the lighting
//   dead              black_frame (a sensor that delivers zeros) or no_frame
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "emulators/field2d/crop_cover_map.h"
#include "emulators/field2d/sprayer_kinematics.h"
#include "emulators/field2d/vec2.h"
#include "rig/camera/pinhole_camera.h"
#include "rig/camera/rgb_image.h"

namespace cv {
class Mat;
}  // namespace cv

namespace rig::emulators::vision {

struct ChannelGains {
    double red = 1.0;    // [0, 4]
    double green = 1.0;  // [0, 4]
    double blue = 1.0;   // [0, 4]
};

enum class DeadCamera { none, black_frame, no_frame };

struct CameraFaults {
    double pitch_offset_deg = 0.0;  // [-30, 30] deg, added to the true pitch (the controller keeps its calibration)
    int blur_radius_px = 0;         // [0, 50] px
    ChannelGains colour_cast;       // low sun: e.g. 1.35 / 1.0 / 0.65 (assumed: warm, blue-poor light)
    DeadCamera dead = DeadCamera::none;
};

struct CameraEmulatorParams {
    rig::camera::CameraModel camera;  // the camera's truth
    // Colours under the reference light (assumed: a dry yellow-brown loess
    // soil, ExG = 2G - R - B = -4; a seedling-wheat green, ExG = 152).
    rig::camera::Rgb soil_rgb{128, 102, 80};
    rig::camera::Rgb plant_rgb{64, 128, 40};
    rig::camera::Rgb sky_rgb{170, 190, 215};  // pixels whose ray misses the ground (only with large pitch)
    double noise_sd_dn = 6.0;        // [0, 50] DN per channel (assumed: a small CMOS sensor in daylight)
    double lighting_gain = 1.0;      // [0, 4]: overall light (overcast < 1 < bright sun)
    ChannelGains lighting_cast;      // [0, 4] each: the light's colour (white at 1 / 1 / 1)
    int samples_per_axis = 2;        // [1, 8]: a pixel's footprint sampled n x n (mixed pixels at leaf edges)
    double frame_rate_hz = 30.0;     // (0, 120]; S7 assumed; the renderer does not use it, the harness paces frames by it
    CameraFaults faults;
};

// Throws std::invalid_argument "<where>.<field>: <what>".
void validate(const CameraEmulatorParams& params, const std::string& where);

// Sec. 2.2.1's calibration scene (Fig. 5, 6): a green board on the boom and a
// red board over each nozzle, all in the boom plane, seen over the ground.
// The paper gives the boards' sizes; where they sit is assumed: the green
// board centred on the boom line (so the line fitted along it is the boom's),
// each red board lengthwise along the travel direction centred over its
// nozzle's line and clear of the green board (so the two fitted lines cross
// at the nozzle).
struct CalibrationBoards {
    double boom_board_length_m = 0.300;    // along the boom; Sec. 2.2.1
    double boom_board_width_m = 0.090;     // Sec. 2.2.1
    double boom_board_right_m = 0.0;       // its centre, m right of the boom centre (a camera's view: its own x)
    double nozzle_board_length_m = 0.190;  // along travel; Sec. 2.2.1
    double nozzle_board_width_m = 0.050;   // Sec. 2.2.1
    double nozzle_board_ahead_m = 0.150;   // centre ahead of the boom line (assumed: 10 mm clear of the green board)
    std::vector<double> nozzle_right_m;    // one board per nozzle, m right of the boom centre
    rig::camera::Rgb green{40, 150, 60};   // assumed board colours
    rig::camera::Rgb red{190, 40, 40};
};

// A chessboard for the camera's extrinsic calibration (Sec. 2.2.2: "place a
// chessboard on the boom plane" for Eq. 5's homography; a second on the
// ground for Eq. 6). Squares alternate black and white, the square whose
// corner is `origin` (inner corner (0, 0)) lying diagonally right-ahead of it
// black; inner corners (i, j) at origin + (i, j) x square_m, i along x
// (right), j along y (ahead), 0 <= i < inner_cols, 0 <= j < inner_rows; a
// white margin one square wide all round (so the board's outline gives no
// X-shaped corner). Sizes assumed (the paper gives none).
struct Chessboard {
    int inner_cols = 7;                   // [2, 50]
    int inner_rows = 5;                   // [2, 50]
    double square_m = 0.040;              // [0.005, 0.5] m
    double origin_right_m = 0.0;          // inner corner (0, 0): m right of the boom centre
    double origin_ahead_m = 0.05;         // ... and ahead of the boom line
    bool on_ground = false;               // false: in the boom plane; true: on the ground under it
    rig::camera::Rgb black{25, 25, 25};
    rig::camera::Rgb white{225, 225, 225};
};

// Where the boom is (plant truth, e.g. from field2d::SprayerTruth): the ground
// point under the boom centre, the heading the boom faces, the boom height.
struct BoomPose {
    rig::field2d::Vec2 boom_centre_ground;
    double heading_deg = 0.0;     // compass, the travel direction
    double boom_height_m = 0.5;   // (0, 5]; Sec. 5.1: 0.5 m
};

// The boom pose of the 2-D plant's truth at some time.
BoomPose boom_pose_of(const rig::field2d::SprayerTruth& truth);

class CameraEmulator {
public:
    // `stream` tells apart the noise of cameras sharing a seed (0 left, 1 right).
    // Throws std::invalid_argument for bad parameters.
    CameraEmulator(CameraEmulatorParams params, std::uint64_t seed, std::uint64_t stream, std::string name = "camera");

    // The frame number `frame_index` (its noise is drawn from it) of the
    // ground at `pose`; nullopt for a dead camera that delivers no frame.
    // Throws std::invalid_argument for a bad boom height or a view reaching
    // 1000 km from the crop's origin. Keeps a block of the crop's cells between
    // calls: not safe to call from two threads at once.
    std::optional<rig::camera::RgbImage> render(const rig::field2d::CropCoverMap& crop, const BoomPose& pose,
                                                std::uint64_t frame_index) const;

    // The calibration scene over the ground at `pose` (the boards ride with the
    // boom); faults apply as to any frame. Throws std::invalid_argument for bad boards.
    std::optional<rig::camera::RgbImage> render_calibration(const rig::field2d::CropCoverMap& crop, const BoomPose& pose,
                                                            const CalibrationBoards& boards, std::uint64_t frame_index) const;

    // A chessboard over the ground at `pose` (the boom plane's rides with the
    // boom; the ground's lies under it). Throws std::invalid_argument for a bad board.
    std::optional<rig::camera::RgbImage> render_chessboard(const rig::field2d::CropCoverMap& crop, const BoomPose& pose,
                                                           const Chessboard& board, std::uint64_t frame_index) const;

    // The ground point (local east/north) the centre of pixel (u, v) sees with
    // the camera as it truly is (faults included); nullopt if it sees no ground.
    std::optional<rig::field2d::Vec2> ground_seen(const BoomPose& pose, double u, double v) const;

    // The camera as it truly is: its parameters with the pitch fault applied.
    const rig::camera::PinholeCamera& true_camera() const { return camera_; }
    const CameraEmulatorParams& params() const { return params_; }
    const std::string& name() const { return name_; }

private:
    // The homography from undistorted normalised image points (x, y, 1) to the
    // ground at `pose`, in the crop truth's cells (cell i's centre at i) less
    // (east_origin, north_origin).
    Eigen::Matrix3d normalized_to_ground_cells(const BoomPose& pose, double east_origin, double north_origin) const;
    // How the window holds the cells: a byte a cell (0 or kPlantCell, what
    // OpenCV's remap reads with n x n samples) or a bit a cell (one sample:
    // an eighth of the memory, so a frame's reads stay in cache).
    enum class CellForm { bytes, bits };
    // Refills window_ (with a margin) unless it holds cells [east_first,
    // east_last] x [north_first, north_last] of `crop` already, in `form`.
    void hold_cells(const rig::field2d::CropCoverMap& crop, std::int64_t east_first, std::int64_t east_last,
                    std::int64_t north_first, std::int64_t north_last, CellForm form) const;
    // With n x n samples a pixel (n > 1): the frame's cover (0 soil .. 255
    // plant), the mean of each pixel's samples, a band of rows at a time,
    // handed to each_band with the band's first row.
    void render_cover_bands(const Eigen::Matrix3f& h, const cv::Mat& view,
                            const std::function<void(int, const cv::Mat&)>& each_band) const;
    // What lies on a plane at boom-frame (x, y): a board's colour, or nothing.
    using PlaneOverlay = std::function<std::optional<rig::camera::Rgb>(double x_m, double y_m)>;
    std::optional<rig::camera::RgbImage> render_scene(const rig::field2d::CropCoverMap& crop, const BoomPose& pose,
                                                      const PlaneOverlay* boom_plane, const PlaneOverlay* ground,
                                                      std::uint64_t frame_index) const;
    CameraEmulatorParams params_;
    std::uint64_t noise_key_;
    std::string name_;
    rig::camera::PinholeCamera camera_;
    // Undistorted normalised rays at the pixel corners, (width + 1) x (height + 1):
    // a pixel's footprint is the ground between its four corners' rays. They
    // depend on the lens alone (intrinsics, distortion), so cameras with the
    // same lens share one table: both of a case's, and the next case's.
    struct CornerRays {
        std::vector<Eigen::Vector2d> ray;
        std::vector<std::uint8_t> valid;
    };
    static std::shared_ptr<const CornerRays> corner_rays_of(const rig::camera::PinholeCamera& camera);
    std::shared_ptr<const CornerRays> corner_rays_;
    // The same rays for render() in single precision, split by axis (zero
    // where a pixel sees no ground); the pixels whose four corner rays do not
    // all meet the ground (255: sky) and whether there are any; the corners on
    // the outline of the pixels that see ground (the view's extremes lie on it).
    std::vector<float> corner_x_;
    std::vector<float> corner_y_;
    // With one sample a pixel, its centre's undistorted point (else empty).
    std::vector<float> centre_x_;
    std::vector<float> centre_y_;
    std::vector<std::uint8_t> sky_pixels_;
    bool any_sky_ = false;
    std::vector<std::size_t> outline_corners_;
    // The noise table: N(0, noise_sd_dn) draws per channel in 1/64 DN,
    // (width + kNoiseShifts - 1) x (height + kNoiseShifts - 1) pixels; empty
    // without noise.
    std::vector<std::int16_t> noise_;
    // The block of the crop's truth render() samples.
    struct CoverWindow {
        std::uint64_t crop_identity = 0;  // 0: holds nothing
        CellForm form = CellForm::bytes;
        std::int64_t east_cell = 0;
        std::int64_t north_cell = 0;
        int cols = 0;
        int rows = 0;
        std::vector<std::uint8_t> cells;    // CellForm::bytes: cols a row
        std::vector<std::uint64_t> bits;    // CellForm::bits: cols / 64 words a row
    };
    mutable CoverWindow window_;
};

// Sec. 1.1's two cameras (left at -0.65 m, right at +0.65 m) with every other
// parameter at its default.
CameraEmulatorParams seed001_camera_params(bool right_camera);

// A box blur of radius r on each channel (kernel (2r + 1) x (2r + 1), edges
// clamped): the mean of the window, rounded.
void box_blur(rig::camera::RgbImage& image, int radius_px);

}  // namespace rig::emulators::vision
