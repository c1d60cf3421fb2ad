#include "harness/boundary_runner.h"

#include <csignal>
#include <cstring>
#include <iostream>
#include <memory>
#include <optional>

#include "harness/board_attach.h"
#include "harness/boundary_judge.h"
#include "harness/boundary_world.h"
#include "harness/case_session.h"
#include "harness/dds_security_setup.h"
#include "harness/realtime_case_loop.h"
#include "harness/run_interrupt.h"
#include "harness/trace_recorder.h"
#include "rig/host/cpu_lease.h"
#include "rig/runtime/lockstep.h"
#include "rig/wire/wire_adapters.h"

namespace rig::harness {
namespace {

// While nothing flows the plant reports truth this often (the 1-D plant's 20 Hz
// would double the trace for nothing: a still boom deposits nothing).
constexpr double kIdleTruthRateHz = 10.0;

// What no node reports, checked in every wait slice and after every round: a
// stop signal, the case's wall-time bound, roles seen in discovery, forged
// samples. Throws NodeFailure naming the culprit.
void check_run(const CaseSpec& spec, const WallStopwatch& wall, DdsContext& dds, TraceRecorder& trace, TimeNs now_ns) {
    if (const int signal = run_interrupt_signal()) {
        throw NodeFailure(FailureKind::interrupted, "harness",
                          std::string("stopped by ") + (signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : strsignal(signal)));
    }
    if (wall.elapsed_s() > spec.timeouts.case_wall_s) {
        throw NodeFailure(FailureKind::wall_time_exceeded, "harness",
                          "case exceeded its wall-time bound of " + std::to_string(spec.timeouts.case_wall_s) + " s");
    }
    const std::vector<DiscoveredEndpoint> found = dds.take_discoveries();
    trace.file().record_discoveries(now_ns, found);
    for (const DiscoveredEndpoint& endpoint : found) {
        if (endpoint.removed) continue;
        if (const auto why = topic_role_violation(endpoint.writer ? "writer" : "reader", endpoint.topic)) {
            throw NodeFailure(FailureKind::topic_role_violation, endpoint.participant,
                              *why + " (GUID prefix " + endpoint.guid_prefix + ", seen by discovery)");
        }
    }
    if (!trace.foreign_samples().empty()) {
        const ForeignSample& forged = trace.foreign_samples().front();
        throw NodeFailure(FailureKind::topic_role_violation, forged.participant,
                          "wrote on " + forged.topic + ", a topic only the rig may write");
    }
}

CaseRun run_without_trace(const CaseSpec& spec, std::uint64_t seed, const std::string& run_name, FailureKind kind,
                          const std::string& error, double wall_seconds) {
    CaseRun run;
    CaseResult& result = run.result;
    result.name = run_name;
    result.file = spec.source_path.string();
    result.seed = seed;
    result.mode = std::string(to_string(spec.mode));
    result.limits = spec.limits;
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
    return run;
}

std::string judging_json(const CaseSpec& spec) {
    JudgingPlan plan;
    plan.scenario = "boundary";
    plan.limits = spec.limits;
    const ExpectSpec expect = applied_expectation(spec, &plan.expect_set_aside);
    plan.expect_fail = expect.fail;
    plan.expect_error = expect.error;
    nlohmann::json json = to_json(plan);
    json["boundary"] = to_json(plan_boundary_judging(*spec.boundary));
    return json.dump();
}

}  // namespace

CaseRun run_boundary_case(const CaseSpec& spec, std::uint64_t seed, const std::string& run_name, const RunOptions& options) {
    const WallStopwatch wall;
    const std::filesystem::path case_dir = options.out_dir / "cases" / run_name;
    const std::filesystem::path trace_file = case_dir / "trace.sqlite";
    try {
        std::filesystem::remove_all(case_dir);
        std::filesystem::create_directories(case_dir / "controller-state");
        const BoundaryCaseSpec& boundary = *spec.boundary;
        const BoundaryWorld world(boundary, seed);
        CaseSession session(spec, case_dir, options.domain, options.open_hid);
        DdsContext dds(session.domain_id(), "harness", /*watch_discovery=*/true, reliability_timers_for(spec.mode));
        session.start_controller(spec, options.controller_executable.parent_path() / kBoundaryControllerExecutable, case_dir,
                                 dds_security_environment(options.dds_security_dir, kControllerIdentity));
        TraceRecorder trace(dds, trace_file);
        trace.record_boundary_topics();
        if (boundary.vision) trace.record_vision_topics();
        trace.file().set_meta("case", run_name);
        trace.file().set_meta("case_file", spec.source_path.string());
        trace.file().set_meta("case_yaml", spec.source_text);
        trace.file().set_meta("system", "boundary");
        trace.file().set_meta("scenario", "boundary");
        trace.file().set_meta("mode", std::string(to_string(spec.mode)));
        trace.file().set_meta("seed", std::to_string(seed));
        trace.file().set_meta("controller_command", session.controller_command_line());
        trace.file().set_meta("wiring", session.wires().description);
        trace.file().set_meta("dds_domain", std::to_string(session.domain_id()));
        trace.file().set_meta("harness_guid_prefix", dds.guid_prefix());
        trace.file().set_meta("judging", judging_json(spec));
        // Nodes hold DDS writers: declared after (destroyed before) the context.
        BoundaryPlantNode plant(world.kinematics,
                                emulators::PwmNozzleValves(world.valves, boundary.flow_table_or_paper()), boundary.spray,
                                kIdleTruthRateHz);
        Ad300Node ad300(world.kinematics, world.ad300);
        L4LaserNode laser(world.kinematics, world.laser);
        // The bench wires' adapters (real time only), after the devices whose lines they carry.
        std::vector<Node*> nodes = {&plant, &ad300, &laser};
        // Seed 001's cameras: the left one sees the first half of the nozzles (Sec. 1.1).
        std::vector<std::unique_ptr<CameraNode>> cameras;
        if (world.vision) {
            const int count = boundary.mounting.nozzle_count;
            for (int camera = 0; camera < 2; ++camera) {
                std::vector<int> nozzles;
                std::vector<double> right_m;
                for (int n = camera * count / 2; n < (camera + 1) * count / 2; ++n) {
                    nozzles.push_back(n);
                    right_m.push_back((n - 0.5 * (count - 1)) * boundary.mounting.nozzle_spacing_m);
                }
                cameras.push_back(std::make_unique<CameraNode>(world.kinematics, *world.crop,
                                                               camera == 0 ? world.vision->left : world.vision->right,
                                                               seed, camera, nozzles, right_m,
                                                               seconds_to_ns(world.vision->calibration_until_s)));
                // The report shows each camera's frame from the middle of the run.
                cameras.back()->keep_frame_at(world.end_ns / 2);
                nodes.push_back(cameras.back().get());
            }
        }
        BenchWires& wires = session.wires();
        std::optional<NmeaSerialAdapter> nmea_adapter;
        std::optional<LaserSerialAdapter> laser_adapter;
        std::optional<NozzlePwmCaptureAdapter> pwm_capture;
        if (wires.gnss_port) nodes.push_back(&nmea_adapter.emplace(*wires.gnss_port));
        if (wires.laser_port) nodes.push_back(&laser_adapter.emplace(*wires.laser_port));
        if (auto* hid = dynamic_cast<HidBoardWire*>(wires.board_io.get())) {
            nodes.push_back(&pwm_capture.emplace(hid->board(), boundary.flow_table_or_paper().nozzle_count(),
                                                 spec.wiring.board_update_hz));
        }
        // A wired Pi whose PWM comes on DDS (board_io: dds), or that takes the
        // camera frames (which travel on DDS only), must know the run's domain.
        if (spec.wiring.external_controller) {
            const bool on_dds = spec.wiring.board_io == BoardIoWireKind::dds || world.vision.has_value();
            announce_attach(spec, wires, run_name, case_dir, std::cout,
                            on_dds ? std::optional<std::uint32_t>(session.domain_id()) : std::nullopt);
        }

        TimeNs now_ns = 0;
        double startup_wall_s = 0.0;
        nlohmann::json realtime_facts;
        if (options.clock != nullptr) options.clock->end_ns.store(world.end_ns, std::memory_order_relaxed);
        const TraceOutcome outcome = session.run_to_outcome(
            [&] {
                if (spec.mode == RunMode::realtime) {
                    run_case_in_realtime(spec, dds, nodes, session, trace, wall, world.end_ns, now_ns, options.clock,
                                         realtime_facts);
                    return;
                }
                LockstepTimeouts timeouts;
                timeouts.ack = std::chrono::milliseconds(static_cast<long>(spec.timeouts.node_ack_s * 1000));
                LockstepMaster master(dds, timeouts);
                for (Node* node : nodes) master.add_local_node(*node);
                if (session.has_controller_process()) {
                    master.add_remote_node("controller", [&session] { return session.controller_gone(); });
                }
                master.set_after_round([&](TimeNs t, int round) {
                    now_ns = t;
                    trace.drain(t, round);
                });
                master.set_watchdog([&] { check_run(spec, wall, dds, trace, now_ns); });
                // A role declared in a hello fails the case before time starts (harness/judge.h).
                master.set_after_hello([](const std::vector<LockstepMaster::HelloTopics>& hellos) {
                    for (const LockstepMaster::HelloTopics& hello : hellos) {
                        if (const auto why = declared_role_violation(hello.subscribed, hello.published)) {
                            throw NodeFailure(FailureKind::topic_role_violation, hello.node, *why);
                        }
                    }
                });
                try {
                    master.start();
                    startup_wall_s = wall.elapsed_s();
                    while (master.advance(world.end_ns)) {
                    }
                    master.shutdown();
                } catch (const NodeFailure&) {
                    master.shutdown(/*after_failure=*/true);
                    throw;
                }
            },
            world.end_ns, now_ns);
        // Seed 001's reference controller ships as a program only: --in-process
        // leaves these cases to it, and says so.
        const bool asked_in_process = spec.controller.in_process.value_or(options.in_process);
        nlohmann::json run_facts = realtime_facts.is_object()
                                       ? realtime_facts
                                       : nlohmann::json{{"wall_seconds", wall.elapsed_s()},
                                                        {"controller_mode", session.controller_mode()},
                                                        {"startup_wall_seconds", startup_wall_s}};
        run_facts["in_process_refused"] = asked_in_process ? "seed 001's boundary controller has no plugin" : "";
        run_facts["cpu_placement"] = describe_thread_placement();  // rig/host/cpu_lease.h
        run_facts["plant_rejected_duty_commands"] = plant.rejected_commands();
        nlohmann::json report_frames = nlohmann::json::array();
        for (std::size_t c = 0; c < cameras.size(); ++c) {
            run_facts[cameras[c]->name() + "_frames"] = cameras[c]->frames_rendered();
            const std::string file = "frame-" + cameras[c]->name() + ".png";
            if (const std::optional<std::uint64_t> number = cameras[c]->write_report_frame(case_dir / file)) {
                report_frames.push_back({{"camera", c}, {"frame_number", *number}, {"file", file}});
            }
        }
        if (!cameras.empty()) trace.file().set_meta("vision_report_frames", report_frames.dump());
        if (pwm_capture) run_facts["nozzle_pwm_captured"] = pwm_capture->published();
        trace.file().set_meta("run", run_facts.dump());
        trace.file().finish(outcome);
    } catch (const std::exception& error) {
        const FailureKind kind = run_interrupt_signal() ? FailureKind::interrupted : FailureKind::harness_error;
        if (!std::filesystem::exists(trace_file)) return run_without_trace(spec, seed, run_name, kind, error.what(), wall.elapsed_s());
    }
    // The verdict and metrics from the recorded trace alone, as `rig judge` gives them later.
    try {
        return judge_trace(read_trace(trace_file));
    } catch (const std::exception& error) {
        return run_without_trace(spec, seed, run_name, FailureKind::harness_error, error.what(), wall.elapsed_s());
    }
}

}  // namespace rig::harness
