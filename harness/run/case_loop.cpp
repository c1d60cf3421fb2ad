#include "harness/run/case_loop.h"

#include <csignal>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "harness/run/run_interrupt.h"
#include "harness/session/board_attach.h"
#include "harness/trace/topic_roles.h"
#include "idl/topics.h"
#include "rig/host/heap_count.h"
#include "rig/runtime/failure_kind.h"
#include "rig/runtime/lockstep.h"
#include "rig/runtime/realtime.h"
#include "rig/wire/wire_adapters.h"

namespace rig::harness {

namespace {

// SCHED_FIFO priority the harness asks for in real-time runs (the controller asks for 40).
constexpr int kRealtimePriority = 50;
// The threads that carry the bench wires' bytes (the Modbus slave answering a
// board's polls, the pty forwarder): above the controller, so a board's request
// is answered on time however busy the machine, below the master, whose
// deadlines make the devices' timing.
constexpr int kWireThreadPriority = 45;
// The session's weight against the machine's other sessions while a real-time
// case runs (rig/runtime/realtime.h SessionCpuWeight): nice -10 weighs 9548
// against a nice-0 session's 1024, so beside a build in each of three other
// sessions it still gets about three quarters of the machine when its
// time-sharing work (the cameras' rendering, the controller) has something to
// do. Measured: with the session at nice 0 (its rendering threads at nice
// -10 within it) and builds running in three other sessions, a camera's
// rendering fell 974 ms behind its frames (docs/seed001-vision.md).
constexpr int kRealtimeSessionNice = -10;
// A bench wire whose bytes wait unread this long has nobody on its far end.
constexpr std::chrono::milliseconds kWireUnreadBound{2000};

// Everything no node reports, checked in every wait slice and after every round:
// a stop signal, the case's wall-time bound, roles seen in discovery, forged
// samples, a bench wire nobody reads. Throws NodeFailure naming the culprit.
//
// While the master starts, a role broken by an endpoint discovery saw is held
// until the hellos are checked: a node that declares the topic in its hello
// is then caught by its hello, the same point and the same reason in every
// run, however its announcement raced its hello (docs/controller-contract.md
// section 4, docs/metrics.md "Topic roles"). An undeclared one is thrown right
// after the hello check.
class Watchdog {
public:
    Watchdog(const TimeoutsSpec& timeouts, const WallStopwatch& wall, DdsContext& dds, TraceRecorder& trace,
             CaseSession& session, const TimeNs& now_ns, CaseClock* clock)
        : timeouts_(timeouts), wall_(wall), dds_(dds), trace_(trace), session_(session), now_ns_(now_ns), clock_(clock) {}

    void operator()() {
        // Called after every round and in every wait slice: the case's clock for a progress display.
        if (clock_ != nullptr) clock_->now_ns.store(now_ns_, std::memory_order_relaxed);
        if (const int signal = run_interrupt_signal()) {
            throw NodeFailure(FailureKind::interrupted, "harness", describe_signal(signal));
        }
        if (wall_.elapsed_s() > timeouts_.case_wall_s) {
            throw NodeFailure(FailureKind::wall_time_exceeded, "harness",
                              "case exceeded its wall-time bound of " + std::to_string(timeouts_.case_wall_s) + " s");
        }
        const std::vector<DiscoveredEndpoint> found = dds_.take_discoveries();
        trace_.file().record_discoveries(now_ns_, found);
        for (const DiscoveredEndpoint& endpoint : found) {
            if (endpoint.removed) continue;
            if (endpoint.writer) writer_types_[endpoint.topic] = endpoint.type;
            if (const auto why = topic_role_violation(endpoint.writer ? "writer" : "reader", endpoint.topic)) {
                NodeFailure violation(FailureKind::topic_role_violation, endpoint.participant,
                                      *why + " (GUID prefix " + endpoint.guid_prefix + ", seen by discovery)");
                if (!holding_) throw violation;
                if (!held_) held_ = std::move(violation);
            }
        }
        if (!trace_.foreign_samples().empty()) {
            const ForeignSample& forged = trace_.foreign_samples().front();
            throw NodeFailure(FailureKind::topic_role_violation, forged.participant,
                              "wrote on " + forged.topic + ", a topic only the rig may write (forged sample at t=" +
                                  std::to_string(ns_to_seconds(forged.t_ns)) + " s)");
        }
        if (const std::string problem = session_.wire_problem(kWireUnreadBound); !problem.empty()) {
            throw NodeFailure(FailureKind::wire_unread, "harness", problem);
        }
    }

