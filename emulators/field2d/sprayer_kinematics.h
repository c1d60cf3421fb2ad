#pragma once
// Where every part of the seed-001 sprayer is at time t (plant truth): the
// route's rear-axle pose, the RTK antenna (position, WGS84, and its velocity,
// which is what a receiver's course and speed over ground measure), the boom
// height, Eq. 18's boom offset at that height, the boom centre and the six
// nozzles. A pure function of t, like the route it is built on.
//
// Body frame: x metres to the right, y metres forward (seed 001 Fig. 16's xoy).
// The antenna sits `antenna_forward_of_axle_m` ahead of the rear axle; the boom
// centre Y1(H) ahead of the antenna (Eq. 18, emulators/field2d/boom_lift.h) on
// the antenna's line; nozzle i at x_i = (i - (n - 1) / 2) x spacing on the boom,
// so with 6 nozzles 0.5 m apart (Table 1) nozzle 0 is 1.25 m left of the boom
// centre and nozzle 5 1.25 m right (numbering left to right facing the travel
// direction: assumed, the paper's Fig. 16 does not say).
#include <cstdint>
#include <optional>
#include <vector>

#include "emulators/field2d/boom_lift.h"
#include "emulators/field2d/local_frame.h"
#include "emulators/field2d/route2d.h"
#include "emulators/field2d/vec2.h"
#include "emulators/guidance/guided_path.h"
#include "rig/papers/seed001.h"

namespace rig::field2d {

struct SprayerMounting {
    // Rear axle to antenna along the heading. Assumed: the paper puts the antenna
    // ahead of the vehicle centre, 25 cm behind the front wall (Sec. 1.1); for a
    // 3.2 m long 3WP-280 (Table 2) that is about 1.6 m ahead of the rear axle.
    double antenna_forward_of_axle_m = 1.60;   // finite
    double antenna_right_m = 0.0;              // finite; Sec. 1.1: on the vehicle's centre line
    double antenna_height_m = 1.70;            // > 0; Sec. 1.1: H1 about 170 cm
    ParallelogramLift lift{};                  // Eq. 18 (assumed lengths, see boom_lift.h)
    int nozzle_count = papers::seed001::kNozzleCount;             // 1..32
    double nozzle_spacing_m = papers::seed001::kNozzleSpacingM;   // > 0
};

// Throws std::invalid_argument naming the field.
void validate(const SprayerMounting& mounting);

// x of nozzle i (m right of the boom centre).
double nozzle_right_m(const SprayerMounting& mounting, int nozzle);

struct SprayerTruth {
    VehiclePose2d pose;                 // rear-axle centre
    Vec2 antenna;                       // antenna's ground point, local east/north
    GeodeticPoint antenna_geodetic;     // antenna phase centre, WGS84 (height_m above the ellipsoid)
    Vec2 antenna_velocity_m_s;          // east/north components, m/s
    double boom_height_m = 0.0;         // H, truth
    double boom_offset_m = 0.0;         // Y1(H), Eq. 18
    Vec2 boom_centre;                   // ground point under the boom centre
    std::vector<Vec2> nozzles;          // ground points under each nozzle, index = nozzle number
};

// With guidance (emulators/guidance/guided_path.h), the rear axle is not on the
// route but steered along it by autosteer over a rough ground: the pose is the
// guided vehicle's, the antenna sits on the rolling, pitching body (its ground
// point moves h sin(roll) sideways, its height is h cos(roll) cos(pitch)), and
// the boom and nozzles follow the body's yaw. The boom's own roll with the body
// is not modelled (its fan lands where the level boom's would).
// Without guidance the route is driven exactly, as before (bit for bit).
class SprayerKinematics {
public:
    // Throws std::invalid_argument for a bad mounting or a height profile the
    // lift cannot reach (naming the height and the lift's range), or bad
    // guidance parameters (naming guidance.<field>). `seed` draws the guided
    // ground (the run's seed).
    SprayerKinematics(LocalFrame frame, Route2d route, SprayerMounting mounting, BoomHeightProfile height,
                      std::optional<emulators::guidance::GuidanceParams> guidance = std::nullopt,
                      std::uint64_t seed = 1);

    SprayerTruth truth_at(double t_s) const;
    double boom_height_at(double t_s) const { return height_.height_at(t_s); }

    const LocalFrame& frame() const { return frame_; }
    const Route2d& route() const { return route_; }
    const SprayerMounting& mounting() const { return mounting_; }
    const BoomHeightProfile& height_profile() const { return height_; }
    // The autosteer's run (nullptr when the route is driven exactly).
    const emulators::guidance::GuidedPath* guided() const { return guided_ ? &*guided_ : nullptr; }

private:
    LocalFrame frame_;
    Route2d route_;
    SprayerMounting mounting_;
    BoomHeightProfile height_;
    std::optional<emulators::guidance::GuidedPath> guided_;
};

// The route as the autosteer follows it: its rear-axle pose at a path length
// (extended straight past the end, where the look-ahead reaches beyond it).
emulators::guidance::ReferencePath reference_path_of(const Route2d& route);

}  // namespace rig::field2d
