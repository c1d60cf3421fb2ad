#pragma once
// A camera frame whose every byte is known from (frame number, width, height),
// for tests/camera_frame_dds_test.cpp, its helper process
// tests/camera_frame_node.cpp and tests/vision_bench.cpp: a receiver can check a
// frame bit for bit without the sender's copy. The bytes come from SplitMix64
// so a dropped, duplicated, shifted or truncated fragment changes what is seen.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "msg_traits.h"

namespace rig::testing {

inline std::uint64_t splitmix64(std::uint64_t& state) {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

// `bytes` may differ from width * height * 3: the tests send frames off the size bound too.
inline rig::msg::CameraFrame patterned_frame(std::uint32_t frame_number, std::uint16_t width, std::uint16_t height,
                                             std::size_t bytes) {
    rig::msg::CameraFrame frame;
    frame.frame_number(frame_number);
    frame.width_px(width);
    frame.height_px(height);
    std::vector<std::uint8_t>& rgb = frame.rgb();
    rgb.resize(bytes);
    std::uint64_t state = (std::uint64_t{frame_number} << 32) ^ (std::uint64_t{width} << 16) ^ height;
    std::size_t i = 0;
    for (; i + 8 <= bytes; i += 8) {
        const std::uint64_t word = splitmix64(state);
        for (int b = 0; b < 8; ++b) rgb[i + b] = static_cast<std::uint8_t>(word >> (8 * b));
    }
    const std::uint64_t tail = splitmix64(state);
    for (int b = 0; i < bytes && b < 8; ++i, ++b) rgb[i] = static_cast<std::uint8_t>(tail >> (8 * b));
    return frame;
}

inline rig::msg::CameraFrame patterned_frame(std::uint32_t frame_number, std::uint16_t width, std::uint16_t height) {
    return patterned_frame(frame_number, width, height, std::size_t{width} * height * 3);
}

// Whether `frame` is exactly what patterned_frame made for its own number and size.
inline bool is_patterned(const rig::msg::CameraFrame& frame) {
    return frame == patterned_frame(frame.frame_number(), frame.width_px(), frame.height_px(), frame.rgb().size());
}

}  // namespace rig::testing
