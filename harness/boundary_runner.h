#pragma once
// Runs one seed-001 boundary case (`system: boundary`): the world of
// harness/boundary_world.h as the lockstep master's local nodes, the boundary
// controller (rig-boundary-controller beside `rig`, unless the case names a
// command) as the remote node, every sample recorded by the trace recorder,
// and the verdict from the trace alone (harness/judge.h, which hands the
// boundary metrics to harness/boundary_judge.h). The same shape as seed 000's
// run (harness/case_runner.cpp): its session, its DDS domain, its trace.
// `mode: realtime` runs the same nodes on seed 000's real-time loop
// (harness/realtime_case_loop.h) with the case's `wiring:`: the AD300's RMC
// and the L4's lines on serial lines (NmeaSerialAdapter, LaserSerialAdapter),
// the nozzle PWM on DDS or from the HID board's capture
// (NozzlePwmCaptureAdapter, `board_io: hid`, with `controller: external`).
#include <cstdint>
#include <string>

#include "harness/case_runner.h"

namespace rig::harness {

// The reference boundary controller's executable, beside `rig`.
inline constexpr const char* kBoundaryControllerExecutable = "rig-boundary-controller";

// Never throws; a run that could not start is a result with its error.
CaseRun run_boundary_case(const CaseSpec& spec, std::uint64_t seed, const std::string& run_name, const RunOptions& options);

}  // namespace rig::harness
