#include "harness/boundary_runner.h"

#include <csignal>
#include <cstring>

#include "harness/boundary_judge.h"
#include "harness/boundary_world.h"
#include "harness/case_session.h"
#include "harness/dds_security_setup.h"
#include "harness/run_interrupt.h"
#include "harness/trace_recorder.h"
#include "rig/runtime/lockstep.h"

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
    result.expected_error = spec.expect.error;
    result.error_kind = std::string(to_string(kind));
    result.error = error;
    result.wall_seconds = wall_seconds;
    const CaseVerdict verdict =
        judge_case(VerdictInputs{{}, {}, result.limits, spec.expect.fail, spec.expect.error, result.error_kind, error});
    result.failures = verdict.failures;
    result.expected_failure = verdict.expected_failure;
    result.passed = verdict.passed;
    return run;
}

std::string judging_json(const CaseSpec& spec) {
    JudgingPlan plan;
    plan.scenario = "boundary";
    plan.limits = spec.limits;
    plan.expect_fail = spec.expect.fail;
    plan.expect_error = spec.expect.error;
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
        CaseSession session(spec, case_dir, options.domain);
        DdsContext dds(session.domain_id(), "harness", /*watch_discovery=*/true);
        session.start_controller(spec, options.controller_executable.parent_path() / kBoundaryControllerExecutable, case_dir,
                                 dds_security_environment(options.dds_security_dir, kControllerIdentity));
        TraceRecorder trace(dds, trace_file);
        trace.record_boundary_topics();
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

        TimeNs now_ns = 0;
        double startup_wall_s = 0.0;
        const TraceOutcome outcome = session.run_to_outcome(
            [&] {
                LockstepTimeouts timeouts;
                timeouts.ack = std::chrono::milliseconds(static_cast<long>(spec.timeouts.node_ack_s * 1000));
                LockstepMaster master(dds, timeouts);
                for (Node* node : {static_cast<Node*>(&plant), static_cast<Node*>(&ad300), static_cast<Node*>(&laser)}) {
                    master.add_local_node(*node);
                }
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
        trace.file().set_meta("run", nlohmann::json{{"wall_seconds", wall.elapsed_s()},
                                                    {"controller_mode", session.controller_mode()},
                                                    {"in_process_refused", asked_in_process
                                                         ? "seed 001's boundary controller has no plugin" : ""},
                                                    {"startup_wall_seconds", startup_wall_s},
                                                    {"plant_rejected_duty_commands", plant.rejected_commands()}}
                                         .dump());
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
