#pragma once
// A controller process's start-up as a follower of the rig's clock, in one
// call (docs/sdk.md, docs/controller-contract.md): the DDS context with the
// reliability timers of the clock mode, the node, real-time scheduling when
// it runs on the wall clock, then the lockstep or the real-time follower
// (rig/runtime/lockstep.h, rig/runtime/realtime.h) until the shutdown tick.
//
// The node comes from a factory, not as a reference, because its readers and
// writers leave the context when they are destroyed: the context must be made
// before the node and outlive it. run_follower makes the node only once the
// context exists and destroys it first, so a caller cannot get that order
// wrong; a node constructed by the caller before the call could not be.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string_view>

#include "rig/runtime/clock.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/lockstep.h"
#include "rig/runtime/node.h"

namespace rig {

// The timers of a follower's context (rig/runtime/dds_context.h): few
// wake-ups in lockstep, where a lost sample costs only a slower round; prompt
// repair on the wall clock, where a 100 Hz device cannot wait for it. The
// rig's own context in the same run gets the same.
ReliabilityTimers reliability_timers_for(ClockMode mode);

// The SCHED_FIFO priority a follower asks for on the wall clock: below the
// rig's real-time master (50), whose deadlines make the devices' timing, and
// the threads that carry the bench wires' bytes (45), so that a board's
// request is answered on time however busy the controller is
// (docs/bench-wiring.md).
inline constexpr int kFollowerRealtimePriority = 40;

struct FollowerStartup {
    std::uint32_t domain_id = 0;
    ClockMode clock = ClockMode::lockstep;
    // options.node_name also names the DDS participant and begins every line
    // the start-up writes to stderr.
    FollowerOptions options;
    // On the wall clock: ask for SCHED_FIFO at this priority and locked memory
    // before the follower starts (rig::request_realtime_scheduling), and write
    // what was granted to stderr as "NAME: detail". nullopt: stay at the
    // scheduler's default and say nothing. Unused in lockstep.
    std::optional<int> realtime_priority = kFollowerRealtimePriority;
};

// Makes the node; called once, after the context exists. What it throws
// comes out of run_follower, the context destroyed on the way.
using NodeFactory = std::function<std::unique_ptr<Node>()>;

// Makes the context, then the node, and runs the follower of startup.clock.
// Returns the follower's process exit code (0 = clean shutdown; the reason
// for any other is already on stderr). Throws what the context's creation or
// the factory throws, and std::logic_error when the factory makes no node.
int run_follower(const FollowerStartup& startup, const NodeFactory& make_node);

}  // namespace rig
