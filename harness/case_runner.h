#pragma once
// Runs cases: builds the plant and emulators from the case file, starts the
// controller under test as its own process, drives everything in lockstep,
// records the trace, computes metrics from truth and judges them.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <vector>

#include "emulators/gnss_g970.h"
#include "emulators/panel_switch.h"
#include "emulators/plant.h"
#include "harness/case_spec.h"
#include "harness/html_report.h"
#include "harness/results_writer.h"

namespace rig::harness {

struct RunOptions {
    std::filesystem::path out_dir = "rig-out";
    std::optional<std::uint64_t> seed_override;
    int jobs = 1;
    // Default controller when a case names no command: the reference controller.
    std::filesystem::path controller_executable = "rig-controller";
};

// What the case's vehicle does and its operator presses (harness/case_runner.cpp).
struct ScenarioPlan {
    std::vector<emulators::RoutePhase> route;
    double start_along_m = 0.0;  // nozzle line at t = 0
    std::vector<emulators::SwitchClosure> button;
    std::vector<emulators::SwitchClosure> spray_switch;
    double approach_starts_s = 0.0;
};

// The case's world as `rig run` builds it: the plant, the operator's script and
// the G970II's parameters. Bench tools (`rig emulate gnss`) use the same.
struct CaseWorld {
    emulators::Plant plant;
    ScenarioPlan scenario;
    emulators::G970Params gnss;
    double breakpoint_crossing_s = 0.0;  // on the approach; NaN in a static test
    TimeNs end_ns = 0;
};
CaseWorld build_case_world(const CaseSpec& spec, std::uint64_t seed);

// Checks that need more than the file itself (e.g. the reference controller's
// own parameters); throws rig::ConfigError naming file, line and key.
void validate_for_run(const CaseSpec& spec, const RunOptions& options);

// A case's verdict and what the report draws of it (Fig. 14 flow curve, Fig. 15 dose).
struct CaseRun {
    CaseResult result;
    CaseFigures figures;
};

// Runs one case to the end (or to the first failure); never throws.
CaseRun run_case(const CaseSpec& spec, const RunOptions& options);

// Runs cases `options.jobs` at a time, printing one progress line per case.
std::vector<CaseRun> run_cases(const std::vector<CaseSpec>& specs, const RunOptions& options, std::ostream& progress);

}  // namespace rig::harness
