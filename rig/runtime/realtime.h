#pragma once
// Real-time runs (docs/design.md "Time", issue: bench acceptance): every node on the
// wall clock with absolute deadlines, for a controller board on real wires or a
// controller process that keeps its own time.
//
// Master side (RealtimeMaster, in the harness): local nodes (plant, emulators,
// wire adapters) run at their own wake times on one RealtimeClock. A node is
// stepped with the instant it actually runs, so truth is evaluated when each
// sample is emitted and scheduling jitter does not become metric error; how
// late each node woke against its deadline is recorded per node (emission
// jitter). Nodes with unread input run at once (input arrival wakes the loop).
// Remote nodes (the controller process) keep their own clocks: the master says
// hello as in lockstep, then one tick at t = 0 starts every clock, and the
// shutdown tick ends the run. A remote whose process ends fails the run by name.
//
// Follower side (run_realtime_follower, in the controller process): the same
// Node interface, stepped on its own RealtimeClock from the start tick on.
#include <chrono>
#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "rig/runtime/clock.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/lateness.h"
#include "rig/runtime/lockstep.h"
#include "rig/runtime/node.h"

namespace rig {

// Lateness of wake-ups against their deadlines, in milliseconds.
struct JitterStats {
    std::size_t samples = 0;
    double p50_ms = 0.0;
    double p99_ms = 0.0;
    double max_ms = 0.0;
    // How long the node's own steps took: a long step makes every node after
    // it in the loop late, so this says whose update a lateness came from.
    double step_p99_ms = 0.0;
    double step_max_ms = 0.0;
};
// Nearest-rank percentiles of `late_ns` (all >= 0); zeros when empty.
JitterStats summarize_lateness(std::vector<TimeNs> late_ns);

// What the process got when it asked for real-time scheduling.
struct SchedulingReport {
    bool fifo = false;          // SCHED_FIFO for the calling thread
    int priority = 0;
    bool memory_locked = false; // mlockall(MCL_CURRENT | MCL_FUTURE)
    std::string detail;         // e.g. "SCHED_FIFO 40, memory locked" or why not
};
// Asks for SCHED_FIFO at `priority` for the calling thread and locks memory;
// whatever is refused (no CAP_SYS_NICE, RLIMIT_MEMLOCK) is said in `detail`,
// and the run goes on without it. Also sets the timer slack to 1 ns, so
// deadline waits are not rounded up by the kernel's default 50 us.
SchedulingReport request_realtime_scheduling(int priority);
// SCHED_FIFO at `priority` for another, already running thread (a wire's
// server or forwarder: threads started before request_realtime_scheduling()
// do not inherit it). "" when granted, else why not.
std::string raise_thread_to_realtime(std::thread& thread, int priority);
// The calling thread back to ordinary time sharing (SCHED_OTHER): for a
// worker that the real-time loop starts (threads inherit SCHED_FIFO) and that
// computes for tens of milliseconds, such as a camera rendering its next
// frame. At the loop's priority it would hold a core the loop needs; below
// it, it takes what the loop leaves. Harmless when the thread was not
// real-time. `nice`, when given (-20 ... 19), weighs the thread against the
// machine's other time-sharing work (below 0, which needs CAP_SYS_NICE: a
// worker whose results have deadlines); without it the thread keeps the nice
// value it inherited. "" when done, else why not.
std::string drop_to_time_sharing(std::optional<int> nice = std::nullopt);

// The weight of this process's session against the machine's other sessions
// while a real-time run lasts. With the kernel's autogroups (Debian's default,
// /proc/sys/kernel/sched_autogroup_enabled), CFS shares the CPUs between
// sessions first and between threads of a session second: a thread's nice
// value only weighs against threads of its own session, and a session beside
// three others building gets a quarter of the machine, whatever its threads
// ask. The run's time-sharing work with deadlines (the cameras' rendering, the
// controller it started) is in this session, so the session's autogroup gets
// `nice` while a guard lives and its nice value from before after the last
// one ends (concurrent real-time cases share one autogroup). When autogroups
// are off or the write is refused, nothing changes and detail() says why.
class SessionCpuWeight {
public:
    explicit SessionCpuWeight(int nice);
    ~SessionCpuWeight();
    SessionCpuWeight(const SessionCpuWeight&) = delete;
    SessionCpuWeight& operator=(const SessionCpuWeight&) = delete;
    // e.g. "session autogroup nice -10 (was 0)", or why not.
    const std::string& detail() const { return detail_; }

private:
    bool raised_ = false;
    std::string detail_;
};

class RealtimeMaster {
public:
    RealtimeMaster(DdsContext& dds, LockstepTimeouts timeouts);
    ~RealtimeMaster();

