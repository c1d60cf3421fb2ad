#include "emulators/seeded_random.h"

#include <cmath>
#include <numbers>

namespace rig::emulators {

namespace {

// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijection that spreads every
// input bit over the output, so seeds 1, 2, 3 and similar stream names give
// unrelated engine seeds.
std::uint64_t mix_64(std::uint64_t value) {
    value += 0x9e3779b97f4a7c15ULL;
    value = (value ^ (value >> 30)) * 0xbf58476d1ce4e5b9ULL;
    value = (value ^ (value >> 27)) * 0x94d049bb133111ebULL;
    return value ^ (value >> 31);
}

}  // namespace

std::uint64_t fnv1a_64(std::string_view text) {
    std::uint64_t hash = 14695981039346656037ULL;
    for (const char character : text) {
        hash ^= static_cast<unsigned char>(character);
        hash *= 1099511628211ULL;
    }
    return hash;
}

SeededRandom::SeededRandom(std::uint64_t seed, std::string_view stream_name)
    : engine_(mix_64(mix_64(seed) ^ fnv1a_64(stream_name))) {}

std::uint64_t SeededRandom::next_u64() { return engine_(); }

double SeededRandom::uniform01() {
    // The top 53 bits scaled by 2^-53: exactly representable, never 1.0.
    return static_cast<double>(engine_() >> 11) * 0x1.0p-53;
}

double SeededRandom::gaussian() {
    if (has_spare_gaussian_) {
        has_spare_gaussian_ = false;
        return spare_gaussian_;
    }
    // Box-Muller: u1 in (0, 1] so that log(u1) is finite.
    const double u1 = 1.0 - uniform01();
    const double u2 = uniform01();
    const double radius = std::sqrt(-2.0 * std::log(u1));
    const double angle = 2.0 * std::numbers::pi * u2;
    spare_gaussian_ = radius * std::sin(angle);
    has_spare_gaussian_ = true;
    return radius * std::cos(angle);
}

}  // namespace rig::emulators
