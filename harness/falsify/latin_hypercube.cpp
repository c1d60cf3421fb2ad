#include "harness/falsify/latin_hypercube.h"

#include <numeric>

namespace rig::harness {

double unit_interval(std::mt19937_64& random) { return static_cast<double>(random() >> 11) * 0x1.0p-53; }

std::size_t below(std::mt19937_64& random, std::size_t count) {
    // Draws past the last whole multiple of `count` are drawn again, so every
    // value is equally likely.
    const std::uint64_t whole = ~std::uint64_t{0} - (~std::uint64_t{0} % count);
    std::uint64_t drawn = random();
    while (drawn >= whole) drawn = random();
    return static_cast<std::size_t>(drawn % count);
}

std::vector<std::vector<double>> latin_hypercube(std::size_t n, std::size_t d, std::uint64_t seed) {
    std::mt19937_64 random(seed);
    std::vector<std::vector<double>> points(n, std::vector<double>(d, 0.0));
    std::vector<std::size_t> strata(n);
    for (std::size_t dimension = 0; dimension < d; ++dimension) {
        std::iota(strata.begin(), strata.end(), std::size_t{0});
        // Fisher-Yates: a random pairing of points and strata.
        for (std::size_t last = n; last > 1; --last) std::swap(strata[last - 1], strata[below(random, last)]);
        for (std::size_t point = 0; point < n; ++point) {
            points[point][dimension] = (static_cast<double>(strata[point]) + unit_interval(random)) / static_cast<double>(n);
        }
    }
    return points;
}

}  // namespace rig::harness
