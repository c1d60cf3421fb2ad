#pragma once
// The proportional control valve of seed 000 (LC-25 electric ball valve): a ball
// turned by a 12 V DC motor on two relays. Nothing tells the board where the ball
// is; its position is the integral of the motor's run time, which is why the
// controller resets it against the end stop (open 5 s, back 2 s, sec. 2.2.2).
//
// Model (a position integrator with the imperfections a real gear train has):
//   - full travel closed -> open in travel_s (11 s, sec. 3.1.2), same speed back;
//   - end stops at 0 % and 100 %: driving into them does nothing more;
//   - start delay: each time a relay closes, the motor needs motor_start_delay_s
//     (relay pull-in, spin-up) before the ball moves: short pulses move less than
//     their length, pulses shorter than it not at all (the valve's deadband);
//   - backlash: the gear train has backlash_pct of play. The motor moves the
//     ball only with the play taken up on the side it pushes: after a reversal
//     the first backlash_pct of motor travel (less, if the play was only partly
//     crossed) turns nothing. The play is tracked, so a pulse too short to turn
//     the motor changes nothing. At power-on it is taken up on whichever side
//     the first drive pushes (where the last run left it).
//   - both relays on: the motor is shorted (braked), nothing moves; counted as a
//     wiring fault.
#include <cstdint>

namespace rig::emulators {

struct BallValveParams {
    double travel_s = 11.0;              // closed -> fully open
    double motor_start_delay_s = 0.02;   // lost at every relay closure
    double backlash_pct = 0.3;           // of full travel, taken up on a reversal
    // Where the ball is at power-on. The reset (open 5 s, back 2 s) reaches the end
    // stop only from above 54.5 % (5 s of 11 s travel): a lower value is the
    // fault of a valve left nearly closed.
    double initial_opening_pct = 85.0;
};

class BallValve {
public:
    explicit BallValve(const BallValveParams& params);

    enum class Drive { off, forward, reverse, both };
    // The relay outputs from now on.
    void set_drive(Drive drive);
    // Advances the motor by dt_s with the current drive.
    void step(double dt_s);

    double opening_pct() const { return opening_pct_; }
    Drive drive() const { return drive_; }
    std::uint32_t both_relays_events() const { return both_relays_events_; }
    const BallValveParams& params() const { return params_; }

private:
    BallValveParams params_;
    double opening_pct_;
    Drive drive_ = Drive::off;
    double start_delay_left_s_ = 0.0;
    // Where the motor sits inside the play: 0 = pushing towards closed, backlash_pct
    // = pushing towards open. Unknown until the motor first turns.
    double play_pct_ = 0.0;
    bool play_known_ = false;
    std::uint32_t both_relays_events_ = 0;
};

}  // namespace rig::emulators
