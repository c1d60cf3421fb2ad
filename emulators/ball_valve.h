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
//   - backlash: after a change of direction the first backlash_pct of motor
//     travel only takes up the gear play.
//   - both relays on: the motor is shorted (braked), nothing moves; counted as a
//     wiring fault.
#include <cstdint>

namespace rig::emulators {

struct BallValveParams {
    double travel_s = 11.0;              // closed -> fully open
    double motor_start_delay_s = 0.02;   // lost at every relay closure
    double backlash_pct = 0.3;           // of full travel, taken up on a reversal
    double initial_opening_pct = 40.0;   // where the ball is at power-on
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
    double backlash_left_pct_ = 0.0;
    int last_direction_ = 0;   // +1 opening, -1 closing, 0 never moved
    std::uint32_t both_relays_events_ = 0;
};

}  // namespace rig::emulators
