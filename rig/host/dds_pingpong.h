#pragma once
// The DDS floor under a lockstep round (`rig bench`): the same exchange a round
// makes with a controller process (a ClockTick out, a ClockAck back, reliable
// keep-all on the loopback profile) between this process and a second one
// (`rig bench --pong`) that does nothing else. No rig can step a controller in
// another process faster than this; the benchmark states the lockstep's cost
// per round as a ratio to it.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace rig {

struct PingPongOptions {
    std::uint32_t rounds = 2000;         // timed round trips
    std::uint32_t warmup_rounds = 200;   // before them, not timed (discovery settles, caches fill)
    std::uint32_t topics_in_tick = 16;   // entries in the tick's published_counts, as a case's tick carries
    std::filesystem::path pong_executable;  // the `rig` binary; started as `rig bench --pong`
    std::filesystem::path log_dir;
    // Set for the second process over this one's environment ("NAME=value"):
    // its DDS-Security identity when the floor is measured secured.
    std::vector<std::string> pong_environment;
};

struct PingPongResult {
    std::uint32_t rounds = 0;
    double matched_after_s = 0.0;  // wall time from start until both ends matched
    double mean_us = 0.0;
    double p50_us = 0.0;
    double p99_us = 0.0;
};

// Throws std::runtime_error naming what failed (no match, a lost answer, the
// second process gone).
PingPongResult run_dds_pingpong(const PingPongOptions& options);

// The second process: answers every ping until `rounds` are answered or none
// comes for a while. Returns 0 on a full exchange.
int run_dds_pong(std::uint32_t domain_id, std::uint32_t rounds);

}  // namespace rig