    // From the master's start to its hello check: discovery's role violations are held.
    void hold_discovery_violations() { holding_ = true; }
    // The hellos are checked (or there were none): a held violation is thrown
    // now, and later ones as discovery sees them.
    void release_discovery_violations() {
        holding_ = false;
        if (held_) {
            const NodeFailure violation = *held_;
            held_.reset();
            throw violation;
        }
    }
    // The start-up ended in `failure` before its hellos were checked: a
    // violation held by then was seen first and is the run's end, unless
    // `failure` is a stop signal (the operator's, whatever the node did) or
    // the hello's own violation.
    void prefer_held_violation_to(const NodeFailure& failure) {
        holding_ = false;
        if (held_ && failure.kind() != FailureKind::interrupted && failure.kind() != FailureKind::topic_role_violation) {
            throw *held_;
        }
    }

    // The type another process's writer announced for a topic, once discovery saw it.
    std::optional<std::string> writer_type(const std::string& topic) const {
        const auto it = writer_types_.find(topic);
        return it == writer_types_.end() ? std::nullopt : std::optional<std::string>(it->second);
    }

private:
    std::map<std::string, std::string> writer_types_;
    bool holding_ = false;
    std::optional<NodeFailure> held_;
    const TimeoutsSpec& timeouts_;
    const WallStopwatch& wall_;
    DdsContext& dds_;
    TraceRecorder& trace_;
    CaseSession& session_;
    const TimeNs& now_ns_;
    CaseClock* clock_;
};

// What the controller said in its hello. A topic it may not read or write
// fails the case here, before time starts: the same point in every run, where
// discovery would tell it whenever its announcement happened to arrive (and
// the trace would hold a varying part of the first instant); what discovery
// found before it waits for this check (Watchdog). Topics it writes
// that the rig has no type for (its own diagnostics) are recorded as raw
// samples, so they are matched, counted and kept like any other.
void check_hello_topics(const std::vector<LockstepMaster::HelloTopics>& hellos, TraceRecorder& trace,
                        Watchdog& watchdog) {
    for (const LockstepMaster::HelloTopics& hello : hellos) {
        if (const auto why = declared_role_violation(hello.subscribed, hello.published)) {
            throw NodeFailure(FailureKind::topic_role_violation, hello.node, *why);
        }
    }
    watchdog.release_discovery_violations();
    std::set<std::string> unknown;
    for (const LockstepMaster::HelloTopics& hello : hellos) {
        for (const std::string& topic : hello.published) {
            if (!trace.records(topic) && topic != topics::kClockAck) unknown.insert(topic);
        }
    }
    const WallStopwatch waited;
    for (const std::string& topic : unknown) {
        // Discovery tells the type name; it has normally arrived with the hello.
        while (!watchdog.writer_type(topic)) {
            if (waited.elapsed() > std::chrono::seconds(10)) {
                throw NodeFailure(FailureKind::startup_timeout, "controller",
                                  "its hello lists topic " + topic + ", but no writer of it was discovered within 10 s");
            }
            watchdog();
            pause_between_polls(std::chrono::milliseconds(5));
        }
        trace.record_raw(topic, *watchdog.writer_type(topic));
    }
}

// Starts `master` with discovery's role violations held until its hellos are
// checked (Watchdog above).
template <class Master>
void start_hellos_first(Master& master, Watchdog& watchdog) {
    watchdog.hold_discovery_violations();
    try {
        master.start();
    } catch (const NodeFailure& failure) {
        watchdog.prefer_held_violation_to(failure);
        throw;
    }
    watchdog.release_discovery_violations();  // a run without remote nodes has no hello
}

// The rig's own lateness against the case's bound, for the judge's verdict
// (judge.cpp: a non-empty `overloaded` makes the run invalid).
nlohmann::json lateness_json(const LatenessVerdict& verdict, const std::optional<RigFaultsSpec>& faults) {
    nlohmann::json devices = nlohmann::json::object();
    for (const auto& [device, mine] : verdict.devices) {
        devices[device] = {{"emissions", mine.emissions},
                           {"late", mine.late},
                           {"max_ms", mine.max_ms},
                           {"max_at_s", ns_to_seconds(mine.max_deadline_ns)}};
    }
    const bool any_late = !verdict.first_late_device.empty();
    nlohmann::json own_limits = nlohmann::json::object();
    for (const auto& [device, limits] : verdict.bound.devices) {
        own_limits[device] = {{"late_after_ms", limits.late_after_ms},
                              {"max_late_pct", limits.max_late_pct},
                              {"max_lateness_ms", limits.max_lateness_ms}};
    }
    return {{"bound",
             {{"late_after_ms", verdict.bound.late_after_ms},
              {"max_late_pct", verdict.bound.max_late_pct},
              {"max_lateness_ms", verdict.bound.max_lateness_ms},
              {"devices", std::move(own_limits)}}},
            {"emissions", verdict.emissions},
            {"late", verdict.late},
            {"late_pct", verdict.late_pct},
            {"max_ms", verdict.max_ms},
            {"worst_device", verdict.worst_device},
            {"worst_at_s", ns_to_seconds(verdict.worst_deadline_ns)},
            {"first_late_device", any_late ? nlohmann::json(verdict.first_late_device) : nlohmann::json(nullptr)},
            {"first_late_at_s", any_late ? nlohmann::json(ns_to_seconds(verdict.first_late_deadline_ns)) : nlohmann::json(nullptr)},
            {"devices", std::move(devices)},
            {"injected_stall", faults ? nlohmann::json{{"at_s", faults->master_stall_at_s}, {"for_s", faults->master_stall_for_s}}
                                      : nlohmann::json(nullptr)},
            {"overloaded", verdict.overloaded}};
}

LockstepTimeouts timeouts_of(const TimeoutsSpec& spec) {
    LockstepTimeouts timeouts;
    timeouts.ack = std::chrono::milliseconds(static_cast<long>(spec.node_ack_s * 1000));
    return timeouts;
}

// Lockstep: virtual time, jumping from wake-up to wake-up (rig/runtime/lockstep.h).
void run_lockstep(const TimeoutsSpec& timeouts, DdsContext& dds, SystemNodes& nodes, CaseSession& session,
                  TraceRecorder& trace, Watchdog& watchdog, TimeNs end_ns, TimeNs& now_ns, RunFacts& facts,
                  const WallStopwatch& wall) {
    LockstepMaster master(dds, timeouts_of(timeouts));
    if (TruthModel* truth = nodes.truth()) master.add_truth_model(*truth);
    for (Node* node : nodes.nodes()) master.add_local_node(*node);
    if (session.has_controller_process()) master.add_remote_node("controller", [&session] { return session.controller_gone(); });
    if (InProcessController* controller = session.in_process_controller()) {
        master.add_in_process_node(controller->node(), controller->dds());
    }
    master.set_after_round([&](TimeNs t, int round) {
        ++facts.rounds;
        now_ns = t;
        trace.drain(t, round);
    });
    master.set_watchdog([&watchdog] { watchdog(); });
    master.set_after_hello([&](const std::vector<LockstepMaster::HelloTopics>& hellos) {
        check_hello_topics(hellos, trace, watchdog);
    });
    try {
        start_hellos_first(master, watchdog);
        facts.startup_wall_seconds = wall.elapsed_s();
        const std::uint64_t allocations_before = heap_allocations();
        while (master.advance(end_ns)) ++facts.instants;
        facts.stepping_wall_seconds = wall.elapsed_s() - facts.startup_wall_seconds;
        add_stepping_allocations(heap_allocations() - allocations_before);
        master.shutdown();
    } catch (const NodeFailure&) {
        master.shutdown(/*after_failure=*/true);
        throw;
    }
}

// The bench wires' threads at SCHED_FIFO `priority`; what was granted, for the run's facts.
std::string raise_wire_threads(BenchWires& wires, int priority) {
    std::vector<std::string> refused;
    int raised = 0;
    const auto raise = [&](const std::string& what, const std::string& why_not) {
        if (why_not.empty()) ++raised;
        else refused.push_back(what + ": " + why_not);
    };
    if (wires.modbus_link) raise("pty forwarder", wires.modbus_link->raise_to_realtime(priority));
    if (auto* modbus_wire = dynamic_cast<ModbusSlaveWire*>(wires.board_io.get())) {
        raise("Modbus slave", modbus_wire->slave().raise_to_realtime(priority));
    }
    if (raised == 0 && refused.empty()) return {};
    std::string text = "; wire threads: " + std::to_string(raised) + " at SCHED_FIFO " + std::to_string(priority);
    for (const std::string& why : refused) text += ", " + why;
    return text;
}

// Real time: the wall clock, for a board on real wires (rig/runtime/realtime.h).
// `truth`, if any, is advanced to each pass's instant before the nodes step.
void run_realtime(const CaseSpec& spec, DdsContext& dds, SystemNodes& nodes, CaseSession& session, TraceRecorder& trace,
                  Watchdog& watchdog, TimeNs end_ns, TimeNs& now_ns, RunFacts& facts,
                  std::optional<BoardAttachment>& board, const WallStopwatch& wall) {
    facts.realtime_scheduling = request_realtime_scheduling(kRealtimePriority).detail;
    facts.realtime_scheduling += raise_wire_threads(session.wires(), kWireThreadPriority);
    const SessionCpuWeight session_weight(kRealtimeSessionNice);
    facts.realtime_scheduling += "; " + session_weight.detail();
    RealtimeMaster master(dds, timeouts_of(spec.timeouts));
    if (TruthModel* truth = nodes.truth()) master.add_truth_model(*truth);
    for (Node* node : nodes.nodes()) master.add_local_node(*node);
    if (session.has_controller_process()) master.add_remote_node("controller", [&session] { return session.controller_gone(); });
    if (auto* modbus_wire = dynamic_cast<ModbusSlaveWire*>(session.wires().board_io.get())) {
        modbus_wire->set_wake([&dds] { dds.notify_data_arrived(); });
    }
    BoardSilenceWatch board_silence(spec.board, session.wires());
    master.set_after_step([&](TimeNs t) {
        now_ns = t;
        trace.drain(t, 0);
        board_silence.check(t);
    });
    master.set_watchdog([&watchdog] { watchdog(); });
    master.set_after_hello([&](const std::vector<LockstepMaster::HelloTopics>& hellos) {
        check_hello_topics(hellos, trace, watchdog);
    });
    for (const auto& [device, limits] : spec.realtime.devices) {
        const std::vector<Node*> all = nodes.nodes();
        if (std::none_of(all.begin(), all.end(), [&](const Node* node) { return node->name() == device; })) {
            std::string names;
            for (const Node* node : all) names += (names.empty() ? "" : ", ") + node->name();
            throw std::runtime_error(spec.source_path.string() + ": realtime.devices." + device +
                                     ": no device of that name in this case (its devices: " + names + ")");
        }
    }
    master.set_lateness_bound(spec.realtime);
    if (spec.rig_faults) {
        master.inject_stall(seconds_to_ns(spec.rig_faults->master_stall_at_s),
                            seconds_to_ns(spec.rig_faults->master_stall_for_s));
    }
    auto collect_jitter = [&] {
        facts.lateness = lateness_json(master.lateness(), spec.rig_faults);
        for (const auto& [device, stats] : master.emission_jitter()) {
            // Nodes that only react to inputs (the NMEA serial adapter, a switch
            // never toggled) had no deadline to be late for: nothing to report.
            if (stats.samples == 0) continue;
            facts.emission_jitter.push_back(EmissionJitter{device, stats.samples, stats.p50_ms, stats.p99_ms,
                                                           stats.max_ms, stats.step_p99_ms, stats.step_max_ms});
        }
    };
    try {
        // A wired board: case time starts once it has attached (harness/board_attach.h).
        if (spec.wiring.external_controller) {
            board = wait_for_board(spec.board, session.wires(), [&watchdog] { watchdog(); });
        }
        start_hellos_first(master, watchdog);
        facts.startup_wall_seconds = wall.elapsed_s();
        master.run_until(end_ns);
        master.shutdown();
    } catch (const NodeFailure&) {
        master.shutdown(/*after_failure=*/true);
        collect_jitter();
        throw;
    } catch (const std::exception& error) {
        // A local node's step (a wire adapter) threw: the rig's side of a wire failed.
        master.shutdown(/*after_failure=*/true);
        collect_jitter();
        throw NodeFailure(FailureKind::harness_error, "harness", error.what());
    }
    collect_jitter();
}

}  // namespace

std::string describe_signal(int signal) {
    return std::string("stopped by ") + (signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : strsignal(signal));
}


void run_loop(const CaseSpec& spec, DdsContext& dds, SystemNodes& nodes, CaseSession& session, TraceRecorder& trace,
              const WallStopwatch& wall, TimeNs end_ns, TimeNs& now_ns, RunFacts& facts,
              std::optional<BoardAttachment>& board, CaseClock* clock) {
    Watchdog watchdog(spec.timeouts, wall, dds, trace, session, now_ns, clock);
    if (spec.mode == ClockMode::lockstep) {
        run_lockstep(spec.timeouts, dds, nodes, session, trace, watchdog, end_ns, now_ns, facts, wall);
    } else {
        run_realtime(spec, dds, nodes, session, trace, watchdog, end_ns, now_ns, facts, board, wall);
    }
}

}  // namespace rig::harness
