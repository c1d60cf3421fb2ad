#pragma once
// Runs cases. One run of a case, in four parts, each in its own file:
//   the world      harness/case_world.h    plant, route, operator, receiver, judging plan
//   the session    harness/case_session.h  DDS domain, bench wires, the controller process
//   the runner     here                    the nodes driven in lockstep or in real time,
//                                          every sample recorded (harness/trace_recorder.h)
//   the judge      harness/judge.h         verdict, metrics and figures from the trace alone
// A case that fails, errs or is interrupted keeps its trace up to that moment,
// with the reason in the trace's meta table, and is judged from it like any other.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "harness/case_spec.h"
#include "harness/judge.h"
#include "rig/wire/hid_board.h"

namespace rig::harness {

// A running case's simulated time and its end, published by its runner for a
// progress display to read from another thread (0: not known yet).
struct CaseClock {
    std::atomic<TimeNs> now_ns{0};
    std::atomic<TimeNs> end_ns{0};
};

struct RunOptions {
    std::filesystem::path out_dir = "rig-out";
    std::optional<std::uint64_t> seed_override;
    int jobs = 1;
    // `--domain N`: every case on this DDS domain (one at a time); else a case's
    // own `domain:`, else a free one.
    std::optional<std::uint32_t> domain;
    // Default controller when a case names no command: the reference controller.
    std::filesystem::path controller_executable = "rig-controller";
    // The reference controller as a plugin (software-in-the-loop); empty = none
    // (then the reference controller's keys are not checked before the run).
    std::filesystem::path controller_plugin;
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
    // false: run_cases drops each run's figures as it ends (a sweep of
    // thousands of runs keeps only their numbers).
    bool keep_figures = true;
    // `rig run --dds-security`: the run's credentials (OUT/security,
    // harness/dds_security_setup.h); the rig's participants hold its rig
    // identity, the controller process is given the controller's. nullopt: none.
    std::optional<std::filesystem::path> dds_security_dir;
    // Where run_case publishes the case's clock as it runs (a progress display);
    // nullptr: nowhere. run_cases sets it per case from its RunObserver.
    CaseClock* clock = nullptr;
    // `board_io: hid`: how the board is opened; empty = hidapi by the case's
    // hid_vid / hid_pid (a test hands an in-process board here).
    HidTransportOpener open_hid;
};

// Checks that need more than the file itself (e.g. the reference controller's
// own parameters); throws rig::ConfigError naming file, line and key.
void validate_for_run(const CaseSpec& spec, const RunOptions& options);

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

// What run_cases tells while it runs (harness/run_progress.h shows it as lines
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
// SIGTERM (harness/run_interrupt.h) the running cases end as interrupted and
// the rest are reported as not run. `phase_walls`, if given, gets each phase's
// wall time.
std::vector<CaseRun> run_cases(const std::vector<CaseSpec>& specs, const RunOptions& options, RunObserver& observer,
                               RunPhaseWalls* phase_walls = nullptr);
// The same, printing one progress line per case as it ends (harness/run_progress.h CaseLineLog).
std::vector<CaseRun> run_cases(const std::vector<CaseSpec>& specs, const RunOptions& options, std::ostream& progress);

}  // namespace rig::harness
