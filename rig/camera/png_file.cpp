#include "rig/camera/png_file.h"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace rig::camera {

// libpng 1.6's simplified API (png_image): no error callbacks or longjmp to
// cross C++ frames; a failure comes back as a return value and a message.

void write_png(const std::string& path, const RgbImage& image) {
    if (image.width <= 0 || image.height <= 0 ||
        image.bytes.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3U) {
        throw std::invalid_argument("png " + path + ": image " + std::to_string(image.width) + " x " + std::to_string(image.height) +
                                    " with " + std::to_string(image.bytes.size()) + " bytes is not a whole RGB frame");
    }
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(image.width);
    png.height = static_cast<png_uint_32>(image.height);
    png.format = PNG_FORMAT_RGB;
    // Speed over size: a camera frame's noise leaves zlib little to find, so its
    // default effort bought a file only 12 % smaller, at a cost the vision
    // cases' wall time showed (two frames per case, for its report;
    // docs/seed001-vision.md, "Start-up and the report's frames").
    png.flags = PNG_IMAGE_FLAG_FAST;
    if (png_image_write_to_file(&png, path.c_str(), 0, image.bytes.data(), 0, nullptr) == 0) {
        const std::string message = png.message;
        png_image_free(&png);
        throw std::runtime_error("png " + path + ": " + message);
    }
}

RgbImage read_png(const std::string& path) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    if (png_image_begin_read_from_file(&png, path.c_str()) == 0) {
        const std::string message = png.message;
        png_image_free(&png);
        throw std::runtime_error("png " + path + ": " + message);
    }
    if (png.width == 0 || png.height == 0 || png.width > 16384 || png.height > 16384) {
        const std::string size = std::to_string(png.width) + " x " + std::to_string(png.height);
        png_image_free(&png);
        throw std::runtime_error("png " + path + ": " + size + " is not a frame this rig reads");
    }
    // Whatever the file holds (palette, grey, 16-bit, alpha), libpng converts it
    // to 8-bit RGB, alpha composed over black.
    png.format = PNG_FORMAT_RGB;
    RgbImage image(static_cast<int>(png.width), static_cast<int>(png.height));
    const png_color black{0, 0, 0};
    if (png_image_finish_read(&png, &black, image.bytes.data(), 0, nullptr) == 0) {
        const std::string message = png.message;
        png_image_free(&png);
        throw std::runtime_error("png " + path + ": " + message);
    }
    return image;
}

void draw_line(RgbImage& image, const Eigen::Vector2d& a, const Eigen::Vector2d& b, Rgb colour, int thickness_px) {
    if (!a.allFinite() || !b.allFinite()) return;
    const double length = (b - a).norm();
    const int steps = std::max(1, static_cast<int>(std::ceil(length * 2.0)));
    const int half = std::max(0, thickness_px / 2);
    for (int s = 0; s <= steps; ++s) {
        const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(s) / steps);
        const int u0 = static_cast<int>(std::floor(p.x()));
        const int v0 = static_cast<int>(std::floor(p.y()));
        for (int dv = -half; dv <= half; ++dv) {
            for (int du = -half; du <= half; ++du) {
                const int u = u0 + du;
                const int v = v0 + dv;
                if (u >= 0 && v >= 0 && u < image.width && v < image.height) image.set(u, v, colour);
            }
        }
    }
}

void draw_quad(RgbImage& image, const std::array<Eigen::Vector2d, 4>& corners, Rgb colour, int thickness_px) {
    for (std::size_t i = 0; i < 4; ++i) draw_line(image, corners[i], corners[(i + 1) % 4], colour, thickness_px);
}

}  // namespace rig::camera
