#pragma once
// The ground under a guided vehicle: seeded, smooth random processes over the
// distance driven, on a 5 cm grid, linearly interpolated between. Over
// distance, not time, because the ground is the same whatever the speed:
// driven faster, the same bumps excite the vehicle faster, which is what makes
// guidance worse with speed.
//
// Each is white noise through two first-order lags of the same length L in
// distance (correlation (1 + d / L) exp(-d / L)): one lag alone (a first-order
// Gauss-Markov chain) is rough at every scale, its slope unbounded, which
// would give the body roll rates no vehicle has (the tyres and the wheelbase
// average the ground) and a receiver's course jumping by degrees.
//
// Each channel draws from its own stream of the run's seed
// (emulators/seeded_random.h), so the same seed gives the same ground, bit for
// bit, and a channel's size does not shift another's numbers.
#include <cstdint>
#include <string_view>
#include <vector>

#include "emulators/seeded_random.h"

namespace rig::emulators::guidance {

class CorrelatedProfile {
public:
    static constexpr double kGridM = 0.05;
    // Stationary: SD `sd` at every grid point, correlation (1 + d / L) exp(-d / L) at a lag d, L = length_m.
    // sd >= 0 and length_m > 0 (std::invalid_argument otherwise).
    CorrelatedProfile(double sd, double length_m, std::uint64_t seed, std::string_view stream_name);

    // The value at distance_m >= 0 (clamped at 0 below), drawing the grid out as far as needed.
    double at(double distance_m);

private:
    // One 5 cm step of both lags; the result is the second's output.
    double step();

    double rho_;
    double innovation_;  // the first lag's input per step
    double first_lag_ = 0.0;
    double second_lag_ = 0.0;
    SeededRandom random_;
    std::vector<double> grid_;
};

}  // namespace rig::emulators::guidance
