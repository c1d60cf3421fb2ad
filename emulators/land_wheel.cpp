#include "emulators/land_wheel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "emulators/seeded_random.h"

namespace rig::emulators {

LandWheel::LandWheel(const LandWheelParams& params, std::uint64_t seed) : params_(params) {
    if (!std::isfinite(params.slip_pct)) throw std::invalid_argument("land wheel: slip_pct must be finite");
    if (!(params.slip_sd_pct >= 0.0) || !std::isfinite(params.slip_sd_pct)) {
        throw std::invalid_argument("land wheel: slip_sd_pct must be finite and >= 0");
    }
    if (!(params.terrain_sd_m_per_sqrt_m >= 0.0) || !std::isfinite(params.terrain_sd_m_per_sqrt_m)) {
        throw std::invalid_argument("land wheel: terrain_sd_m_per_sqrt_m must be finite and >= 0");
    }
    if (!(params.deflection_pct >= 0.0 && params.deflection_pct < 20.0)) {
        throw std::invalid_argument("land wheel: deflection_pct must be in [0, 20)");
    }
    if (!(params.terrain_length_m > 0.0) || !std::isfinite(params.terrain_length_m)) {
        throw std::invalid_argument("land wheel: terrain_length_m must be finite and > 0");
    }

    // Separate streams: the slip draw does not depend on how long the walk is.
    SeededRandom slip_random(seed, "land_wheel.slip");
    slip_fraction_ = (params.slip_pct + params.slip_sd_pct * slip_random.gaussian()) / 100.0;

    SeededRandom terrain_random(seed, "land_wheel.terrain");
    const auto cells = static_cast<std::size_t>(std::ceil(params.terrain_length_m / kGridStep_m));
    // A random walk's increment over one cell has sd sigma * sqrt(cell length).
    const double increment_sd_m = params.terrain_sd_m_per_sqrt_m * std::sqrt(kGridStep_m);
    node_travel_m_.reserve(cells + 1);
    // Nominal-circumference metres per ground metre: slip makes it less, a
    // deflected (smaller) rolling radius makes it more.
    const double turns_per_ground_m = (1.0 - slip_fraction_) / (1.0 - params.deflection_pct / 100.0);
    node_travel_m_.push_back(0.0);
    for (std::size_t cell = 0; cell < cells; ++cell) {
        const double rolled_m = kGridStep_m * turns_per_ground_m + increment_sd_m * terrain_random.gaussian();
        // Never backwards: at worst the wheel skids through the cell without turning.
        node_travel_m_.push_back(node_travel_m_.back() + std::max(0.0, rolled_m));
    }
}

double LandWheel::wheel_travel_m(double ground_distance_m) const {
    if (!(ground_distance_m >= 0.0) || ground_distance_m > params_.terrain_length_m) {
        throw std::out_of_range("land wheel: ground distance " + std::to_string(ground_distance_m) +
                                " m outside the modelled [0, " + std::to_string(params_.terrain_length_m) + "] m");
    }
    const double cell_position = ground_distance_m / kGridStep_m;
    // The last node closes the last cell, so clamp the cell index to a valid pair.
    const std::size_t cell =
        std::min(static_cast<std::size_t>(cell_position), node_travel_m_.size() - 2);
    const double fraction = cell_position - static_cast<double>(cell);
    const double start_m = node_travel_m_[cell];
    return start_m + fraction * (node_travel_m_[cell + 1] - start_m);
}

}  // namespace rig::emulators
