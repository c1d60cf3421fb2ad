#pragma once
// Counter-based random numbers for plant truth that is drawn where it is
// looked at (crop rows, camera pixel noise): the n-th number of a stream is a
// pure function of (key, n), so a plant or a pixel comes out the same whatever
// was drawn before it. (The device models' sequential streams are
// emulators/seeded_random.h; these must be random-access instead.)
#include <cstdint>

namespace rig::field2d {

// MurmurHash3's 64-bit finaliser: every input bit spreads over the output, so
// neighbouring keys (row 3 and row 4, pixel n and n + 1) give unrelated values.
inline std::uint64_t hash_finalise(std::uint64_t k) {
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    k *= 0xc4ceb9fe1a85ec53ULL;
    k ^= k >> 33;
    return k;
}

// A key from a seed and two integers (a row and a cell, a frame and a pixel).
inline std::uint64_t hash_key(std::uint64_t seed, std::uint64_t a, std::uint64_t b) {
    std::uint64_t key = hash_finalise(seed ^ 0x5eed001c0ffee000ULL);
    key = hash_finalise(key ^ a);
    return hash_finalise(key ^ (b * 0x2545f4914f6cdd1dULL));
}

class HashStream {
public:
    explicit HashStream(std::uint64_t key) : state_(key) {}
    std::uint64_t next_u64() {
        state_ += 0x9e3779b97f4a7c15ULL;  // Weyl step: odd, so n steps never repeat a state
        return hash_finalise(state_);
    }
    // Uniform on [0, 1) with 53 random bits.
    double uniform01() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }

private:
    std::uint64_t state_;
};

}  // namespace rig::field2d
