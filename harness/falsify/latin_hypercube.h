#pragma once
// A Latin hypercube design on [0, 1)^d: each dimension cut into n equal
// strata, each stratum holding exactly one of the n points, placed at random
// inside it; the strata of different dimensions paired at random. It spreads
// a search's first points over every parameter's whole range (no two share a
// stratum of any one parameter), which plain random points do not.
//
// Deterministic: the same (n, d, seed) gives the same points on every machine
// (a 64-bit Mersenne Twister and integer arithmetic, no library distribution,
// whose algorithms the C++ standard leaves to each implementation).
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

namespace rig::harness {

// A uniform double in [0, 1) from the generator's top 53 bits.
double unit_interval(std::mt19937_64& random);
// A uniform integer in [0, count), count > 0.
std::size_t below(std::mt19937_64& random, std::size_t count);

// n points of d coordinates each, in [0, 1).
std::vector<std::vector<double>> latin_hypercube(std::size_t n, std::size_t d, std::uint64_t seed);

}  // namespace rig::harness
