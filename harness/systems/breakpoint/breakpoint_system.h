#pragma once
// Seed 000, the breakpoint sprayer (Li et al. 2023, Agriculture 13, 2203) as
// a system of the rig (harness/systems/system.h): its sections
// (breakpoint_case.h), one run's world (breakpoint_world.h: the plant, the
// spray circuit, the G970II, the encoder, the meters, the operator's button
// and switch), its judge (breakpoint_judge.h) and its reference controller
// (rig-controller, and its plugin for software-in-the-loop).
#include "harness/systems/system.h"

namespace rig::harness {

const System& breakpoint_system();

}  // namespace rig::harness
