#pragma once
// RGB frames to and from PNG files (libpng), and the outlines drawn on them:
// what a report shows of a camera frame (the ROIs the controller used, drawn
// over what the camera saw).
#include <array>
#include <string>

#include <Eigen/Dense>

#include "rig/camera/rgb_image.h"

namespace rig::camera {

// 8-bit RGB, no interlace. Throws std::runtime_error naming the path when the
// file cannot be written, std::invalid_argument for an empty or inconsistent image.
void write_png(const std::string& path, const RgbImage& image);
// Any PNG libpng reads, converted to 8-bit RGB (palette, grey, 16-bit and
// alpha are expanded or composed over black). Throws std::runtime_error
// naming the path and libpng's complaint.
RgbImage read_png(const std::string& path);

// A straight line from a to b (continuous pixel coordinates), `thickness_px`
// wide, clipped to the image; non-finite ends draw nothing.
void draw_line(RgbImage& image, const Eigen::Vector2d& a, const Eigen::Vector2d& b, Rgb colour, int thickness_px = 2);
// The closed outline through four corners (e.g. a ROI's image_px).
void draw_quad(RgbImage& image, const std::array<Eigen::Vector2d, 4>& corners, Rgb colour, int thickness_px = 2);

}  // namespace rig::camera
