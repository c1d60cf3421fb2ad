#pragma once
// A system the rig tests: seed 000's breakpoint sprayer (systems/breakpoint/),
// seed 001's per-nozzle boundary shut-off (systems/boundary/), the next. Each
// implements this interface in a folder of its own and has a row in the table
// of harness/systems/systems.h, where the case file's `system:` finds it, as
// ros2_control finds a hardware plugin by name. The framework (harness/run,
// harness/judge, harness/report) knows this interface and never which system
// it drives.
//
// A system gives:
//   its sections    read from a case file (SystemSections, harness/spec/case_spec.h);
//   one run's world  SystemRun: built before anything runs, a pure function of
//                    the case and its seed: its length, the judging plan, what
//                    the trace records, what the controller is given besides
//                    its configuration, and the nodes (SystemNodes) that the
//                    lockstep master steps;
//   its judge        metrics and figures from a recorded trace alone (SystemJudge,
//                    harness/judge/judge_trace.h);
//   its key signals  what `rig diff --html` draws of two runs over each other;
//   its reference controller, run when a case names none.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/judge/judge_trace.h"
#include "harness/plot/gnuplot_panel.h"
#include "harness/spec/case_spec.h"
#include "harness/trace/run_facts.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/lockstep.h"
#include "rig/runtime/node.h"

namespace rig::harness {

struct BenchWires;    // harness/session/case_session.h
class TraceRecorder;  // harness/trace/trace_recorder.h
class TraceFile;      // harness/trace/trace_file.h

// What runs when a case names no controller: the system's reference controller.
struct ReferenceController {
    std::string executable;  // its program, beside `rig` (bin/)
    std::string plugin;      // its shared library in lib/rig/ (software-in-the-loop); empty: it has none
    std::string name;        // for messages: "seed 001's boundary controller"
};

// The local nodes of one run, made on the run's DDS context: they hold its
// writers, so they are made after the context and destroyed before it.
class SystemNodes {
public:
    virtual ~SystemNodes() = default;
    // In the order they step each instant, the bench wires' adapters last.
    virtual std::vector<Node*> nodes() = 0;
    // Advanced by the master to each instant before any node steps; nullptr: none.
    virtual TruthModel* truth() { return nullptr; }
    // The run reached its end (the loop returned): the truth catches up with it.
    virtual void run_completed(TimeNs end_ns) { (void)end_ns; }
    // After the run, whatever its ending: what the trace keeps besides its
    // samples (seed 000: the spray on the ground, the faults injected) and the
    // facts the system adds to the run's (seed 001: frames rendered); `case_dir`
    // takes files for the report (camera frames).
    virtual void finish(TraceFile& trace, RunFacts& facts, const std::filesystem::path& case_dir) = 0;
};

// The world of one run of a case.
class SystemRun {
public:
    virtual ~SystemRun() = default;
    // The last simulated instant of the run.
    virtual TimeNs end_ns() const = 0;
    // The checks that need this world (a timed event against the route's
    // length): rig::ConfigError at the key. The common part (the rig's own
    // stall) is the caller's.
    virtual void check_timeline(const CaseSpec& spec) const { (void)spec; }
    // The system's part of the judging plan (meta `judging`): what the judge
    // holds the controller to, from the case and its route, added to `plan`
    // (which already holds the common part, harness/judge/judge_trace.h).
    virtual void add_judging_plan(nlohmann::json& plan) const = 0;
    // What the trace records of this system, in the order it is drained (part
    // of what makes the trace reproducible), and any truth added at the
    // controller's outputs.
    virtual void record(TraceRecorder& trace) const = 0;
    // Files the controller is given besides its configuration, written into
    // `case_dir` (seed 001: job.yaml, the operator's target areas and the
    // cameras; docs/controller-contract.md): the arguments that name them on
    // its command line. None by default.
    virtual std::vector<std::string> write_controller_inputs(const std::filesystem::path& case_dir) const {
        (void)case_dir;
        return {};
    }
    // What attach.json says of this system to a wired board (seed 000: its
    // sensors' register scalings; seed 001: the run's DDS domain and the job).
    virtual void describe_attach(nlohmann::json& attach, std::uint32_t dds_domain) const = 0;
    // The nodes, with the adapters of the case's bench wires.
    virtual std::unique_ptr<SystemNodes> make_nodes(BenchWires& wires) = 0;
};

// A signal of one run over simulated time, as `rig diff --html` draws it for
// two runs of a case over each other (docs/diff.md).
struct KeySignal {
    std::string name;  // "main-pipeline flow (truth)": the other run's signal of that name is drawn with it
    std::string unit;  // the y axis: "L/min"
    bool held = false;  // a command or a state, held until its next sample (drawn as steps)
    std::vector<Point> points;  // (t in s, value), in time order
};

class System : public SystemJudge {
public:
    // The case file's `system:` word.
    virtual std::string_view name() const = 0;
    // Reads the system's own sections of a case file (not finish()ed here);
    // throws rig::ConfigError naming file, line and key.
    virtual std::shared_ptr<const SystemSections> read_sections(const YamlSection& root) const = 0;
    virtual ReferenceController reference_controller() const = 0;
    // The world of one run of `spec`, one of this system's cases, with `seed`.
    // Throws (rig::ConfigError, std::runtime_error) when it cannot be built.
    virtual std::unique_ptr<SystemRun> plan_run(const CaseSpec& spec, std::uint64_t seed) const = 0;
    // The signals that show what a run of this system did, from its trace
    // alone, in the order they are drawn. A signal the trace holds no sample
    // of is left out.
    virtual std::vector<KeySignal> key_signals(const RecordedTrace& trace) const = 0;
};

}  // namespace rig::harness
