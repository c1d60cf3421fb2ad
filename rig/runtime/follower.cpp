#include "rig/runtime/follower.h"

#include <iostream>
#include <stdexcept>
#include <string>

#include "rig/runtime/clock.h"
#include "rig/runtime/realtime.h"

namespace rig {

ReliabilityTimers reliability_timers_for(ClockMode mode) {
    return mode == ClockMode::realtime ? ReliabilityTimers::prompt_repair : ReliabilityTimers::few_wakeups;
}

int run_follower(const FollowerStartup& startup, const NodeFactory& make_node) {
    const std::string& name = startup.options.node_name;
    // Declared before the node, so destroyed after it (see follower.h).
    DdsContext dds(startup.domain_id, name, /*watch_discovery=*/false, reliability_timers_for(startup.clock));
    const std::unique_ptr<Node> node = make_node();
    if (!node) throw std::logic_error("the node factory made no node");
    if (startup.clock == ClockMode::lockstep) {
        ManualClock clock;
        return run_lockstep_follower(*node, dds, clock, startup.options);
    }
    if (startup.realtime_priority) {
        std::cerr << name << ": " << request_realtime_scheduling(*startup.realtime_priority).detail << "\n";
    }
    return run_realtime_follower(*node, dds, startup.options);
}

}  // namespace rig
