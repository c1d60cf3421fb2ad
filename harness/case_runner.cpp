#include "harness/case_runner.h"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstring>
#include <iostream>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "controller/boundary/boundary_node_config.h"
#include "emulators/boom_height_sensor.h"
#include "emulators/flow_meter_kf11.h"
#include "emulators/panel_switch.h"
#include "emulators/plant.h"
#include "emulators/pump_flow_sensor.h"
#include "emulators/spray_circuit.h"
#include "emulators/spray_circuit_node.h"
#include "emulators/wheel_encoder.h"
#include "harness/board_attach.h"
#include "harness/boundary_runner.h"
#include "harness/case_session.h"
#include "harness/case_world.h"
#include "harness/dds_security_setup.h"
#include "harness/realtime_case_loop.h"
#include "harness/run_interrupt.h"
#include "harness/run_progress.h"
#include "harness/trace_recorder.h"
#include "harness/wire_fault_report.h"
#include "idl/topics.h"
#include "rig/host/cpu_lease.h"
#include "rig/runtime/lockstep.h"
#include "rig/runtime/realtime.h"
#include "rig/wire/wire_adapters.h"

namespace rig::harness {

namespace {

constexpr double kVehicleTruthRateHz = 20.0;
constexpr double kHydraulicsTruthRateHz = 100.0;
// SCHED_FIFO priority the harness asks for in real-time runs (the controller asks for 40).
constexpr int kRealtimePriority = 50;
// The threads that carry the bench wires' bytes (the Modbus slave answering a
// board's polls, the pty forwarder): above the controller, so a board's request
// is answered on time however busy the machine, below the master, whose
// deadlines make the devices' timing.
constexpr int kWireThreadPriority = 45;
// A bench wire whose bytes wait unread this long has nobody on its far end.
constexpr std::chrono::milliseconds kWireUnreadBound{2000};

// The device emulators and the plant as the case's local nodes, in the order
// they step each instant: plant truth and the spray circuit (which takes the
// actuator commands) before the devices sample them, the wire adapters last
// (they carry what the devices published). The circuit itself is the master's
// to advance (`truth`), once per instant before any of them steps.
struct LocalNodes {
    LocalNodes(const CaseSpec& spec, const CaseWorld& world, emulators::SprayCircuit& circuit, std::uint64_t seed,
               BenchWires& wires)
        : truth(circuit),
          plant(world.plant, kVehicleTruthRateHz),
          spray_circuit(circuit, kHydraulicsTruthRateHz),
          gnss(world.plant, world.gnss),
          encoder(world.plant, emulators::WheelEncoderParams{spec.encoder.pulses_per_rev,
                                                             spec.encoder.wheel_diameter_m, spec.encoder.rate_hz}),
          flow_meter(circuit, emulators::Kf11Params{spec.flow_meter.pulses_per_l, spec.flow_meter.k_factor_error_pct,
                                                    0.27, spec.flow_meter.rate_hz}),
          pump_sensor(circuit, emulators::PumpFlowSensorParams{spec.pump_sensor.full_scale_m3_h, spec.pump_sensor.noise_mv,
                                                               spec.pump_sensor.offset_ma, spec.pump_sensor.rate_hz, seed}),
          boom_height(world.plant,
                      emulators::BoomHeightSensorParams{spec.boom_height_sensor.range_m, spec.boom_height_sensor.rate_hz}),
          button("breakpoint_button", topics::kBreakpointButton, world.scenario.button),
          spray_switch("spray_switch", topics::kSpraySwitch, world.scenario.spray_switch) {
        all = {&plant, &spray_circuit, &gnss, &encoder, &flow_meter, &pump_sensor, &boom_height, &button, &spray_switch};
        if (wires.gnss_port) all.push_back(&nmea_adapter.emplace(*wires.gnss_port));
        if (wires.board_io) all.push_back(&board_adapter.emplace(*wires.board_io, spec.wiring.board_update_hz));
    }
    TruthModel& truth;
    emulators::PlantNode plant;
    emulators::SprayCircuitNode spray_circuit;
    emulators::GnssG970 gnss;
    emulators::WheelEncoder encoder;
    emulators::FlowMeterKf11 flow_meter;
    emulators::PumpFlowSensor pump_sensor;
    emulators::BoomHeightSensor boom_height;
    emulators::PanelSwitch button;
    emulators::PanelSwitch spray_switch;
    std::optional<NmeaSerialAdapter> nmea_adapter;
    std::optional<BoardIoAdapter> board_adapter;
    std::vector<Node*> all;
};

// What the run learnt about itself, for the trace's meta `run` (results.json echoes it).
struct RunFacts {
    std::string controller_mode;     // process, in_process, external
    std::string in_process_refused;  // asked for in process, ran as a process: why
    double startup_wall_seconds = 0.0;
    // Lockstep: simulated instants processed and rounds run (a round: the local
    // nodes, then one tick to the controller and its answer), and the wall time
    // from the end of start-up to the last instant (rig bench's per-round cost).
    std::uint64_t instants = 0;
    std::uint64_t rounds = 0;
    double stepping_wall_seconds = 0.0;
    std::string realtime_scheduling;
    std::string cpu_placement = describe_thread_placement();  // rig/host/cpu_lease.h
    std::vector<EmissionJitter> emission_jitter;
    nlohmann::json lateness;  // real time: lateness_json(), null in lockstep
    std::optional<BoardAttachment> board_attachment;  // controller: external
    nlohmann::json board_io;  // harness/board_attach.h board_io_report(), null without a Modbus wire
};

std::string describe_signal(int signal) {
    return std::string("stopped by ") + (signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : strsignal(signal));
}

// Everything no node reports, checked in every wait slice and after every round:
// a stop signal, the case's wall-time bound, roles seen in discovery, forged
// samples, a bench wire nobody reads. Throws NodeFailure naming the culprit.
class Watchdog {
public:
    Watchdog(const CaseSpec& spec, const WallStopwatch& wall, DdsContext& dds, TraceRecorder& trace,
             CaseSession& session, const TimeNs& now_ns, CaseClock* clock)
        : spec_(spec), wall_(wall), dds_(dds), trace_(trace), session_(session), now_ns_(now_ns), clock_(clock) {}

