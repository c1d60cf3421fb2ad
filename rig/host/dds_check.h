#pragma once
// `rig dds-check`: a bench-machine self-test of the DDS set-up. Starts a second
// process (`rig dds-check --echo`), exchanges ping/pong samples with it through
// the loopback profile and reports the round trips. A short, bounded DDS
// exchange between two processes, which also makes it the workload the
// kernel-level network test (strace) observes.
#include <cstdint>
#include <filesystem>
#include <iosfwd>

namespace rig {

struct DdsCheckOptions {
    std::uint32_t samples = 20;
    std::filesystem::path echo_executable;  // the `rig` binary; started with --echo
    std::filesystem::path log_dir;          // where the echo process's log goes
};

// Returns 0 when every ping came back in order, 1 otherwise; prints what it did.
int run_dds_check(const DdsCheckOptions& options, std::ostream& out);

// The echo side: answers pings until it has answered `samples` or none arrive
// for a while. Returns 0 on a full exchange.
int run_dds_echo(std::uint32_t domain_id, std::uint32_t samples, std::ostream& out);

}  // namespace rig
