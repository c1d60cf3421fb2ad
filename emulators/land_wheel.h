#pragma once
// The land wheel's error model: how far the wheel's circumference has rolled
// (what its encoder counts) after the sprayer has covered a given ground distance.
//
// Seed 000 sec. 3.2.1 / Fig. 13: "wheel deformation and uneven field terrain" put
// an error between odometer and true mileage that "accumulated as the recorded
// mileage increased": the fusion's breakpoint error was smallest with the 5 m
// odometer threshold (2.54 / 7.22 / 15.07 cm at 3 / 4.5 / 6 km/h) and reached
// 3.45 m (mean 1.59 m, sd 1.15 m) over thresholds of 5-50 m. Two terms model it:
//
//   wheel_travel(d) = d (1 - slip) / (1 - deflection) + terrain(d)
//
// where wheel_travel is what the encoder counts, expressed as revolutions times
// the NOMINAL circumference pi D (the D the controller's Eq. 5 uses):
//   deflection a loaded tyre rolls on a smaller radius than its nominal D / 2, by
//            deflection_pct: it turns more often per metre, so the odometer reads
//            long and the fusion declares "at breakpoint" early, by about
//            deflection x the odometer's distance. Together with the GNSS latency
//            (which makes the mileage base s_b late by v x latency) this is what
//            makes Table 3's error shrink with speed (15.85 cm at 3 km/h to
//            5.65 cm at 6 km/h): v x latency grows with speed and cancels more of
//            the fixed deflection error.
//
//   slip     one value per run: slip_pct / 100 + N(0, slip_sd_pct / 100). It
//            stands for tyre deformation (a smaller rolling radius than the
//            nominal D) and skid; the error it makes grows linearly with d.
//   terrain  a random walk in ground distance, linear between the nodes of a
//            1 m grid, with independent N(0, sigma^2 x 1 m) increments per metre,
//            sigma = terrain_sd_m_per_sqrt_m: bumps and furrows lengthen or
//            shorten the path the wheel rolls. Its spread grows like sigma sqrt(d)
//            (3.5 cm after 50 m with the default sigma).
//
// Fig. 13's numbers grow faster than linearly (cm at 5 m, metres at 50 m), so no
// single parameter set reproduces all of them; a case picks slip_pct, slip_sd_pct
// and terrain_sd_m_per_sqrt_m for the effect it wants to test.
//
// Properties the rest of the rig relies on:
//  - wheel_travel_m() is a pure function of (seed, params, ground distance): the
//    whole walk is drawn in the constructor from seeded streams, so the count is
//    the same whatever the order or frequency of queries.
//  - It never decreases as the ground distance grows: a land wheel does not roll
//    backwards while the sprayer drives forwards. Within each 1 m cell the slope
//    (1 - slip) + increment is clamped at 0 (the wheel skids, standing still); with
//    the defaults that clamp is a ~200-sigma event and never happens in practice.
//  - The walk is drawn for terrain_length_m of ground distance (default 10 km, far
//    more than any case drives); asking beyond it is an error, not a silent
//    extrapolation.
#include <cstdint>
#include <vector>

namespace rig::emulators {

struct LandWheelParams {
    double slip_pct = 0.0;                    // mean slip; positive = wheel rolls less than the ground
    double slip_sd_pct = 0.0;                 // run-to-run spread of the slip, >= 0
    double terrain_sd_m_per_sqrt_m = 0.005;   // sigma of the terrain walk, >= 0
    double terrain_length_m = 10000.0;        // ground distance the walk covers, > 0
    double deflection_pct = 0.0;              // loaded rolling radius below nominal, [0, 20)
};

class LandWheel {
public:
    // Draws the run's slip from stream "land_wheel.slip" and the terrain walk from
    // "land_wheel.terrain" of `seed`. Throws std::invalid_argument for a negative
    // spread or a non-positive or non-finite length.
    LandWheel(const LandWheelParams& params, std::uint64_t seed);

    // Distance rolled by the wheel after `ground_distance_m` of travel over the
    // ground (0 <= ground_distance_m <= terrain_length_m, else std::out_of_range).
    double wheel_travel_m(double ground_distance_m) const;
    // wheel_travel_m(d) - d: the odometer's error at ground distance d.
    double error_m(double ground_distance_m) const { return wheel_travel_m(ground_distance_m) - ground_distance_m; }

    // The slip drawn for this run, as a fraction (0.015 = 1.5 %).
    double slip_fraction() const { return slip_fraction_; }
    const LandWheelParams& params() const { return params_; }

private:
    static constexpr double kGridStep_m = 1.0;

    LandWheelParams params_;
    double slip_fraction_ = 0.0;
    // wheel travel at ground distance k * kGridStep_m; node_travel_m_[0] = 0, and
    // each next node is the previous one plus a non-negative cell increment.
    std::vector<double> node_travel_m_;
};

}  // namespace rig::emulators
