#pragma once
// Actuator commands the plant refuses (docs/controller-contract.md "Malformed
// commands"). A command no wiring of the sprayer could carry out is a bug of
// the controller that sent it, and the rig must report it: the plant does not
// act on a guess (a duty clamped into range, a section bit dropped would be a
// number passed off as the command), it ends the run with malformed_command
// (rig/runtime/failure_kind.h), naming the topic, the instant and what was
// wrong. A command it can act on it takes exactly as before, so no trace of a
// well-formed run changes.
//
// What each actuator topic must hold (idl/actuator.idl):
//   actuator/section_valves/open   open_mask: bit i = section i, so no bit at
//                                  or above the boom's section count (seed 000:
//                                  the case's hydraulics.section_nozzles, Fig. 9's three)
//   actuator/nozzle_pwm/duty       duty_pct: one duty per nozzle (seed 001: the
//                                  case's boom, Sec. 3.2.1's six), each a finite
//                                  % of the PWM period in [0, 100]; frequency_hz
//                                  finite and not below 0, and 0 (no PWM: each
//                                  line steady, as the bench capture reads it)
//                                  only with every duty 0 or 100 %
//   actuator/ball_valve/relays,    booleans: every value is a command a relay
//   actuator/unloading_valve/open  can carry out (both relays on brakes the
//                                  valve's motor, which the plant models)
#include <optional>
#include <string>
#include <string_view>

#include "actuator.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/lockstep.h"

namespace rig::emulators {

// What is wrong with the command, for the error; nullopt when the plant can act on it.
std::optional<std::string> section_valves_problem(const msg::SectionValves& command, int section_count);
std::optional<std::string> nozzle_pwm_problem(const msg::NozzlePwm& command, int nozzle_count);

// The failure that ends the run, for the plant node to throw: the controller
// (whatever drives the actuator topics) named, "TOPIC at t=S s: PROBLEM", S to
// the millisecond as in the rig's other errors.
NodeFailure malformed_command(std::string_view topic, TimeNs at_ns, const std::string& problem);

}  // namespace rig::emulators