    void operator()() {
        // Called after every round and in every wait slice: the case's clock for a progress display.
        if (clock_ != nullptr) clock_->now_ns.store(now_ns_, std::memory_order_relaxed);
        if (const int signal = run_interrupt_signal()) {
            throw NodeFailure(FailureKind::interrupted, "harness", describe_signal(signal));
        }
        if (wall_.elapsed_s() > spec_.timeouts.case_wall_s) {
            throw NodeFailure(FailureKind::wall_time_exceeded, "harness",
                              "case exceeded its wall-time bound of " + std::to_string(spec_.timeouts.case_wall_s) + " s");
        }
        const std::vector<DiscoveredEndpoint> found = dds_.take_discoveries();
        trace_.file().record_discoveries(now_ns_, found);
        for (const DiscoveredEndpoint& endpoint : found) {
            if (endpoint.removed) continue;
            if (endpoint.writer) writer_types_[endpoint.topic] = endpoint.type;
            if (const auto why = topic_role_violation(endpoint.writer ? "writer" : "reader", endpoint.topic)) {
                throw NodeFailure(FailureKind::topic_role_violation, endpoint.participant,
                                  *why + " (GUID prefix " + endpoint.guid_prefix + ", seen by discovery)");
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

    // The type another process's writer announced for a topic, once discovery saw it.
    std::optional<std::string> writer_type(const std::string& topic) const {
        const auto it = writer_types_.find(topic);
        return it == writer_types_.end() ? std::nullopt : std::optional<std::string>(it->second);
    }

private:
    std::map<std::string, std::string> writer_types_;
    const CaseSpec& spec_;
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
// the trace would hold a varying part of the first instant). Topics it writes
// that the rig has no type for (its own diagnostics) are recorded as raw
// samples, so they are matched, counted and kept like any other.
void check_hello_topics(const std::vector<LockstepMaster::HelloTopics>& hellos, TraceRecorder& trace,
                        Watchdog& watchdog) {
    for (const LockstepMaster::HelloTopics& hello : hellos) {
        if (const auto why = declared_role_violation(hello.subscribed, hello.published)) {
            throw NodeFailure(FailureKind::topic_role_violation, hello.node, *why);
        }
    }
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
    return {{"bound",
             {{"late_after_ms", verdict.bound.late_after_ms},
              {"max_late_pct", verdict.bound.max_late_pct},
              {"max_lateness_ms", verdict.bound.max_lateness_ms}}},
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

LockstepTimeouts timeouts_of(const CaseSpec& spec) {
    LockstepTimeouts timeouts;
    timeouts.ack = std::chrono::milliseconds(static_cast<long>(spec.timeouts.node_ack_s * 1000));
    return timeouts;
}

// Lockstep: virtual time, jumping from wake-up to wake-up (rig/runtime/lockstep.h).
void run_lockstep(const CaseSpec& spec, DdsContext& dds, LocalNodes& nodes, CaseSession& session,
                  TraceRecorder& trace, Watchdog& watchdog, TimeNs end_ns, TimeNs& now_ns, RunFacts& facts,
                  const WallStopwatch& wall) {
    LockstepMaster master(dds, timeouts_of(spec));
    master.add_truth_model(nodes.truth);
    for (Node* node : nodes.all) master.add_local_node(*node);
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
        master.start();
        facts.startup_wall_seconds = wall.elapsed_s();
        while (master.advance(end_ns)) ++facts.instants;
        facts.stepping_wall_seconds = wall.elapsed_s() - facts.startup_wall_seconds;
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
void run_realtime(const CaseSpec& spec, DdsContext& dds, const std::vector<Node*>& nodes, TruthModel* truth,
                  CaseSession& session, TraceRecorder& trace, Watchdog& watchdog, TimeNs end_ns, TimeNs& now_ns,
                  RunFacts& facts, const WallStopwatch& wall) {
    facts.realtime_scheduling = request_realtime_scheduling(kRealtimePriority).detail;
    facts.realtime_scheduling += raise_wire_threads(session.wires(), kWireThreadPriority);
    RealtimeMaster master(dds, timeouts_of(spec));
    if (truth != nullptr) master.add_truth_model(*truth);
    for (Node* node : nodes) master.add_local_node(*node);
    if (session.has_controller_process()) master.add_remote_node("controller", [&session] { return session.controller_gone(); });
    if (auto* modbus_wire = dynamic_cast<ModbusSlaveWire*>(session.wires().board_io.get())) {
        modbus_wire->set_wake([&dds] { dds.notify_data_arrived(); });
    }
    BoardSilenceWatch board_silence(spec, session.wires());
    master.set_after_step([&](TimeNs t) {
        now_ns = t;
        trace.drain(t, 0);
        board_silence.check(t);
    });
    master.set_watchdog([&watchdog] { watchdog(); });
    master.set_after_hello([&](const std::vector<LockstepMaster::HelloTopics>& hellos) {
        check_hello_topics(hellos, trace, watchdog);
    });
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
            facts.board_attachment = wait_for_board(spec, session.wires(), [&watchdog] { watchdog(); });
        }
        master.start();
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

nlohmann::json run_facts_json(const RunFacts& facts, double wall_seconds) {
    nlohmann::json jitter = nlohmann::json::array();
    for (const EmissionJitter& device : facts.emission_jitter) {
        jitter.push_back({{"device", device.device},
                          {"samples", device.samples},
                          {"p50_ms", device.p50_ms},
                          {"p99_ms", device.p99_ms},
                          {"max_ms", device.max_ms},
                          {"step_p99_ms", device.step_p99_ms},
                          {"step_max_ms", device.step_max_ms}});
    }
    nlohmann::json run = {{"wall_seconds", wall_seconds},
                          {"controller_mode", facts.controller_mode},
                          {"in_process_refused", facts.in_process_refused},
                          {"startup_wall_seconds", facts.startup_wall_seconds},
                          {"instants", facts.instants},
                          {"rounds", facts.rounds},
                          {"stepping_wall_seconds", facts.stepping_wall_seconds},
                          {"realtime_scheduling", facts.realtime_scheduling},
                          {"cpu_placement", facts.cpu_placement},
                          {"emission_jitter", std::move(jitter)}};
    if (!facts.board_io.is_null()) run["board_io"] = facts.board_io;
    if (!facts.lateness.is_null()) run["lateness"] = facts.lateness;
    return run;
}

// A case that could not even start (no trace to judge): its result from what is known.
CaseRun unstarted_run(const CaseSpec& spec, std::uint64_t seed, const std::string& run_name, FailureKind kind,
                      const std::string& error, double wall_seconds) {
    CaseRun run;
    CaseResult& result = run.result;
    result.name = run_name;
    result.file = spec.source_path.string();
    result.seed = seed;
    result.mode = std::string(to_string(spec.mode));
    result.limits = effective_limits(spec);
    const ExpectSpec expect = applied_expectation(spec, &result.expectation_set_aside);
    result.expected_error = expect.error;
    result.error_kind = std::string(to_string(kind));
    result.error = error;
    result.wall_seconds = wall_seconds;
    const CaseVerdict verdict =
        judge_case(VerdictInputs{{}, {}, result.limits, expect.fail, expect.error, result.error_kind, error});
    result.failures = verdict.failures;
    result.expected_failure = verdict.expected_failure;
    result.passed = verdict.passed;
    run.figures.breakpoint_along_m = spec.breakpoint.along_m;
    return run;
}

}  // namespace

void run_case_in_realtime(const CaseSpec& spec, DdsContext& dds, const std::vector<Node*>& nodes, CaseSession& session,
                          TraceRecorder& trace, const WallStopwatch& wall, TimeNs end_ns, TimeNs& now_ns,
                          CaseClock* clock, nlohmann::json& run_facts) {
    RunFacts facts;
    facts.controller_mode = session.controller_mode();
    Watchdog watchdog(spec, wall, dds, trace, session, now_ns, clock);
    const auto record_facts = [&] {
        facts.board_io = board_io_report(spec, session.wires(), facts.board_attachment);
        run_facts = run_facts_json(facts, wall.elapsed_s());
    };
    try {
        run_realtime(spec, dds, nodes, nullptr, session, trace, watchdog, end_ns, now_ns, facts, wall);
    } catch (...) {
        record_facts();
        throw;
    }
    record_facts();
}

void validate_for_run(const CaseSpec& spec, const RunOptions& options) {
    // A wired board's valve commands come over its wire, and the rig's own
    // bridge puts them on the actuator topics, which the rig's identity may
    // not write (docs/dds-security.md): DDS-Security protects none of that.
    if (options.dds_security_dir && spec.wiring.board_io != BoardIoWireKind::dds) {
        throw std::runtime_error(spec.source_path.string() + ": wiring.board_io " +
                                 std::string(to_string(spec.wiring.board_io)) +
                                 ": the controller's commands come over the wire and the rig writes them on the "
                                 "actuator topics itself; run it without --dds-security");
    }
    // Seed 001's reference boundary controller (a program; its configuration
    // library is the harness's too).
    if (spec.system == CaseSystem::boundary && spec.controller.command.empty()) {
        controller::boundary::parse_boundary_node_config(YamlSection(spec.controller.params));
        return;
    }
    // The controller's own keys are checked before anything starts, by its
    // plugin (the harness does not link the reference controller): the
    // reference controller's, or the plugin a case names. A program without a
    // plugin checks its section itself when it starts.
    const std::filesystem::path plugin = controller_plugin_of(spec, options);
    if (plugin.empty() || spec.wiring.external_controller) return;
    const auto library = load_controller_plugin(plugin);
    const std::string error =
        library->check_config(NodePluginCaseText{spec.source_path.string(), spec.source_text, "controller"});
    if (!error.empty()) throw std::runtime_error(error);
}

std::vector<CaseInstance> expand_runs(const std::vector<CaseSpec>& specs, const RunOptions& options) {
    std::vector<CaseInstance> runs;
    for (std::size_t i = 0; i < specs.size(); ++i) {
        const CaseSpec& spec = specs[i];
        if (!options.seed_sweep.empty()) {
            for (std::uint64_t seed : options.seed_sweep) {
                runs.push_back(CaseInstance{i, seed, spec.name + "-seed" + std::to_string(seed)});
            }
            continue;
        }
        if (spec.seeds.empty()) {
            runs.push_back(CaseInstance{i, options.seed_override.value_or(spec.seed), spec.name});
            continue;
        }
        const std::vector<std::uint64_t> seeds =
            options.seed_override ? std::vector<std::uint64_t>{*options.seed_override} : spec.seeds;
        for (std::uint64_t seed : seeds) runs.push_back(CaseInstance{i, seed, spec.name + "-seed" + std::to_string(seed)});
    }
    return runs;
}

CaseRun run_case(const CaseSpec& spec, const RunOptions& options) {
    const std::vector<CaseInstance> runs = expand_runs({spec}, options);
    return run_case(spec, runs.front().seed, runs.front().name, options);
}

CaseRun run_case(const CaseSpec& spec, std::uint64_t seed, const std::string& run_name, const RunOptions& options) {
    // A lockstep case's chain of hand-offs (this thread, Fast DDS's threads, the
    // controller process) on one CPU; a real-time case keeps the scheduler's.
    const CpuLease cpu(options.pin_cpu && spec.mode == RunMode::lockstep);
    if (spec.system == CaseSystem::boundary) return run_boundary_case(spec, seed, run_name, options);
    const WallStopwatch wall;
    const std::filesystem::path case_dir = options.out_dir / "cases" / run_name;
    const std::filesystem::path trace_file = case_dir / "trace.sqlite";
    try {
        std::filesystem::remove_all(case_dir);
        std::filesystem::create_directories(case_dir / "controller-state");

        const CaseWorld world = build_case_world(spec, seed);
        emulators::SprayCircuit circuit(world.plant, world.circuit);
        CaseSession session(spec, case_dir, options.domain, options.open_hid);
        // The harness's participant first, watching discovery; then the
        // controller, so every endpoint it makes is seen.
        DdsContext dds(session.domain_id(), "harness", /*watch_discovery=*/true, reliability_timers_for(spec.mode));
        const ControllerPlacement placement = place_controller(spec, options);
        std::string in_process_refused = placement.refused;
        if (placement.plugin) in_process_refused = session.start_in_process_controller(spec, *placement.plugin, case_dir, dds);
        session.start_controller(spec, options.controller_executable, case_dir,
                                 dds_security_environment(options.dds_security_dir, kControllerIdentity));
        TraceRecorder trace(dds, trace_file);
        trace.file().set_meta("case", run_name);
        trace.file().set_meta("case_file", spec.source_path.string());
        trace.file().set_meta("case_yaml", spec.source_text);
        trace.file().set_meta("scenario", std::string(to_string(spec.scenario)));
        trace.file().set_meta("mode", std::string(to_string(spec.mode)));
        trace.file().set_meta("seed", std::to_string(seed));
        trace.file().set_meta("controller_command", session.controller_command_line());
        trace.file().set_meta("wiring", session.wires().description);
        trace.file().set_meta("dds_domain", std::to_string(session.domain_id()));
        trace.file().set_meta("harness_guid_prefix", dds.guid_prefix());
        if (options.dds_security_dir) trace.file().set_meta("dds_security", options.dds_security_dir->string());
        trace.file().set_meta("judging", to_json(plan_judging(spec, world)).dump());
        if (spec.wiring.external_controller) announce_attach(spec, session.wires(), run_name, case_dir, std::cout);
        trace.set_vehicle_truth_probe([&world](TimeNs t) { return world.plant.truth_at(t); });
        // Nodes hold DDS writers, so they are declared after (and destroyed before) the context.
        LocalNodes nodes(spec, world, circuit, seed, session.wires());
        install_line_noise(spec, seed, session.wires());  // board.line_noise, if any

        TimeNs now_ns = 0;
        RunFacts facts;
        facts.controller_mode = session.controller_mode();
        facts.in_process_refused = in_process_refused;
        if (options.clock != nullptr) options.clock->end_ns.store(world.end_ns, std::memory_order_relaxed);
        Watchdog watchdog(spec, wall, dds, trace, session, now_ns, options.clock);
        const TraceOutcome outcome = session.run_to_outcome(
            [&] {
                if (spec.mode == RunMode::lockstep) {
                    run_lockstep(spec, dds, nodes, session, trace, watchdog, world.end_ns, now_ns, facts, wall);
                } else {
                    run_realtime(spec, dds, nodes.all, &nodes.truth, session, trace, watchdog, world.end_ns, now_ns, facts, wall);
                }
                circuit.advance_to(world.end_ns);
            },
            world.end_ns, now_ns);
        // Whatever the ending, the spray on the ground so far is part of the record.
        trace.file().record_deposition(circuit.deposition());
        trace.file().record_landing_edges(circuit.landing_edges());
        facts.board_io = board_io_report(spec, session.wires(), facts.board_attachment);
        if (spec.gnss.wire_faults.any()) {
            trace.file().set_meta(kGnssWireFaultsMeta,
                                  gnss_wire_fault_json(spec.gnss.wire_faults, nodes.gnss.wire_fault_counts()).dump());
        }
        if (options.dds_security_dir) {
            // Who tried to join and was refused (not in the digest: it depends on who was around).
            trace.file().set_meta("dds_security_refused", nlohmann::json(dds.refused_participants()).dump());
        }
        trace.file().set_meta("run", run_facts_json(facts, wall.elapsed_s()).dump());
        trace.file().finish(outcome);
    } catch (const std::exception& error) {
        // The run could not be set up or recorded (a port that does not open, a
        // trace that cannot be written): there may be no trace to judge.
        const FailureKind kind = run_interrupt_signal() ? FailureKind::interrupted : FailureKind::harness_error;
        if (!std::filesystem::exists(trace_file)) {
            return unstarted_run(spec, seed, run_name, kind, error.what(), wall.elapsed_s());
        }
        try {
            RecordedTrace recorded = read_trace(trace_file);
            if (recorded.meta["outcome"] == "completed" || recorded.meta["outcome"] == "running") {
                return unstarted_run(spec, seed, run_name, kind, error.what(), wall.elapsed_s());
            }
        } catch (const std::exception&) {
            return unstarted_run(spec, seed, run_name, kind, error.what(), wall.elapsed_s());
        }
    }
    // The verdict, metrics and figures come from the recorded trace alone,
    // exactly as `rig judge` computes them from it later.
    try {
        return judge_trace(read_trace(trace_file));
    } catch (const std::exception& error) {
        return unstarted_run(spec, seed, run_name, FailureKind::harness_error, error.what(), wall.elapsed_s());
    }
}

std::vector<CaseRun> run_cases(const std::vector<CaseSpec>& specs, const RunOptions& options, std::ostream& progress) {
    CaseLineLog observer(progress, Verbosity::normal);
    return run_cases(specs, options, observer);
}

std::vector<CaseRun> run_cases(const std::vector<CaseSpec>& specs, const RunOptions& options, RunObserver& observer,
                               RunPhaseWalls* phase_walls) {
    const std::vector<CaseInstance> instances = expand_runs(specs, options);
    std::vector<CaseRun> runs(instances.size());
    observer.runs_planned(instances, specs);
    auto run_one = [&](std::size_t i) {
        const CaseInstance& instance = instances[i];
        const CaseSpec& spec = specs[instance.spec_index];
        observer.case_started(i);
        if (const int signal = run_interrupt_signal()) {
            runs[i] = unstarted_run(spec, instance.seed, instance.name, FailureKind::interrupted,
                                    "not run: " + describe_signal(signal) + " before it started", 0.0);
        } else {
            RunOptions case_options = options;
            case_options.clock = observer.case_clock(i);
            runs[i] = run_case(spec, instance.seed, instance.name, case_options);
        }
        observer.case_finished(i, runs[i].result);
        if (!options.keep_figures) runs[i].figures = CaseFigures{};
    };
    // Lockstep cases share the machine; a real-time case runs alone, after them,
    // so that other cases' load does not become its scheduling jitter.
    std::vector<std::size_t> lockstep, realtime;
    for (std::size_t i = 0; i < instances.size(); ++i) {
        (specs[instances[i].spec_index].mode == RunMode::realtime ? realtime : lockstep).push_back(i);
    }
    std::atomic<std::size_t> next{0};
    auto worker = [&] {
        for (std::size_t k = next++; k < lockstep.size(); k = next++) run_one(lockstep[k]);
    };
    const int jobs = std::max(1, std::min<int>(options.jobs, static_cast<int>(lockstep.size())));
    const WallStopwatch lockstep_phase;
    std::vector<std::thread> threads;
    for (int j = 0; j < jobs; ++j) threads.emplace_back(worker);
    for (auto& thread : threads) thread.join();
    if (phase_walls != nullptr) phase_walls->lockstep_seconds = lockstep_phase.elapsed_s();
    const WallStopwatch realtime_phase;
    for (std::size_t i : realtime) run_one(i);
    if (phase_walls != nullptr) phase_walls->realtime_seconds = realtime_phase.elapsed_s();
    return runs;
}

}  // namespace rig::harness
