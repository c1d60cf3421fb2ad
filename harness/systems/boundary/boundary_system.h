#pragma once
// Seed 001, per-nozzle shut-off at a target area's edge and rates from the
// plant cover the boom cameras see (Yang et al. 2022; ../docs/seed001-*.md),
// as a system of the rig (harness/systems/system.h): its sections
// (boundary_case.h), one run's world (boundary_world.h: the 2-D plant and its
// six PWM nozzles, the AD300's RMC, the L4 laser, the two cameras), its judge
// (boundary_judge.h) and its reference controller (rig-boundary-controller).
#include "harness/systems/system.h"

namespace rig::harness {

const System& boundary_system();

}  // namespace rig::harness
