#pragma once
// Reproducible random numbers for the device and plant models (docs/design.md "Time":
// same case + same seed => identical trace).
//
// The engine is std::mt19937_64, whose output sequence the C++ standard fixes
// bit for bit. The distributions are NOT taken from <random>: the standard
// leaves the algorithm of std::normal_distribution (and of the real-valued
// uniform ones) to the library, so libstdc++ and libc++, or two releases of one,
// may turn the same engine output into different numbers. uniform01() and
// gaussian() below are written out here instead, so a trace recorded today
// replays identically with another C++ standard library. (gaussian() still calls
// std::log, std::cos and std::sin, which come from the C library, glibc on the
// rig's Debian, not from libstdc++; a different libm may differ in the last bit.)
//
// Each device gets its own stream: the case seed is combined with an FNV-1a hash
// of the stream name ("gnss_g970", "land_wheel.slip", ...), so adding a draw to
// one device never shifts the numbers another device sees.
#include <cstdint>
#include <random>
#include <string_view>

namespace rig::emulators {

// 64-bit FNV-1a of `text` (offset basis 14695981039346656037, prime 1099511628211).
std::uint64_t fnv1a_64(std::string_view text);

class SeededRandom {
public:
    SeededRandom(std::uint64_t seed, std::string_view stream_name);

    // The engine's raw 64-bit output.
    std::uint64_t next_u64();
    // Uniform on [0, 1) with 53 random bits (every double k * 2^-53).
    double uniform01();
    // Standard normal N(0, 1), Box-Muller transform; the second value of each
    // pair is kept and returned by the next call.
    double gaussian();

private:
    std::mt19937_64 engine_;
    double spare_gaussian_ = 0.0;
    bool has_spare_gaussian_ = false;
};

}  // namespace rig::emulators
