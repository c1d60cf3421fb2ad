#include "emulators/guidance/ground_roughness.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rig::emulators::guidance {

CorrelatedProfile::CorrelatedProfile(double sd, double length_m, std::uint64_t seed, std::string_view stream_name)
    : rho_(0.0), innovation_(0.0), random_(seed, stream_name) {
    if (!std::isfinite(sd) || sd < 0.0) throw std::invalid_argument("ground profile SD must be finite and >= 0");
    if (!std::isfinite(length_m) || length_m <= 0.0) {
        throw std::invalid_argument("ground profile correlation length must be finite and > 0");
    }
    rho_ = std::exp(-kGridM / length_m);
    // The first lag's stationary SD is sqrt 2 sd: the second lag of the same
    // length halves the variance (the integral of 2 L / (1 + k^2 L^2)^2 over
    // the wavenumber k is half that of 2 L / (1 + k^2 L^2)).
    innovation_ = std::sqrt(2.0) * sd * std::sqrt(1.0 - rho_ * rho_);
    // Start stationary: ten lengths of ground before distance 0 (at most 20 000 steps).
    const auto warm_up = static_cast<std::size_t>(std::min(20000.0, std::ceil(10.0 * length_m / kGridM)));
    for (std::size_t i = 0; i < warm_up; ++i) step();
    grid_.push_back(second_lag_);
}

double CorrelatedProfile::step() {
    first_lag_ = rho_ * first_lag_ + innovation_ * random_.gaussian();
    second_lag_ = rho_ * second_lag_ + (1.0 - rho_) * first_lag_;
    return second_lag_;
}

double CorrelatedProfile::at(double distance_m) {
    const double cells = std::max(0.0, distance_m) / kGridM;
    const auto below = static_cast<std::size_t>(std::floor(cells));
    while (grid_.size() < below + 2) grid_.push_back(step());
    const double fraction = cells - static_cast<double>(below);
    return grid_[below] + fraction * (grid_[below + 1] - grid_[below]);
}

}  // namespace rig::emulators::guidance
