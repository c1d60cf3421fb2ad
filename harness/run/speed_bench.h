#pragma once
// `rig bench`: what the rig's lockstep costs, against the DDS floor.
// For each case, N runs in process mode (the controller in its own process) on
// one leased CPU as `rig run` places them (rig/host/cpu_lease.h), N more left
// to the scheduler (`--no-pin`), and N in software-in-the-loop mode (its plugin
// in the rig's process), one at a time; in the same invocation, a DDS
// ping-pong between two processes on the rig's profile with the clock's own
// message types (rig/host/dds_pingpong.h), in each of the two placements,
// once before each repeat of the process-mode runs of that placement, each
// repeat judged against the ping-pong just before it.
// One table: per mode, the wall time per round and rounds per second while
// stepping, simulated over wall time per case, start-up to all matched (p50 /
// p99), trace bytes per simulated minute, and the per-round cost as a ratio to
// the ping-pong's. Times are the machine's, as loaded as it is: the table
// prints the load average beside them. Speed is measured here, never asserted
// by a test.
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "harness/run/case_runner.h"
#include "rig/host/dds_pingpong.h"

namespace rig::harness {

struct SpeedBenchOptions {
    std::vector<std::string> cases;  // case files (lockstep; a `seeds:` case runs its first seed)
    int repeat = 5;                  // runs per case and mode
    PingPongOptions pingpong;
    std::filesystem::path out_dir = "rig-bench";  // traces, bench.json
    RunOptions run;                  // controller executable and plugin
    // Also process mode and the ping-pong with DDS-Security (credentials made in
    // out_dir/security, docs/dds-security.md): what it costs per round.
    bool dds_security = false;
};

// Prints the table; writes out_dir/bench.json. Returns 0, 1 when a run failed
// or the two modes' digests differ, 2 on bad input.
int run_speed_bench(const SpeedBenchOptions& options, std::ostream& out, std::ostream& err);

}  // namespace rig::harness
