#pragma once
// Sec. 2.2.1: the nozzle points from the calibration image (Fig. 5, 6, 8, 9).
// A green board lies along the boom, a red board over each nozzle, in the
// boom plane:
//   (1) boom board: 2G - B - R (Eq. 15's index), Otsu, a least-squares line
//       through the board's pixels (Eq. 1: z = -0.00255 i + 662.58)
//   (2) nozzle boards: 2R - G - B, Otsu, the image split so each part holds
//       one board (here: at the gaps between the red pixels' columns)
//   (3) a least-squares line per nozzle board (Eq. 2-4), crossed with the
//       boom line: the nozzle points, e.g. (107.2, 662.3), (579.6, 661.1),
//       (1044.4, 659.9) px in the paper
// The paper undistorts the image first; here each selected pixel's centre is
// undistorted instead (cv::undistortPoints: the same points, without
// resampling the frame). Otsu is OpenCV's (image_ops.h). The
// lines are total least squares (the principal axis of the pixels), not
// z = a i + b: a nozzle board's line is nearly vertical in the image (Eq. 3's
// slope is -50), where fitting z on i is ill-conditioned.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "controller/boundary/vision/nozzle_vision.h"
#include "rig/camera/pinhole_camera.h"
#include "rig/camera/rgb_image.h"

namespace rig::controller::boundary::vision {

struct ImageLine {
    Eigen::Vector2d point;      // the pixels' centroid (undistorted image)
    Eigen::Vector2d direction;  // unit
    long pixels = 0;
    // The pixels' spread across the line over their spread along it (SDs): a
    // board's is about its width over its length (0.3 for both boards, 90 /
    // 300 and 50 / 190 mm); a scatter of plants' is near 1.
    double spread_ratio = 0.0;
};

struct NozzleCalibration {
    bool ok = false;
    std::string problem;                   // why not, when !ok
    int green_threshold = 0;               // used on 2G - B - R
    int red_threshold = 0;                 // used on 2R - G - B
    std::optional<ImageLine> boom_line;
    std::vector<ImageLine> nozzle_lines;   // left to right
    std::vector<PixelPoint> nozzle_pixels; // left to right, undistorted image: VisionCameraConfig::nozzle_pixels
};

// `model`: the camera's intrinsics and distortion (its mounting is not used).
// `colour_floor`: the least index counted as board whatever Otsu finds
// (assumed 60: boards are saturated colours, index ~150, soil ~0).
// Never throws for what the image holds: a frame without the boards, with a
// board cut by the frame's edge, with another number of red boards than
// `nozzle_count`, or with green or red pixels that do not form a board
// (spread ratio above 0.5: a crop in view; the paper calibrates on a
// platform, Fig. 5) gives ok = false and says why.
NozzleCalibration find_nozzle_points(const rig::camera::RgbImage& frame, const rig::camera::PinholeCamera& model,
                                     std::size_t nozzle_count, int colour_floor = 60);

}  // namespace rig::controller::boundary::vision
