#pragma once
// The front boom's hydraulic parallelogram lift (seed 001 Sec. 4.2.2, Fig. 15)
// and the boom height over time, which is plant truth.
//
// Eq. 18: the boom centre's horizontal distance ahead of the GNSS antenna at
// boom height H is
//     Y1 = sqrt(I^2 - (Hp - H)^2) - (M - L)
// with I the lift rod length, Hp the height of the parallelogram's hinge on the
// vehicle, M the antenna's distance to that hinge point O and L the distance
// from the parallelogram's hinge on the boom to the boom centre. The paper
// gives none of these lengths: the defaults below are chosen (assumed) so the
// boom centre is 1.00 m ahead of the antenna at the paper's 0.5 m spray height
// (Sec. 5.1), with the antenna just behind the boom as in Fig. 3, and so that
// the arithmetic is exact (a 3-4-5 triangle at H = 0.5 m):
//     sqrt(0.50^2 - (0.80 - 0.50)^2) - (0.30 - 0.90) = 0.40 + 0.60 = 1.00 m.
// At H = 0.40 m: sqrt(0.25 - 0.16) + 0.60 = 0.90 m; at 0.60 m: 1.058 m.
#include <string>
#include <vector>
#include "rig/papers/seed001.h"

namespace rig::field2d {

struct ParallelogramLift {
    double rod_length_m = papers::seed001::kLiftRodLengthM;                   // I, > 0
    double hinge_height_m = papers::seed001::kLiftHingeHeightM;               // Hp, > 0
    double antenna_to_o_m = papers::seed001::kLiftAntennaToOM;                // M, finite
    double hinge_to_boom_centre_m = papers::seed001::kLiftHingeToBoomCentreM;  // L, finite
    // Lowest and highest boom height the rods reach: Hp -+ I (rods vertical).
    double min_height_m() const { return hinge_height_m - rod_length_m; }
    double max_height_m() const { return hinge_height_m + rod_length_m; }
};

// Throws std::invalid_argument naming the field for a non-positive I or Hp or a
// non-finite length.
void validate(const ParallelogramLift& lift, const std::string& where = "lift");

// Eq. 18. Throws std::invalid_argument when H is not finite or |Hp - H| > I
// (the rods cannot reach that height).
double eq18_boom_offset_m(const ParallelogramLift& lift, double boom_height_m);

// Boom height H (m above the ground; the nozzles spray from this height) as a
// piecewise-linear function of time through knots, constant before the first
// and after the last. A single knot is a constant height. The paper's runs used
// 0.5 m (Sec. 5.1).
struct HeightKnot {
    double t_s = 0.0;
    double height_m = 0.5;
};

class BoomHeightProfile {
public:
    // Throws std::invalid_argument for no knots, times not strictly increasing,
    // or a non-finite or non-positive height (naming the knot).
    explicit BoomHeightProfile(std::vector<HeightKnot> knots = {HeightKnot{0.0, 0.5}});
    double height_at(double t_s) const;
    double min_height_m() const;
    double max_height_m() const;
    const std::vector<HeightKnot>& knots() const { return knots_; }

private:
    std::vector<HeightKnot> knots_;
};

}  // namespace rig::field2d
