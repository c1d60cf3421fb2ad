#pragma once
// An 8-bit RGB frame, row-major, 3 bytes per pixel (R, G, B), no padding: the
// layout a V4L2 / libcamera RGB24 buffer has, and what the camera emulators
// render and the seed-001 controller's vision reads.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace rig::camera {

struct Rgb {
    std::uint8_t r = 0;
    std::uint8_t g = 0;
    std::uint8_t b = 0;
};

struct RgbImage {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> bytes;  // width * height * 3

    RgbImage() = default;
    RgbImage(int width_px, int height_px)
        : width(width_px), height(height_px),
          bytes(static_cast<std::size_t>(width_px) * static_cast<std::size_t>(height_px) * 3U, 0) {}

    std::size_t offset(int u, int v) const { return (static_cast<std::size_t>(v) * static_cast<std::size_t>(width) + static_cast<std::size_t>(u)) * 3U; }
    Rgb at(int u, int v) const {
        const std::size_t i = offset(u, v);
        return {bytes[i], bytes[i + 1], bytes[i + 2]};
    }
    void set(int u, int v, Rgb colour) {
        const std::size_t i = offset(u, v);
        bytes[i] = colour.r;
        bytes[i + 1] = colour.g;
        bytes[i + 2] = colour.b;
    }
};

}  // namespace rig::camera
