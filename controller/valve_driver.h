#pragma once
// Drives the proportional ball valve through its two relays, knowing its
// position only by dead reckoning: opening changes at 100 % / travel_s while a
// relay is closed, less the motor's start delay at each closure and the gear
// backlash after a reversal (the controller's beliefs about its valve, set from
// its configuration; the plant has its own truth).
//
// Reset (seed 000 sec. 2.2.2): "the control valve to the maximum flow rate for
// 5 s ... to ensure that the control valve has been opened to the maximum, and
// then it is adjusted in the opposite direction for 2 s": afterwards the valve is
// believed at 100 - (2 - start_delay) / travel_s x 100 + backlash % (81.8 % for
// an ideal 11 s valve; 82.3 % with the default 20 ms start delay and 0.3 % play),
// whatever it was before.
#include <optional>

#include "rig/runtime/clock.h"

namespace rig::controller {

struct ValveDriverParams {
    double travel_s = 11.0;
    double start_delay_s = 0.02;
    double backlash_pct = 0.3;
    double reset_open_s = 5.0;
    double reset_back_s = 2.0;
    double deadband_pct = 0.02;   // smaller moves are not worth a relay closure (0.22 L/min at 3 L/min per %: below 1 % of 20 L/min)
};

enum class RelayDrive { off, forward, reverse };

class ValveDriver {
public:
    explicit ValveDriver(const ValveDriverParams& params);

    // Starts the reset procedure (takes reset_open_s + reset_back_s).
    void start_reset(TimeNs now_ns);
    // Drive towards `opening_pct` (ignored while resetting; replaces any previous target).
    void move_to(double opening_pct, TimeNs now_ns);
    // Advances the belief and the relay plan to now; call before reading outputs.
    void update(TimeNs now_ns);

    RelayDrive drive() const { return drive_; }
    bool resetting() const { return reset_phase_ != ResetPhase::none; }
    bool position_known() const { return position_known_; }
    // True when not resetting and no move is under way.
    bool idle() const { return !resetting() && drive_ == RelayDrive::off; }
    double believed_opening_pct() const { return believed_pct_; }
    std::optional<double> target_pct() const { return target_pct_; }
    // When the relays must change next (kNever if nothing is planned).
    TimeNs next_event_ns() const { return next_event_ns_; }

private:
    enum class ResetPhase { none, opening, closing };
    void set_drive(RelayDrive drive, TimeNs now_ns);
    void advance_belief(TimeNs now_ns);
    void plan_move(TimeNs now_ns);

    ValveDriverParams params_;
    RelayDrive drive_ = RelayDrive::off;
    ResetPhase reset_phase_ = ResetPhase::none;
    bool position_known_ = false;
    double believed_pct_ = 50.0;
    std::optional<double> target_pct_;
    TimeNs drive_since_ns_ = 0;       // belief integrated up to here
    double start_delay_left_s_ = 0.0;
    // Where the motor is believed inside the gear play (see emulators/ball_valve.h):
    // 0 = pushing towards closed, backlash_pct = towards open.
    double play_pct_ = 0.0;
    bool play_known_ = false;
    double play_to_cross_pct(RelayDrive drive) const;
    TimeNs next_event_ns_ = kNever;
};

}  // namespace rig::controller
