#pragma once
// Runs cases, whatever their system. One run of a case, in parts, each in its own place:
//   the world      its system's SystemRun (harness/systems/system.h): plant,
//                  route, devices, judging plan, what the trace records
//   the session    harness/session/case_session.h: DDS domain, bench wires, the
//                  controller's process or plugin
//   the loop       harness/run/case_loop.h: the nodes driven in lockstep or in
//                  real time, every sample recorded (harness/trace/trace_recorder.h)
//   the judge      harness/judge/judge_trace.h with the system's own judge:
//                  verdict, metrics and figures from the trace alone
// A case that fails, errs or is interrupted keeps its trace up to that moment,
// with the reason in the trace's meta table, and is judged from it like any other.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "harness/judge/judge_trace.h"
#include "harness/run/case_loop.h"
#include "harness/run/shard.h"
#include "harness/spec/case_spec.h"
#include "harness/systems/system.h"
#include "rig/wire/hid_board.h"

namespace rig::harness {

struct RunOptions {
    std::filesystem::path out_dir = "rig-out";
    std::optional<std::uint64_t> seed_override;
    int jobs = 1;
    // `--domain N`: every case on this DDS domain (one at a time); else a case's
    // own `domain:`, else a free one.
    std::optional<std::uint32_t> domain;
    // Where the reference controllers are (each system names its own,
    // harness/systems/system.h ReferenceController): their programs, run when
    // a case names no controller (bin/, beside `rig`), and their plugins
    // (software-in-the-loop; lib/rig/ beside bin/). Empty plugin_dir: no
    // plugins (then a reference controller's keys are not checked before the run).
    std::filesystem::path controller_dir = ".";
    std::filesystem::path plugin_dir;
    // `rig run --in-process`: every case whose controller can runs in process
    // (a case's own controller.in_process wins).
    bool in_process = false;
    // Each lockstep case's thread, the controller process it starts and Fast
    // DDS's threads on one leased CPU at SCHED_BATCH (rig/host/cpu_lease.h);
    // `--no-pin`: left to the scheduler (a controller that steps on several threads).
    bool pin_cpu = true;
    // `rig sweep --seeds N`: every case runs once per seed here, as NAME-seedN
    // (a case's own seed or `seeds:` and --seed are then not used).
    std::vector<std::uint64_t> seed_sweep;
    // `rig sweep --shard I/N`: only the sweep's runs of this shard
    // (harness/run/shard.h shard_of_run); nullopt: every run.
    std::optional<Shard> sweep_shard;
    // false: run_cases drops each run's figures as it ends (a sweep of
    // thousands of runs keeps only their numbers).
    bool keep_figures = true;
    // `rig run --dds-security`: the run's credentials (OUT/security,
    // harness/session/dds_security_setup.h); the rig's participants hold its rig
    // identity, the controller process is given the controller's. nullopt: none.
    std::optional<std::filesystem::path> dds_security_dir;
    // Where run_case publishes the case's clock as it runs (a progress display);
    // nullptr: nowhere. run_cases sets it per case from its RunObserver.
    CaseClock* clock = nullptr;
    // `board_io: hid`: how the board is opened; empty = hidapi by the case's
    // hid_vid / hid_pid (a test hands an in-process board here).
    HidTransportOpener open_hid;
};

// Checks that need more than the file itself, before anything starts: the
// controller's own section, by the controller (a plugin's check_config, or
// the reference program's --check-config), and the case's timed events
// against its world's length. Throws rig::ConfigError / std::runtime_error
// naming file, line and key.
void validate_for_run(const CaseSpec& spec, const RunOptions& options);

// The case's controller when it names none: its system's reference
// controller's program and plugin (empty: it has none), as found in `options`.
struct ControllerFiles {
    std::filesystem::path executable;
    std::filesystem::path plugin;
    std::string name;  // "seed 000's reference controller", or the case's command or plugin
};
ControllerFiles reference_controller_files(const CaseSpec& spec, const RunOptions& options);

// Where a case's controller runs, decided before anything starts.
struct ControllerPlacement {
    std::optional<std::filesystem::path> plugin;  // set: run this plugin in process
    std::string refused;  // asked for in process but cannot be (why), reported in results.json
};
// The case's `controller.in_process`, else `rig run --in-process`; a case that
// cannot run in process (real time, a program without a plugin) runs as a
// process, with the reason.
ControllerPlacement place_controller(const CaseSpec& spec, const RunOptions& options);
// The plugin a case names (relative to the case file), or its reference
// controller's; empty when the case's controller is a program without one.
std::filesystem::path controller_plugin_of(const CaseSpec& spec, const RunOptions& options);

// One run of a case file: a seed and the name its outputs go under.
struct CaseInstance {
    std::size_t spec_index = 0;
    std::uint64_t seed = 1;
    std::string name;  // the case's name, or NAME-seedN for a case with `seeds:`
};
// The runs the case files ask for, in order (a `seeds:` case gives one per seed;
// --seed gives one run with that seed).
std::vector<CaseInstance> expand_runs(const std::vector<CaseSpec>& specs, const RunOptions& options);

// Runs one case to the end (or to the first failure) and judges its trace;
// never throws.
CaseRun run_case(const CaseSpec& spec, std::uint64_t seed, const std::string& run_name, const RunOptions& options);
// The same with the case's own seed (or --seed) and name.
CaseRun run_case(const CaseSpec& spec, const RunOptions& options);

// What run_cases tells while it runs (harness/run/run_progress.h shows it as lines
// or on a terminal's status line). runs_planned comes first, on the calling
// thread; the others come from the thread running that case, so may overlap.
class RunObserver {
public:
    virtual ~RunObserver() = default;
    // Every run, in expand_runs() order (the indexes below), and their case files.
    virtual void runs_planned(const std::vector<CaseInstance>& runs, const std::vector<CaseSpec>& specs) = 0;
    virtual void case_started(std::size_t index) = 0;
    virtual void case_finished(std::size_t index, const CaseResult& result) = 0;
    // Where the run `index` publishes its clock; nullptr: nobody reads it.
    virtual CaseClock* case_clock(std::size_t index) = 0;
};

// The wall time of run_cases' two phases: the lockstep cases (`jobs` at a
// time), then the real-time ones (alone). A real-time case runs at 1x by
// definition, so the rig's speed is the first phase's figure.
struct RunPhaseWalls {
    double lockstep_seconds = 0.0;
    double realtime_seconds = 0.0;
};

// Runs every expanded case `options.jobs` at a time (real-time cases alone,
// after the others), telling `observer` as cases start and end. After SIGINT /
// SIGTERM (harness/run/run_interrupt.h) the running cases end as interrupted and
// the rest are reported as not run. `phase_walls`, if given, gets each phase's
// wall time.
std::vector<CaseRun> run_cases(const std::vector<CaseSpec>& specs, const RunOptions& options, RunObserver& observer,
                               RunPhaseWalls* phase_walls = nullptr);
// The same, printing one progress line per case as it ends (harness/run/run_progress.h CaseLineLog).
std::vector<CaseRun> run_cases(const std::vector<CaseSpec>& specs, const RunOptions& options, std::ostream& progress);

}  // namespace rig::harness
