#pragma once
// A vehicle steered along its route by autosteer (docs/guidance.md), instead of
// driving the route exactly: a kinematic bicycle with the vehicle's wheelbase,
// a pure-pursuit controller on the route, a steering actuator with lag, rate
// and angle limits, and a seeded ground that rolls, pitches and yaws the body.
//
// The loop is integrated once, at construction, on a fixed grid of step_s from
// the start time, with the speed the route prescribes at each instant (the
// guidance steers; it does not change the speed profile). state_at(t)
// interpolates linearly between grid points, so it is a pure function of t,
// the same in any order of calls (lockstep runs jump in time, real-time runs
// sample at odd instants) and the same for the same seed, bit for bit.
//
// Frames: positions in a plane frame with compass headings (0 = +north,
// clockwise; emulators/field2d/vec2.h): the local east-north frame for seed
// 001, the A-B line's (right, along) for seed 000. The body: right, forward,
// up, from the ground point under the rear-axle centre (the bicycle's
// reference: the one point whose velocity is along the heading).
//
// What the loop does each step:
//   1. the ground at the route distance the vehicle is at: roll, pitch, yaw disturbance;
//   2. the controller's view of the rear axle: the antenna's reported position
//      less its mounting, with the part of its roll / pitch shift the terrain
//      compensation does not remove (an antenna 1.7 m up at 1 deg roll is 3 cm off);
//   3. pure pursuit: the route point one look-ahead beyond the axle's foot
//      point, and the steering angle of the arc through it,
//      delta = atan(2 L sin(alpha) / l_d) (Coulter 1992);
//   4. the actuator moves toward that angle (lag, rate, angle limits);
//   5. the bicycle moves: yaw rate = v tan(delta) / L + v x yaw disturbance.
#include <cstdint>
#include <functional>
#include <vector>

#include "emulators/field2d/vec2.h"
#include "emulators/guidance/guidance_params.h"

namespace rig::emulators::guidance {

using field2d::Vec2;

// A point of the route the rear axle should follow, and the route's heading there.
struct PathPose {
    Vec2 position;
    double heading_deg = 0.0;
};
// The route as a function of its path length (>= 0; beyond its end, its last
// point and heading extended straight).
using ReferencePath = std::function<PathPose(double distance_m)>;
// The speed the route prescribes at time t (>= 0, m/s).
using SpeedProfile = std::function<double(double t_s)>;

// A point fixed to the body: right, forward, up of the ground point under the rear-axle centre.
struct BodyPoint {
    double right_m = 0.0;
    double forward_m = 0.0;
    double up_m = 0.0;
};

// Where a body point is when the body rolls (roll_deg > 0: right side down)
// and pitches (pitch_deg > 0: nose up) about the rear axle's ground point,
// roll applied first (yaw-pitch-roll): right, forward, up in the heading's
// frame. At 10 deg roll a point 1.7 m up moves 1.7 sin 10 deg = 0.295 m right.
BodyPoint tilted(const BodyPoint& point, double roll_deg, double pitch_deg);

// Pure pursuit: the steering angle (rad, > 0 steering right) that puts the rear
// axle at `axle`, heading `heading_deg`, on the circle through `target`:
// atan(2 L sin(alpha) / l_d), alpha the target's bearing from the heading and
// l_d its distance. A target at the axle gives 0.
double pure_pursuit_steer_rad(Vec2 axle, double heading_deg, Vec2 target, double wheelbase_m);

// The steering actuator one step of dt_s: toward `command_rad` with the first-order
// lag, its rate limited to steer_rate_max and the command and result to steer_angle_max.
double steer_actuator_step(double angle_rad, double command_rad, double dt_s, const GuidanceParams& params);

struct GuidedState {
    double time_s = 0.0;
    Vec2 position;                  // rear-axle centre's ground point
    double heading_deg = 0.0;       // [0, 360)
    double speed_m_s = 0.0;         // along the heading (the route's speed at time_s)
    double yaw_rate_deg_s = 0.0;    // > 0 turning right
    double distance_m = 0.0;        // odometer from the start
    double steer_deg = 0.0;         // front wheel angle, > 0 right
    double roll_deg = 0.0;          // > 0 right side down
    double pitch_deg = 0.0;         // > 0 nose up
    // From truth: the rear axle's offset right of the route at its foot point,
    // the heading minus the route's there, and the foot point's route distance.
    double cross_track_m = 0.0;
    double heading_error_deg = 0.0;
    double route_distance_m = 0.0;
    // The antenna (the BodyPoint given at construction) with the body's tilt:
    // its ground point, its height above the ground, and the velocity of that
    // ground point (what a receiver's course and speed measure).
    Vec2 antenna;
    double antenna_up_m = 0.0;
    Vec2 antenna_velocity_m_s;
};

class GuidedPath {
public:
    // Integrates the loop from start_s (the vehicle at route distance
    // start_distance_m, offset by params' start_cross_track_m and
    // start_heading_error_deg) to end_s. `seed` and `stream` name the ground's
    // random streams ("<stream>.roll", ".pitch", ".yaw"). Throws
    // std::invalid_argument for bad params (naming the field), a non-finite or
    // negative time span, or more than kMaxSteps steps.
    GuidedPath(const GuidanceParams& params, ReferencePath route, SpeedProfile speed, double start_s, double end_s,
               double start_distance_m, BodyPoint antenna, std::uint64_t seed, const char* stream = "guidance");

    // The state at t_s, clamped to [start_s, end_s].
    GuidedState state_at(double t_s) const;
    double start_s() const { return start_s_; }
    double end_s() const { return start_s_ + step_s_ * static_cast<double>(samples_.size() - 1); }
    const GuidanceParams& params() const { return params_; }

    // An hour at 100 Hz.
    static constexpr std::size_t kMaxSteps = 360000;

private:
    GuidanceParams params_;
    double start_s_;
    double step_s_;
    std::vector<GuidedState> samples_;  // at start_s + k step_s; heading_deg unwrapped
};

}  // namespace rig::emulators::guidance
