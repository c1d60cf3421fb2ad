#include "controller/valve_driver.h"

#include <algorithm>
#include <cmath>

namespace rig::controller {

ValveDriver::ValveDriver(const ValveDriverParams& params) : params_(params) {}

void ValveDriver::set_drive(RelayDrive drive, TimeNs now_ns) {
    advance_belief(now_ns);
    if (drive == drive_) return;
    if (drive != RelayDrive::off) start_delay_left_s_ = params_.start_delay_s;
    drive_ = drive;
}

void ValveDriver::advance_belief(TimeNs now_ns) {
    if (now_ns <= drive_since_ns_) return;
    if (drive_ != RelayDrive::off) {
        double run_s = ns_to_seconds(now_ns - drive_since_ns_);
        const double lost_s = std::min(run_s, start_delay_left_s_);
        start_delay_left_s_ -= lost_s;
        run_s -= lost_s;
        double travel_pct = run_s * 100.0 / params_.travel_s;
        if (travel_pct > 0.0) {
            const bool opening = drive_ == RelayDrive::forward;
            if (!play_known_) {
                play_pct_ = opening ? params_.backlash_pct : 0.0;
                play_known_ = true;
            }
            const double crossed_pct = std::min(travel_pct, play_to_cross_pct(drive_));
            play_pct_ += opening ? crossed_pct : -crossed_pct;
            travel_pct -= crossed_pct;
            believed_pct_ = std::clamp(believed_pct_ + (opening ? travel_pct : -travel_pct), 0.0, 100.0);
        }
    }
    drive_since_ns_ = now_ns;
}

double ValveDriver::play_to_cross_pct(RelayDrive drive) const {
    if (!play_known_ || drive == RelayDrive::off) return 0.0;
    return drive == RelayDrive::forward ? params_.backlash_pct - play_pct_ : play_pct_;
}

void ValveDriver::start_reset(TimeNs now_ns) {
    target_pct_.reset();
    reset_phase_ = ResetPhase::opening;
    set_drive(RelayDrive::forward, now_ns);
    next_event_ns_ = now_ns + seconds_to_ns(params_.reset_open_s);
}

void ValveDriver::move_to(double opening_pct, TimeNs now_ns) {
    if (resetting()) return;
    target_pct_ = std::clamp(opening_pct, 0.0, 100.0);
    plan_move(now_ns);
}

void ValveDriver::plan_move(TimeNs now_ns) {
    advance_belief(now_ns);
    if (!target_pct_) return;
    const double error_pct = *target_pct_ - believed_pct_;
    if (std::abs(error_pct) < params_.deadband_pct) {
        set_drive(RelayDrive::off, now_ns);
        next_event_ns_ = kNever;
        return;
    }
    const RelayDrive wanted = error_pct > 0 ? RelayDrive::forward : RelayDrive::reverse;
    set_drive(wanted, now_ns);
    // Run long enough to cover the start delay and backlash still to come, then the distance.
    const double run_s =
        start_delay_left_s_ + (play_to_cross_pct(wanted) + std::abs(error_pct)) * params_.travel_s / 100.0;
    next_event_ns_ = now_ns + std::max<TimeNs>(1, seconds_to_ns(run_s));
}

void ValveDriver::update(TimeNs now_ns) {
    advance_belief(now_ns);
    if (now_ns < next_event_ns_) return;
    switch (reset_phase_) {
        case ResetPhase::opening:
            // Against the end stop now (believed): drive back for reset_back_s.
            believed_pct_ = 100.0;
            play_pct_ = params_.backlash_pct;  // pushed against the stop
            play_known_ = true;
            reset_phase_ = ResetPhase::closing;
            set_drive(RelayDrive::reverse, now_ns);
            next_event_ns_ = now_ns + seconds_to_ns(params_.reset_back_s);
            return;
        case ResetPhase::closing:
            set_drive(RelayDrive::off, now_ns);
            reset_phase_ = ResetPhase::none;
            position_known_ = true;
            next_event_ns_ = kNever;
            return;
        case ResetPhase::none:
            break;
    }
    // End of a planned move: stop (or correct once more if the belief says so).
    set_drive(RelayDrive::off, now_ns);
    next_event_ns_ = kNever;
    if (target_pct_ && std::abs(*target_pct_ - believed_pct_) >= params_.deadband_pct) plan_move(now_ns);
}

}  // namespace rig::controller
