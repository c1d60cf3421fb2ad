#pragma once
// Seed 001's spray on the ground, pulse by pulse: the six PWM valves
// (emulators/pwm_nozzle_valves.h) deliver their volumes, and each step's volume
// lands as the nozzle's 110 deg fan band (emulators/field2d/deposition_grid2d.h)
// under where the nozzle is at that step (emulators/field2d/sprayer_kinematics.h),
// at the boom height of that instant.
//
// Time moves on a fixed grid of step_s from t = 0: advance_to(t) integrates
// every whole step that ends at or before t, so how a run jumps in time does
// not change what lands where (lockstep), bit for bit. Volumes are exact per
// step (integrated between PWM edges); only the place is taken at the step's
// middle, so a pulse is smeared by at most v x step_s / 2 (3.75 mm at 1.5 m/s).
//
// Not modelled: the droplets' fall time (about 0.07 s from 0.5 m, seed 000
// Table 1) and their drift; the spray lands under the nozzle when it leaves it.
#include <vector>

#include "emulators/field2d/deposition_grid2d.h"
#include "emulators/field2d/sprayer_kinematics.h"
#include "emulators/pwm_nozzle_valves.h"
#include "rig/runtime/clock.h"

namespace rig::emulators {

struct SprayDepositionParams {
    double fan_angle_deg = 110.0;   // (0, 180); Table 1 (Agrotop 110 deg flat fan)
    // The fan sheet's thickness along the travel direction where it meets the
    // ground. Assumed (the paper gives none): a 110 deg flat fan at 0.5 m lands
    // as a strip a few centimetres to about 10 cm deep.
    double band_thickness_m = 0.10; // (0, 1]
    double step_s = 0.005;          // (0, 0.05]; assumed, well under a 9 Hz pulse (44 ms at 40 %)
};

class BoundarySprayPlant {
public:
    // `kinematics` must outlive this object. Throws std::invalid_argument for
    // bad parameters or when the valves, grid and boom disagree on the number
    // of nozzles.
    BoundarySprayPlant(const field2d::SprayerKinematics& kinematics, PwmNozzleValves valves,
                       field2d::DepositionGrid2d grid, SprayDepositionParams params = {});

    // The controller's duty for a nozzle (the actuator topic), from at_ns on.
    // at_ns must not be before integrated_until_ns() (std::logic_error).
    void command_duty(int nozzle, double duty_pct, TimeNs at_ns);
    // Integrates every whole step ending at or before t_ns.
    void advance_to(TimeNs t_ns);
    TimeNs integrated_until_ns() const { return valves_.now_ns(); }

    const field2d::DepositionGrid2d& grid() const { return grid_; }
    const PwmNozzleValves& valves() const { return valves_; }
    const field2d::SprayerKinematics& kinematics() const { return kinematics_; }
    const SprayDepositionParams& params() const { return params_; }

private:
    const field2d::SprayerKinematics& kinematics_;
    PwmNozzleValves valves_;
    field2d::DepositionGrid2d grid_;
    SprayDepositionParams params_;
    TimeNs step_ns_ = 0;
};

}  // namespace rig::emulators
