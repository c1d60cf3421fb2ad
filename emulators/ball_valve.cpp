#include "emulators/ball_valve.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rig::emulators {

BallValve::BallValve(const BallValveParams& params) : params_(params), opening_pct_(params.initial_opening_pct) {
    if (!(params.travel_s > 0.0) || !std::isfinite(params.travel_s)) {
        throw std::invalid_argument("ball valve: travel_s must be > 0");
    }
    if (!(params.motor_start_delay_s >= 0.0) || !(params.backlash_pct >= 0.0)) {
        throw std::invalid_argument("ball valve: motor_start_delay_s and backlash_pct must be >= 0");
    }
    if (!(params.initial_opening_pct >= 0.0 && params.initial_opening_pct <= 100.0)) {
        throw std::invalid_argument("ball valve: initial_opening_pct must be in [0, 100]");
    }
}

void BallValve::set_drive(Drive drive) {
    if (drive == drive_) return;
    if (drive == Drive::both) ++both_relays_events_;
    // Every relay closure costs the motor its start delay; the play is only
    // crossed once the motor really turns (step()).
    if (drive == Drive::forward || drive == Drive::reverse) start_delay_left_s_ = params_.motor_start_delay_s;
    drive_ = drive;
}

void BallValve::step(double dt_s) {
    if (drive_ != Drive::forward && drive_ != Drive::reverse) return;
    double run_s = dt_s;
    const double lost_s = std::min(run_s, start_delay_left_s_);
    start_delay_left_s_ -= lost_s;
    run_s -= lost_s;
    double travel_pct = run_s * 100.0 / params_.travel_s;
    if (travel_pct <= 0.0) return;
    const bool opening = drive_ == Drive::forward;
    if (!play_known_) {
        play_pct_ = opening ? params_.backlash_pct : 0.0;
        play_known_ = true;
    }
    // First cross what is left of the play, then the ball turns.
    const double play_to_cross_pct = opening ? params_.backlash_pct - play_pct_ : play_pct_;
    const double crossed_pct = std::min(travel_pct, play_to_cross_pct);
    play_pct_ += opening ? crossed_pct : -crossed_pct;
    travel_pct -= crossed_pct;
    opening_pct_ = std::clamp(opening_pct_ + (opening ? travel_pct : -travel_pct), 0.0, 100.0);
}

}  // namespace rig::emulators