    void add_local_node(Node& node);
    // Advanced to each pass's instant before the local nodes step (rig/runtime/node.h).
    void add_truth_model(TruthModel& model) { truth_models_.push_back(&model); }
    void add_remote_node(const std::string& name, std::function<std::optional<std::string>()> liveness);
    // Called after every pass through the loop with the instant it began (the
    // trace recorder drains its readers here).
    void set_after_step(std::function<void(TimeNs)> callback) { after_step_ = std::move(callback); }
    // As LockstepMaster::set_watchdog: called while waiting at start-up and after every pass.
    void set_watchdog(std::function<void()> callback) {
        watchdog_ = callback;
        remotes_.set_watchdog(std::move(callback));
    }
    // As LockstepMaster::set_after_hello.
    void set_after_hello(std::function<void(const std::vector<LockstepMaster::HelloTopics>&)> callback) {
        remotes_.set_after_hello(std::move(callback));
    }

    // Configures the local nodes, says hello to the remotes, waits for every
    // endpoint to match, then starts every clock at t = 0.
    void start();
    // Runs until the clock reaches end_ns. Throws NodeFailure for a remote that
    // died and whatever a local node's step throws.
    void run_until(TimeNs end_ns);
    // The shutdown tick to the remotes, local nodes shut down in reverse order.
    // Never throws. `after_failure`: as LockstepMaster::shutdown.
    void shutdown(bool after_failure = false) noexcept;

    const RealtimeClock& clock() const { return clock_; }
    // Per local node (by name): how late its timed wake-ups were.
    std::map<std::string, JitterStats> emission_jitter() const;
    // Every timed emission of the local nodes against `bound` (rig/runtime/lateness.h):
    // whether the rig kept time well enough for the run to judge the controller.
    void set_lateness_bound(LatenessBound bound) { lateness_.set_bound(bound); }
    LatenessVerdict lateness() const { return lateness_.verdict(); }
    // Self-test of the overload detection (a case's `rig_faults:`): the first
    // pass at or after `at_ns` blocks for `for_ns` before stepping anything, as
    // a machine that took the rig's CPU away would. Never used to judge a controller.
    void inject_stall(TimeNs at_ns, TimeNs for_ns) {
        stall_at_ns_ = at_ns;
        stall_for_ns_ = for_ns;
    }

private:
    struct Local {
        Node* node;
        TimeNs next_wake_ns = 0;
        std::vector<TimeNs> late_ns;
        std::vector<TimeNs> step_ns;
    };
    void record_emission(Local& local, TimeNs deadline_ns, TimeNs emitted_ns);

    DdsContext& dds_;
    LockstepMaster remotes_;
    RealtimeClock clock_;
    std::vector<Local> locals_;
    std::vector<TruthModel*> truth_models_;
    LatenessAccount lateness_;
    TimeNs stall_at_ns_ = kNever;
    TimeNs stall_for_ns_ = 0;
    std::function<void(TimeNs)> after_step_;
    std::function<void()> watchdog_;
    bool started_ = false;
    bool shut_down_ = false;
};

// Runs `node` in this process on its own wall clock, from the master's start
// tick to its shutdown tick. Returns a process exit code (0 = clean shutdown) and
// prints the reason for any other to stderr.
int run_realtime_follower(Node& node, DdsContext& dds, const FollowerOptions& options);

}  // namespace rig
