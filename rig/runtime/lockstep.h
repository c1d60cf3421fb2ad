#pragma once
// Lockstep virtual time over DDS (docs/design.md "Time").
//
// Protocol, per simulated instant t:
//   round 0: the master steps every local node due at t, then sends
//            ClockTick{seq, t, published_counts} to the remote nodes if one of
//            them is due or anything was published. published_counts is, per
//            topic, how many samples all processes have written since the run
//            began. Each remote node waits until its readers have received that
//            many on every topic it reads (counted delivery, over reliable
//            keep-all DDS), takes its inputs, steps, publishes, and answers
//            ClockAck{seq, next_wake, published_count, published_counts}; the
//            master then waits until its own readers hold what the remotes
//            published. Counting at the reader gives the guarantee a writer's
//            wait_for_acknowledgments gives (every sample published at t is in
//            its readers before they step), minus one handshake per writer per
//            instant, which was 45 % of a case's wall time (docs/design.md "Time").
//   round r>0: while a local node holds unread input (what the previous
//            round published), the nodes with unread input run again at the
//            same t, and the remotes are ticked again if the local nodes
//            published. A sample published at t is therefore seen by its
//            readers at t; delays come only from the models. A round in which
//            no node would step is not run (rounds only when needed).
//   In software in the loop (every node in the master's process, on one
//   LocalBus, rig/runtime/dds_context.h) a sample is in its readers when
//   publish returns: the counts are neither made nor waited for.
// Then the master jumps to the earliest next_wake of all nodes: idle simulated
// time costs nothing. Tick 0 is a hello, sent again every 0.2 s of wall time
// until every remote answered (a reader matched after it was written may never
// get it): the remote answers once all its endpoints are matched, listing the topics it reads and writes; the master then
// waits until each of its writers reaches every reader of its topic and each of
// its readers is reached by every writer. The first tick after the hello carries
// how many readers each topic has, and a remote's writers must reach all of them
// before it first publishes: discovery matches the two ends of a pair at
// different moments, and a volatile sample written to a writer that does not
// know a reader yet never reaches that reader (seen as a case stuck at t = 0
// waiting for the controller's first actuator samples, about 1 run in 50). A remote that does not answer within the
// wall-time bound, or whose process ends, fails the run with its name.
#include <chrono>
#include <deque>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "rig/runtime/clock.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/failure_kind.h"
#include "rig/runtime/node.h"

