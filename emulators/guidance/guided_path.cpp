#include "emulators/guidance/guided_path.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "emulators/guidance/ground_roughness.h"

namespace rig::emulators::guidance {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

// Body point (right, forward) of a body at `origin` facing `heading_deg`.
Vec2 on_ground(Vec2 origin, double heading_deg, const BodyPoint& point) {
    return field2d::body_to_field(origin, heading_deg, point.right_m, point.forward_m);
}

// The route distance of the foot point of `position` near `guess_m`: Newton
// steps on the route's tangent, which is exact on a straight and converges
// within millimetres on an arc far wider than the cross-track error.
double foot_distance_m(const ReferencePath& route, Vec2 position, double guess_m) {
    double distance_m = guess_m;
    for (int i = 0; i < 3; ++i) {
        const PathPose at = route(distance_m);
        distance_m = std::max(0.0, distance_m + field2d::dot(position - at.position, field2d::forward_of(at.heading_deg)));
    }
    return distance_m;
}

GuidedState lerp(const GuidedState& a, const GuidedState& b, double f) {
    const auto mix = [f](double x, double y) { return x + f * (y - x); };
    GuidedState s = a;
    s.position = Vec2{mix(a.position.east_m, b.position.east_m), mix(a.position.north_m, b.position.north_m)};
    s.heading_deg = mix(a.heading_deg, b.heading_deg);
    s.speed_m_s = mix(a.speed_m_s, b.speed_m_s);
    s.yaw_rate_deg_s = mix(a.yaw_rate_deg_s, b.yaw_rate_deg_s);
    s.distance_m = mix(a.distance_m, b.distance_m);
    s.steer_deg = mix(a.steer_deg, b.steer_deg);
    s.roll_deg = mix(a.roll_deg, b.roll_deg);
    s.pitch_deg = mix(a.pitch_deg, b.pitch_deg);
    s.cross_track_m = mix(a.cross_track_m, b.cross_track_m);
    s.heading_error_deg = mix(a.heading_error_deg, b.heading_error_deg);
    s.route_distance_m = mix(a.route_distance_m, b.route_distance_m);
    s.antenna = Vec2{mix(a.antenna.east_m, b.antenna.east_m), mix(a.antenna.north_m, b.antenna.north_m)};
    s.antenna_up_m = mix(a.antenna_up_m, b.antenna_up_m);
    // a's velocity is the slope of the antenna's interval [a, b].
    return s;
}

}  // namespace

BodyPoint tilted(const BodyPoint& point, double roll_deg, double pitch_deg) {
    const double sr = std::sin(roll_deg * kRadPerDeg);
    const double cr = std::cos(roll_deg * kRadPerDeg);
    const double sp = std::sin(pitch_deg * kRadPerDeg);
    const double cp = std::cos(pitch_deg * kRadPerDeg);
    // Roll about the forward axis (right side down: up moves right), then pitch
    // about the right axis (nose up: up moves back).
    const double right_m = point.right_m * cr + point.up_m * sr;
    const double up_after_roll_m = -point.right_m * sr + point.up_m * cr;
    return BodyPoint{right_m, point.forward_m * cp - up_after_roll_m * sp, point.forward_m * sp + up_after_roll_m * cp};
}

double pure_pursuit_steer_rad(Vec2 axle, double heading_deg, Vec2 target, double wheelbase_m) {
    const Vec2 to_target = target - axle;
    const double lookahead_m = field2d::norm(to_target);
    if (lookahead_m == 0.0) return 0.0;
    // alpha: the target's bearing from the heading, > 0 to the right.
    const double alpha_rad = std::atan2(field2d::dot(to_target, field2d::right_of(heading_deg)),
                                        field2d::dot(to_target, field2d::forward_of(heading_deg)));
    // The arc tangent to the heading through the target has curvature 2 sin(alpha) / l_d.
    return std::atan(2.0 * wheelbase_m * std::sin(alpha_rad) / lookahead_m);
}

double steer_actuator_step(double angle_rad, double command_rad, double dt_s, const GuidanceParams& params) {
    const double max_angle_rad = params.steer_angle_max_deg * kRadPerDeg;
    const double max_step_rad = params.steer_rate_max_deg_s * kRadPerDeg * dt_s;
    const double wanted_rad = std::clamp(command_rad, -max_angle_rad, max_angle_rad);
    // First-order lag: a fraction dt / tau of the gap per step (exact for a constant
    // command: 1 - exp(-dt / tau)); no lag closes the gap at once, rate permitting.
    const double tau_s = params.steer_time_constant_s;
    const double lag_step_rad = (wanted_rad - angle_rad) * (tau_s > 0.0 ? 1.0 - std::exp(-dt_s / tau_s) : 1.0);
    return std::clamp(angle_rad + std::clamp(lag_step_rad, -max_step_rad, max_step_rad), -max_angle_rad, max_angle_rad);
}

