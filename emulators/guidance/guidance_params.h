#pragma once
// The autosteer loop's parameters (emulators/guidance/guided_path.h): the
// vehicle's steering geometry, the guidance controller, its steering actuator
// and the ground that disturbs it. Every one declared here once, with unit,
// default, bounds and where the number comes from; a case's `guidance:` section
// overrides them by the same names (docs/guidance.md), and validate() holds
// them to the bounds given here.
//
// Published figures used:
//   - RTK autosteer pass-to-pass accuracy of +-2.5 cm (RTK autosteer
//     specifications, docs/guidance.md): set beside the rig's cross-track
//     error from truth (docs/guidance.md's table); not an input to the loop.
//   - Pure pursuit (Coulter 1992, CMU-RI-TR-92-01) with a look-ahead that grows
//     with speed, as open-source tractor autosteer (AgOpenGPS) uses it.
// Everything else is an assumption, named as such below.
#include <string_view>

namespace rig::emulators::guidance {

struct GuidanceParams {
    // Rear axle to front axle, m, [0.5, 10]. Assumed: a small self-propelled
    // sprayer or a compact tractor (seed 001's 3WP-280 is 3.2 m long, Table 2).
    double wheelbase_m = 1.8;
    // Pure pursuit look-ahead = max(lookahead_min_m, lookahead_time_s x speed).
    // Assumed, of the size autosteer defaults use: 2 m, or 1.5 s of travel.
    double lookahead_min_m = 2.0;        // m, [0.3, 50]
    double lookahead_time_s = 1.5;       // s, [0, 10]
    // The steering actuator (hydraulic valve or wheel motor): a first-order lag
    // toward the commanded angle, limited in rate and angle. Assumed: 0.2 s,
    // 30 deg/s, 35 deg (orders of an electric steering-wheel motor).
    double steer_time_constant_s = 0.2;  // s, [0, 5]; 0: no lag (rate limit only)
    double steer_rate_max_deg_s = 30.0;  // deg/s, [0.1, 360]
    double steer_angle_max_deg = 35.0;   // deg, [1, 60]
    // Fraction of the antenna's sideways shift from roll and pitch that the
    // autosteer's terrain compensation (an IMU) removes before steering. 1:
    // perfect compensation, 0: none (it steers the antenna itself onto the
    // line). Assumed 0.8: compensation with a lagging, imperfect roll estimate. [0, 1]
    double terrain_compensation = 0.8;
    // The ground: seeded random functions of the distance driven, white noise
    // through two first-order lags of the correlation length (correlation
    // (1 + d/L) e^(-d/L), ground_roughness.h), so the same ground excites
    // faster at higher speed.
    // Roll and pitch of the body (it follows the ground, suspension ignored) and
    // a yaw disturbance: the heading change per metre that ruts, clods and
    // wheel slip force on the vehicle (a curvature the steering must cancel).
    // Roll 1 deg, pitch 0.5 deg and the 2 m correlation length are assumed. The
    // yaw disturbance's size is the one fitted number: 0.9 deg/m gives seed
    // 001 Table 7's SD along the edge at 1.0 m/s (paper 2.06 cm; 2.08 cm, the
    // mean over seeds 1-30 of the nozzle's truth at the 11 stations); the
    // other speeds' SD, Table 7's means and the cross-track error against the
    // published +-2.5 cm are predictions (docs/guidance.md).
    double roll_sd_deg = 1.0;            // deg, [0, 15]
    double pitch_sd_deg = 0.5;           // deg, [0, 15]
    double yaw_disturbance_sd_deg_m = 0.9;   // deg/m, [0, 20]; fitted (above)
    double roughness_length_m = 2.0;     // m, [0.1, 100]
    // Where the vehicle starts relative to its route (and, on seed 000, where it
    // comes back to the line after each headland turn): the rear axle's offset
    // right of the route, m, [-5, 5], and its heading minus the route's, deg,
    // clockwise, [-30, 30].
    double start_cross_track_m = 0.0;
    double start_heading_error_deg = 0.0;
    // The loop's integration step, s, [0.0001, 0.05]: the controller and the
    // actuator update at 1 / step_s (100 Hz; autosteer loops run at 10-100 Hz).
    double step_s = 0.01;
};

// Throws std::invalid_argument naming `section`.<field> and its bounds.
void validate(const GuidanceParams& params, std::string_view section = "guidance");

// Seed 000's plant (emulators/plant.h) has no body: where its RTK antenna sits
// on the sprayer, for guidance (without guidance the antenna is a point on the
// A-B line and these are unused). Assumed: the
// paper gives the antenna-to-nozzle geometry (Fig. 5, Eq. 6), not where the
// antenna is over the wheels; a cab-roof antenna on a self-propelled sprayer
// sits about 1 m ahead of the rear axle and 2.5 m above the ground.
struct AntennaMount {
    double forward_of_rear_axle_m = 1.0;  // m, [-10, 10]
    double height_m = 2.5;                // m, [0.1, 10]
};
// Throws std::invalid_argument naming `section`.<field>.
void validate(const AntennaMount& antenna, std::string_view section = "guidance");

}  // namespace rig::emulators::guidance