namespace rig {

// A node failed: did not answer in time, died, or reported a fatal error.
class NodeFailure : public std::runtime_error {
public:
    NodeFailure(FailureKind kind, std::string node_name, const std::string& what)
        : std::runtime_error("node '" + node_name + "': " + what), kind_(kind), node_name_(std::move(node_name)) {}
    FailureKind kind() const { return kind_; }
    const std::string& node_name() const { return node_name_; }

private:
    FailureKind kind_;
    std::string node_name_;
};

struct LockstepTimeouts {
    std::chrono::milliseconds ack{10'000};        // a remote must answer a tick within this
    std::chrono::milliseconds startup{30'000};    // discovery + hello
    std::chrono::milliseconds delivery{10'000};   // wait_for_acknowledgments bound
};

// Master side, in the harness process.
class LockstepMaster {
public:
    LockstepMaster(DdsContext& dds, LockstepTimeouts timeouts);
    ~LockstepMaster();

    // Local nodes run in the master's process and are stepped in the order added.
    void add_local_node(Node& node);
    // Advanced to each instant before the local nodes step at it (rig/runtime/node.h).
    void add_truth_model(TruthModel& model) { truth_models_.push_back(&model); }
    // A remote node (its own process). `liveness` returns an error text when the
    // node is known to be gone (e.g. its process exited), checked while waiting.
    void add_remote_node(const std::string& name, std::function<std::optional<std::string>()> liveness);
    // A node run in this process on a DDS participant of its own (a controller
    // plugin, rig/runtime/node_plugin.h), in place of a remote: it is configured,
    // says hello, waits for counted delivery, activates and steps exactly where a
    // follower process would, only called instead of ticked. Same order, same
    // inputs at each step: the same trace as process mode. `node_dds` must
    // outlive the master's shutdown.
    void add_in_process_node(Node& node, DdsContext& node_dds);
    // Called after every round with (t, round): the recorder drains its readers here.
    void set_after_round(std::function<void(TimeNs, int)> callback) { after_round_ = std::move(callback); }
    // Called in every wall-time slice the master waits (start-up, acknowledgements,
    // delivery) and after every round: the harness checks what no node reports
    // (a stop signal, its wall-time bound, topic roles seen in discovery) and
    // throws NodeFailure to end the run.
    void set_watchdog(std::function<void()> callback) { watchdog_ = std::move(callback); }
    // What a remote node said in its hello: the topics it reads and writes.
    struct HelloTopics {
        std::string node;
        std::vector<std::string> subscribed;
        std::vector<std::string> published;
    };
    // Called once the remotes answered the hello, with what each said it reads
    // and writes, before time starts and before the endpoints are matched: the
    // harness checks the roles declared there (a node that says it reads truth
    // fails here, at the same point every run, not whenever discovery happens
    // to tell), and the recorder adds readers for topics it does not know yet
    // (a controller's own diagnostics), so that they are matched and counted.
    void set_after_hello(std::function<void(const std::vector<HelloTopics>&)> callback) {
        after_hello_ = std::move(callback);
    }

    // Configure local nodes, wait for remote hellos and endpoint matching, activate.
    void start();
    // Processes the earliest instant <= until_ns; returns it, or nullopt when the
    // next wake-up is later than until_ns (the run is over).
    std::optional<TimeNs> advance(TimeNs until_ns);
    // Sends the shutdown tick, waits (bounded) for the remotes' last acks, shuts
    // local nodes down in reverse order. Never throws. After a failure
    // (`after_failure`) the tick is sent but not waited for: a remote that died
    // or stopped answering would only make the rig wait out its bound again.
    void shutdown(bool after_failure = false) noexcept;

    std::uint64_t ticks_sent() const { return seq_; }
    // Real-time runs (rig/runtime/realtime.h) use the master for the remotes only: one
    // tick at t tells them to start their clocks, and liveness is checked here.
    void tick_remotes_at(TimeNs t) { tick_remotes(t, false); }
    // Throws NodeFailure naming a remote whose process is gone.
    void check_remotes_alive(TimeNs t) const;
    TimeNs now_ns() const { return now_ns_; }

private:
    using TopicCounts = std::map<std::string, std::uint64_t>;
    struct Remote {
        std::string name;
        std::function<std::optional<std::string>()> liveness;
        TimeNs next_wake_ns = 0;
        std::vector<std::string> subscribed_topics;
        std::vector<std::string> published_topics;
        TopicCounts published_counts;  // cumulative, from its latest ack
        // In process (add_in_process_node): stepped by the master, no clock topics.
        Node* in_process = nullptr;
        DdsContext* in_process_dds = nullptr;
        bool configured = false;
        bool activated = false;
        bool shut_down = false;
    };
    struct Local {
        Node* node;
        TimeNs next_wake_ns = 0;
    };
    // Sends one tick and collects every remote's ack; returns samples they published.
    std::uint32_t tick_remotes(TimeNs t, bool shutdown);
    // What every process has published so far, per topic.
    TopicCounts all_published_counts() const;
    // How many readers each topic has, here and in the remotes.
    TopicCounts reader_counts() const;
    // Until the local readers hold all of it (bounded; a dead remote is named).
    void wait_local_readers(TimeNs t);
    // What a follower process does on a tick, for an in-process node; returns
    // the samples it published.
    std::uint32_t step_in_process(Remote& remote, std::uint64_t seq, TimeNs t, bool shutdown,
                                  const TopicCounts& published_before);
    // Before its hello: every reader of an in-process node has a writer (as a
    // follower's wait_matched), within the start-up bound.
    void wait_in_process_matched(const Remote& remote, const std::function<void(const std::string&)>& check_startup);
    std::size_t process_remote_count() const;

    DdsContext& dds_;
    LockstepTimeouts timeouts_;
    std::vector<Local> locals_;
    std::vector<TruthModel*> truth_models_;
    std::vector<Remote> remotes_;
    std::unique_ptr<Writer<msg::ClockTick>> tick_writer_;
    std::unique_ptr<Reader<msg::ClockAck>> ack_reader_;
    std::function<void(TimeNs, int)> after_round_;
    std::function<void()> watchdog_;
    std::function<void(const std::vector<HelloTopics>&)> after_hello_;
    std::uint64_t seq_ = 0;
    TimeNs now_ns_ = 0;
    // Set by start(): no process remote, and every reader here and in the
    // in-process nodes is on a LocalBus (rig/runtime/dds_context.h), so what
    // is published is in its readers when publish returns: no counts are
    // made, sent or waited for.
    bool delivered_at_publish_ = false;
    const TopicCounts no_counts_;
    bool started_ = false;
    bool shut_down_ = false;
};

struct FollowerOptions {
    std::string node_name;
    // The harness is gone if no tick arrives for this long: exit instead of hanging.
    std::chrono::milliseconds idle_timeout{120'000};
    std::chrono::milliseconds startup_timeout{30'000};
    std::chrono::milliseconds delivery_timeout{10'000};
    // Fault injection (bench and tests): from this simulated time on, stop
    // answering ticks, like a wedged firmware loop. kNever = never.
    TimeNs stall_at_ns = kNever;
};

// The node side of the clock protocol, shared by the lockstep follower and the
// real-time one (rig/runtime/realtime.h): the tick reader, the ack writer, the hello.
class FollowerLink {
public:
    FollowerLink(DdsContext& dds, const FollowerOptions& options);
    // Waits until every endpoint in the context has a counterpart; false (and says
    // which ones on stderr) when the startup timeout passes.
    bool wait_matched();
    // The next tick other than a hello (hellos are answered here, with the topics
    // this process reads); nullopt when none came within `timeout`.
    std::optional<msg::ClockTick> next_tick(std::chrono::milliseconds timeout);
    void ack(std::uint64_t seq, TimeNs next_wake, std::uint32_t published, const std::string& subscribed,
             const std::string& fatal);
    // An ack after which the process ends: waits until it is delivered.
    void final_ack(std::uint64_t seq, const std::string& fatal);
    // The harness's clock writer is still matched (it goes away when the harness dies).
    bool harness_present() const;
    // Before the first step: until every writer here reaches the readers the
    // first tick counted for its topic. Returns why not (empty = all reached).
    std::string wait_writers_reach_readers(const msg::ClockTick& first_tick);

private:
    DdsContext& dds_;
    FollowerOptions options_;
    std::unique_ptr<Reader<msg::ClockTick>> tick_reader_;
    std::unique_ptr<Writer<msg::ClockAck>> ack_writer_;
    std::deque<msg::ClockTick> pending_;
};

// The start both followers share: the clock endpoints, the node's configure(),
// every endpoint matched. Returns the link, or the process exit code with the
// reason already on stderr (2: configure failed, 3: no counterpart in time).
std::variant<std::unique_ptr<FollowerLink>, int> start_follower(Node& node, DdsContext& dds,
                                                               const FollowerOptions& options);

// Follower side: runs `node` in this process under the master's ticks until the
// shutdown tick. Returns a process exit code (0 = clean shutdown) and prints the
// reason for any other to stderr.
int run_lockstep_follower(Node& node, DdsContext& dds, ManualClock& clock, const FollowerOptions& options);

}  // namespace rig