GuidedPath::GuidedPath(const GuidanceParams& params, ReferencePath route, SpeedProfile speed, double start_s,
                       double end_s, double start_distance_m, BodyPoint antenna, std::uint64_t seed,
                       const char* stream)
    : params_(params), start_s_(start_s), step_s_(params.step_s) {
    validate(params_);
    if (!std::isfinite(start_s) || !std::isfinite(end_s) || end_s < start_s) {
        throw std::invalid_argument("guidance: the run must span a finite time, start <= end");
    }
    if (!std::isfinite(start_distance_m) || start_distance_m < 0.0) {
        throw std::invalid_argument("guidance: the start's route distance must be finite and >= 0");
    }
    const double steps_real = std::ceil((end_s - start_s) / step_s_);
    if (steps_real > static_cast<double>(kMaxSteps)) {
        throw std::invalid_argument("guidance: " + std::to_string(static_cast<long long>(steps_real)) +
                                    " steps of step_s; at most " + std::to_string(kMaxSteps) +
                                    " (an hour at 100 Hz): a larger step_s or a shorter route");
    }
    const auto steps = static_cast<std::size_t>(steps_real);
    const std::string name(stream);
    CorrelatedProfile roll(params_.roll_sd_deg, params_.roughness_length_m, seed, name + ".roll");
    CorrelatedProfile pitch(params_.pitch_sd_deg, params_.roughness_length_m, seed, name + ".pitch");
    CorrelatedProfile yaw(params_.yaw_disturbance_sd_deg_m, params_.roughness_length_m, seed, name + ".yaw");

    const PathPose start = route(start_distance_m);
    Vec2 position = start.position + params_.start_cross_track_m * field2d::right_of(start.heading_deg);
    double heading_deg = start.heading_deg + params_.start_heading_error_deg;  // unwrapped
    double steer_rad = 0.0;
    double odometer_m = 0.0;
    double foot_m = start_distance_m;
    const BodyPoint flat_antenna{antenna.right_m, antenna.forward_m, antenna.up_m};
    const double wheelbase_m = params_.wheelbase_m;
    samples_.reserve(steps + 1);
    for (std::size_t k = 0;; ++k) {
        const double t_s = start_s + step_s_ * static_cast<double>(k);
        foot_m = foot_distance_m(route, position, foot_m);
        const PathPose foot = route(foot_m);
        GuidedState sample;
        sample.time_s = t_s;
        sample.position = position;
        sample.heading_deg = heading_deg;
        sample.speed_m_s = speed(t_s);
        sample.distance_m = odometer_m;
        sample.steer_deg = steer_rad / kRadPerDeg;
        sample.roll_deg = roll.at(foot_m);
        sample.pitch_deg = pitch.at(foot_m);
        const double yaw_disturbance_rad_m = yaw.at(foot_m) * kRadPerDeg;
        sample.yaw_rate_deg_s = sample.speed_m_s * (std::tan(steer_rad) / wheelbase_m + yaw_disturbance_rad_m) / kRadPerDeg;
        sample.cross_track_m = field2d::dot(position - foot.position, field2d::right_of(foot.heading_deg));
        sample.heading_error_deg = field2d::heading_difference_deg(heading_deg, foot.heading_deg);
        sample.route_distance_m = foot_m;
        const BodyPoint antenna_now = tilted(antenna, sample.roll_deg, sample.pitch_deg);
        sample.antenna = on_ground(position, heading_deg, antenna_now);
        sample.antenna_up_m = antenna_now.up_m;
        samples_.push_back(sample);
        if (k == steps) break;

        // The controller's rear axle: the reported antenna less its mounting, with
        // the tilt's share the terrain compensation leaves in.
        const Vec2 tilt_shift = sample.antenna - on_ground(position, heading_deg, flat_antenna);
        const Vec2 believed_axle = position + (1.0 - params_.terrain_compensation) * tilt_shift;
        const double v_m_s = speed(t_s + 0.5 * step_s_);
        const double lookahead_m = std::max(params_.lookahead_min_m, params_.lookahead_time_s * v_m_s);
        const Vec2 target = route(foot_m + lookahead_m).position;
        steer_rad = steer_actuator_step(steer_rad, pure_pursuit_steer_rad(believed_axle, heading_deg, target, wheelbase_m),
                                        step_s_, params_);
        // Kinematic bicycle, midpoint rule over the step.
        const double yaw_rate_rad_s = v_m_s * (std::tan(steer_rad) / wheelbase_m + yaw_disturbance_rad_m);
        const double heading_mid_deg = heading_deg + 0.5 * yaw_rate_rad_s * step_s_ / kRadPerDeg;
        position = position + (v_m_s * step_s_) * field2d::forward_of(heading_mid_deg);
        heading_deg += yaw_rate_rad_s * step_s_ / kRadPerDeg;
        odometer_m += v_m_s * step_s_;
    }
    for (std::size_t k = 0; k + 1 < samples_.size(); ++k) {
        samples_[k].antenna_velocity_m_s = (1.0 / step_s_) * (samples_[k + 1].antenna - samples_[k].antenna);
    }
    if (samples_.size() > 1) samples_.back().antenna_velocity_m_s = samples_[samples_.size() - 2].antenna_velocity_m_s;
}

GuidedState GuidedPath::state_at(double t_s) const {
    const double steps = std::clamp((t_s - start_s_) / step_s_, 0.0, static_cast<double>(samples_.size() - 1));
    const auto below = static_cast<std::size_t>(std::floor(steps));
    GuidedState state = below + 1 < samples_.size()
                            ? lerp(samples_[below], samples_[below + 1], steps - static_cast<double>(below))
                            : samples_.back();
    state.time_s = t_s;
    state.heading_deg = field2d::heading_0_360_deg(state.heading_deg);
    return state;
}

}  // namespace rig::emulators::guidance
