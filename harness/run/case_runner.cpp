#include "harness/run/case_runner.h"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <iostream>
#include <mutex>
#include <set>
#include <thread>

#include <yaml-cpp/yaml.h>

#include "harness/judge/verdict.h"
#include "harness/run/run_identity.h"
#include "harness/run/run_interrupt.h"
#include "harness/run/run_progress.h"
#include "harness/session/board_attach.h"
#include "harness/session/case_session.h"
#include "harness/session/dds_security_setup.h"
#include "harness/session/in_process_controller.h"
#include "harness/session/line_noise.h"
#include "harness/systems/systems.h"
#include "harness/trace/sha256.h"
#include "harness/trace/trace_recorder.h"
#include "rig/host/child_process.h"
#include "rig/host/cpu_lease.h"
#include "rig/runtime/follower.h"

namespace rig::harness {

namespace {

// How long a reference program may take to check a case's controller section.
constexpr std::chrono::milliseconds kConfigCheckTimeLimit{20'000};

// A case that could not even start (no trace to judge): its result from what is known.
CaseRun unstarted_run(const CaseSpec& spec, std::uint64_t seed, const std::string& run_name, FailureKind kind,
                      const std::string& error, double wall_seconds) {
    CaseRun run;
    CaseResult& result = run.result;
    result.name = run_name;
    result.case_name = spec.name;
    result.file = spec.source_path.string();
    result.seed = seed;
    result.case_sha256 = case_content_sha256(spec);
    for (const KeySetting& setting : spec.settings) result.settings[setting.key] = setting.value;
    result.mode = std::string(to_string(spec.mode));
    result.limits = effective_limits(spec);
    result.min_effects = spec.min_effects;
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

// `rig run --set`'s values, as meta `case_settings` keeps them: key path -> value as given.
nlohmann::json settings_json(const CaseSpec& spec) {
    nlohmann::json settings = nlohmann::json::object();
    for (const KeySetting& setting : spec.settings) settings[setting.key] = setting.value;
    return settings;
}

// What the judge will hold the controller to (meta `judging`): the common part
// from the case, the system's from its world.
std::string judging_plan_json(const CaseSpec& spec, const SystemRun& world) {
    JudgingPlan plan;
    plan.scenario = spec.system->scenario();
    plan.limits = effective_limits(spec);
    plan.min_effects = spec.min_effects;
    const ExpectSpec expect = applied_expectation(spec, &plan.expect_set_aside);
    plan.expect_fail = expect.fail;
    plan.expect_error = expect.error;
    nlohmann::json json = nlohmann::json::object();
    add_to_json(plan, json);
    world.add_judging_plan(json);
    return json.dump();
}

// The controller's own section, checked by the controller before anything runs.
void check_controller_section(const CaseSpec& spec, const RunOptions& options) {
    // A controller that names no plugin and runs as a program of the team's
    // checks its section itself when it starts; an external board is not ours to ask.
    if (spec.wiring.external_controller) return;
    const std::filesystem::path plugin = controller_plugin_of(spec, options);
    if (!plugin.empty()) {
        const auto library = load_controller_plugin(plugin);
        const std::string error =
            library->check_config(NodePluginCaseText{spec.source_path.string(), spec.source_text, "controller"});
        if (!error.empty()) throw std::runtime_error(error);
        return;
    }
    if (!spec.controller.command.empty()) return;
    // The reference program without a plugin: its own --check-config.
    // Sections that passed once pass again (many cases share one).
    static std::mutex mutex;
    static std::set<std::string> passed;
    const ControllerFiles reference = reference_controller_files(spec, options);
    const std::string section = spec.controller.params.present ? YAML::Dump(spec.controller.params.node) : std::string();
    const std::string key = reference.executable.string() + "\n" + section;
    {
        const std::lock_guard lock(mutex);
        if (passed.count(key)) return;
    }
    const CommandResult checked = run_command({reference.executable.string(), "--check-config", spec.source_path.string(),
                                               "--config-section", "controller"},
                                              kConfigCheckTimeLimit);
    if (!checked.succeeded()) {
        std::string output = checked.output;
        while (!output.empty() && (output.back() == '\n' || output.back() == ' ')) output.pop_back();
        if (output.empty()) output = reference.name + " (" + reference.executable.string() + "): " + checked.ended;
        throw std::runtime_error(output);
    }
    const std::lock_guard lock(mutex);
    passed.insert(key);
}

}  // namespace

ControllerFiles reference_controller_files(const CaseSpec& spec, const RunOptions& options) {
    const ReferenceController reference = system_of(spec).reference_controller();
    ControllerFiles files;
    files.executable = options.controller_dir / reference.executable;
    if (!reference.plugin.empty() && !options.plugin_dir.empty()) files.plugin = options.plugin_dir / reference.plugin;
    files.name = reference.name;
    return files;
}

std::filesystem::path controller_plugin_of(const CaseSpec& spec, const RunOptions& options) {
    if (!spec.controller.plugin.empty()) {
        if (spec.controller.plugin.is_absolute()) return spec.controller.plugin;
        // Beside the case file, as a relative `command` is.
        return (std::filesystem::absolute(spec.source_path).parent_path() / spec.controller.plugin).lexically_normal();
    }
    if (spec.controller.command.empty()) return reference_controller_files(spec, options).plugin;
    return {};
}

ControllerPlacement place_controller(const CaseSpec& spec, const RunOptions& options) {
    ControllerPlacement placement;
    const bool wanted = spec.controller.in_process.value_or(options.in_process);
    if (!wanted || spec.wiring.external_controller) return placement;
    // The case file's own `in_process: true` was checked when it was read; these
    // are cases `--in-process` asks of that cannot comply.
    if (spec.mode != ClockMode::lockstep) {
        placement.refused = "a real-time case: its controller runs as a process on the wall clock";
        return placement;
    }
    // In the rig's process a controller would hold the rig's identity (one per
    // process), which may write every device and truth topic: what the
    // permissions exist to keep from it.
    if (options.dds_security_dir) {
        placement.refused = "rig run --dds-security: the controller's identity is given to a process of its own";
        return placement;
    }
    const std::filesystem::path plugin = controller_plugin_of(spec, options);
    if (plugin.empty()) {
        placement.refused = spec.controller.command.empty()
                                ? reference_controller_files(spec, options).name + " has no plugin"
                                : "controller.command names a program and no controller.plugin";
        return placement;
    }
    placement.plugin = plugin;
    return placement;
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
    check_controller_section(spec, options);
    // Timed events against the case's length, which only its world gives.
    const std::unique_ptr<SystemRun> world = system_of(spec).plan_run(spec, spec.seed);
    world->check_timeline(spec);
    check_common_timeline(spec, ns_to_seconds(world->end_ns()));
}

std::vector<CaseInstance> expand_runs(const std::vector<CaseSpec>& specs, const RunOptions& options) {
    std::vector<CaseInstance> runs;
    std::size_t sweep_runs = 0;  // the sweep's runs so far, this shard's or not
    for (std::size_t i = 0; i < specs.size(); ++i) {
        const CaseSpec& spec = specs[i];
        if (!options.seed_sweep.empty()) {
            for (std::uint64_t seed : options.seed_sweep) {
                const std::size_t index = sweep_runs++;
                if (options.sweep_shard && !run_in_shard(index, *options.sweep_shard)) continue;
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
    const CpuLease cpu(options.pin_cpu && spec.mode == ClockMode::lockstep);
    const WallStopwatch wall;
    const std::filesystem::path case_dir = options.out_dir / "cases" / run_name;
    const std::filesystem::path trace_file = case_dir / "trace.sqlite";
    try {
        std::filesystem::remove_all(case_dir);
        std::filesystem::create_directories(case_dir / "controller-state");

        const System& system = system_of(spec);
        const std::unique_ptr<SystemRun> world = system.plan_run(spec, seed);
        CaseSession session(spec, case_dir, options.domain, options.open_hid);
        // The harness's participant first, watching discovery; then the
        // controller, so every endpoint it makes is seen.
        DdsContext dds(session.domain_id(), "harness", /*watch_discovery=*/true, reliability_timers_for(spec.mode));
        const ControllerPlacement placement = place_controller(spec, options);
        std::string in_process_refused = placement.refused;
        if (placement.plugin) in_process_refused = session.start_in_process_controller(spec, *placement.plugin, case_dir, dds);
        const std::vector<std::string> controller_inputs = world->write_controller_inputs(case_dir);
        const std::filesystem::path executable =
            spec.controller.command.empty() ? reference_controller_files(spec, options).executable : std::filesystem::path();
        session.start_controller(spec, executable, case_dir,
                                 dds_security_environment(options.dds_security_dir, kControllerIdentity),
                                 controller_inputs);
        TraceRecorder trace(dds, trace_file);
        world->record(trace);
        trace.file().set_meta("case", run_name);
        trace.file().set_meta("case_name", spec.name);
        trace.file().set_meta("case_file", spec.source_path.string());
        trace.file().set_meta("case_yaml", spec.source_text);
        if (!spec.settings.empty()) trace.file().set_meta("case_settings", settings_json(spec).dump());
        trace.file().set_meta("system", std::string(system.name()));
        trace.file().set_meta("scenario", spec.system->scenario());
        trace.file().set_meta("mode", std::string(to_string(spec.mode)));
        trace.file().set_meta("seed", std::to_string(seed));
        trace.file().set_meta("controller_command", session.controller_command_line());
        // What `rig compare` sets side by side (harness/run/run_identity.h); not in the digest.
        trace.file().set_meta("case_sha256", case_content_sha256(spec));
        if (!spec.wiring.external_controller) {
            const bool ran_in_process = session.controller_mode() == "in_process";
            const std::filesystem::path plugin = ran_in_process ? *placement.plugin : std::filesystem::path();
            trace.file().set_meta("controller_sha256", file_sha256(controller_file_of(spec, plugin, executable)));
            Sha256 config;
            config.add(controller_config_text(spec));
            trace.file().set_meta("controller_config_sha256", config.hex());
        }
        trace.file().set_meta("wiring", session.wires().description);
        trace.file().set_meta("dds_domain", std::to_string(session.domain_id()));
        trace.file().set_meta("harness_guid_prefix", dds.guid_prefix());
        if (options.dds_security_dir) trace.file().set_meta("dds_security", options.dds_security_dir->string());
        trace.file().set_meta("judging", judging_plan_json(spec, *world));
        // Nodes hold DDS writers, so they are made after (and destroyed before) the context.
        const std::unique_ptr<SystemNodes> nodes = world->make_nodes(session.wires());
        if (spec.wiring.external_controller) {
            nlohmann::json described = nlohmann::json::object();
            world->describe_attach(described, session.domain_id());
            announce_attach(spec.wiring, spec.board, session.wires(), run_name, case_dir, std::cout, described);
        }
        install_line_noise(spec.board, spec.wiring, seed, session.wires());  // board.line_noise, if any

        TimeNs now_ns = 0;
        RunFacts facts;
        facts.controller_mode = session.controller_mode();
        facts.in_process_refused = in_process_refused;
        facts.cpu_placement = describe_thread_placement();  // rig/host/cpu_lease.h
        std::optional<BoardAttachment> board;
        if (options.clock != nullptr) options.clock->end_ns.store(world->end_ns(), std::memory_order_relaxed);
        const TraceOutcome outcome = session.run_to_outcome(
            [&] {
                run_loop(spec, dds, *nodes, session, trace, wall, world->end_ns(), now_ns, facts, board, options.clock);
                nodes->run_completed(world->end_ns());
            },
            world->end_ns(), now_ns);
        // Whatever the ending, what the system keeps of the run is part of the record.
        nodes->finish(trace.file(), facts, case_dir);
        facts.board_io = board_io_report(spec.board, session.wires(), board);
        if (options.dds_security_dir) {
            // Who tried to join and was refused (not in the digest: it depends on who was around).
            trace.file().set_meta("dds_security_refused", nlohmann::json(dds.refused_participants()).dump());
        }
        facts.wall_seconds = wall.elapsed_s();
        trace.file().set_meta("run", to_json(facts).dump());
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
        (specs[instances[i].spec_index].mode == ClockMode::realtime ? realtime : lockstep).push_back(i);
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
