#include "harness/run/speed_bench.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <map>
#include <ostream>
#include <set>
#include <sstream>
#include <thread>
#include <tuple>

#include <sys/resource.h>

#include <nlohmann/json.hpp>

#include "harness/session/dds_security_setup.h"
#include "harness/run/output_dir.h"
#include "harness/systems/systems.h"
#include "harness/judge/case_result.h"
#include "harness/output/atomic_file.h"
#include "rig/host/cpu_lease.h"
#include "rig/host/heap_count.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/dds_security.h"
#include "rig/runtime/thread_id_cache.h"
#include "rig/text/number_text.h"

namespace rig::harness {
namespace {

struct ModeRuns {
    std::string mode;  // process (one leased CPU), process_unpinned, in_process, process_dds_security
    std::vector<CaseResult> runs;
    std::vector<int> repeat_of;  // per run: which repeat (0-based) it belongs to
    std::uint64_t context_switches = 0;  // over all its runs (context_switches_so_far)
    std::uint64_t stepping_allocations = 0;  // over all its runs, while stepping (rig/host/heap_count.h)
    // Wall time of each whole run, to its trace finished and judged: what a
    // sweep or a search pays a case (x real time stops before the trace is
    // finished: its last batch, its index, its log folded back).
    double whole_wall_s = 0.0;
    double whole_sim_s = 0.0;
};

double whole_x_real_time(const ModeRuns& mode) {
    return mode.whole_wall_s > 0.0 ? mode.whole_sim_s / mode.whole_wall_s : 0.0;
}

// Context switches, voluntary and not, of every thread of this process and of
// its children that have ended and been waited for (a case's controller
// process, the ping-pong's second process): the hand-offs a round costs.
std::uint64_t context_switches_so_far() {
    rusage self{}, children{};
    getrusage(RUSAGE_SELF, &self);
    getrusage(RUSAGE_CHILDREN, &children);
    return static_cast<std::uint64_t>(self.ru_nvcsw + self.ru_nivcsw + children.ru_nvcsw + children.ru_nivcsw);
}

// The rig's own participants hold the run's rig identity while a secured mode
// runs, and none again after it (rig/runtime/dds_security.h).
class RigIdentityScope {
public:
    explicit RigIdentityScope(const std::optional<DdsSecurityRun>& credentials) : active_(credentials.has_value()) {
        if (active_) use_dds_security_identity(credentials->identity_dir(kRigIdentity));
    }
    ~RigIdentityScope() {
        if (active_) use_dds_security_identity(std::filesystem::path());
    }
    RigIdentityScope(const RigIdentityScope&) = delete;
    RigIdentityScope& operator=(const RigIdentityScope&) = delete;

private:
    bool active_;
};

double percentile(std::vector<double> values, double fraction) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    const auto index = static_cast<std::size_t>(fraction * static_cast<double>(values.size() - 1) + 0.5);
    return values[std::min(index, values.size() - 1)];
}

struct ModeFigures {
    double us_per_round = 0.0;
    double rounds_per_s = 0.0;
    double x_real_time = 0.0;  // simulated / wall, whole case (start-up included)
    double startup_p50_s = 0.0;
    double startup_p99_s = 0.0;
    double trace_bytes_per_sim_minute = 0.0;
    std::uint64_t rounds = 0;
    double rounds_per_sim_s = 0.0;
};

ModeFigures figures_of(const std::vector<CaseResult>& runs) {
    ModeFigures f;
    double stepping = 0.0, sim = 0.0, wall = 0.0, trace_bytes_per_min = 0.0;
    std::vector<double> startups;
    for (const CaseResult& run : runs) {
        f.rounds += run.rounds;
        stepping += run.stepping_wall_seconds;
        sim += run.sim_seconds;
        wall += run.wall_seconds;
        startups.push_back(run.startup_wall_seconds);
        std::error_code error;
        const auto bytes = std::filesystem::file_size(run.trace_path, error);
        if (!error && run.sim_seconds > 0.0) trace_bytes_per_min += static_cast<double>(bytes) / run.sim_seconds * 60.0;
    }
    if (f.rounds > 0) f.us_per_round = stepping / static_cast<double>(f.rounds) * 1e6;
    if (stepping > 0.0) f.rounds_per_s = static_cast<double>(f.rounds) / stepping;
    if (wall > 0.0) f.x_real_time = sim / wall;
    if (sim > 0.0) f.rounds_per_sim_s = static_cast<double>(f.rounds) / sim;
    f.startup_p50_s = percentile(startups, 0.50);
    f.startup_p99_s = percentile(startups, 0.99);
    if (!runs.empty()) f.trace_bytes_per_sim_minute = trace_bytes_per_min / static_cast<double>(runs.size());
    return f;
}

// A series of ping-pongs (one before each repeat): medians over them.
struct FloorFigures {
    PingPongResult result;
    std::vector<double> p50s;  // per repeat
};

FloorFigures floor_figures_of(const std::vector<PingPongResult>& slices, std::uint32_t rounds) {
    FloorFigures f;
    std::vector<double> p99s, means, matched;
    for (const PingPongResult& slice : slices) {
        f.p50s.push_back(slice.p50_us);
        p99s.push_back(slice.p99_us);
        means.push_back(slice.mean_us);
        matched.push_back(slice.matched_after_s);
    }
    f.result.rounds = rounds;
    f.result.p50_us = percentile(f.p50s, 0.5);
    f.result.p99_us = percentile(p99s, 0.5);
    f.result.mean_us = percentile(means, 0.5);
    f.result.matched_after_s = percentile(matched, 0.5);
    return f;
}

// Each repeat's us/round over the ping-pong measured just before it.
std::vector<double> ratios_to_floor(const ModeRuns& mode, const std::vector<PingPongResult>& floors) {
    std::vector<double> ratios;
    for (std::size_t r = 0; r < floors.size(); ++r) {
        std::vector<CaseResult> runs_of_repeat;
        for (std::size_t i = 0; i < mode.runs.size(); ++i) {
            if (mode.repeat_of[i] == static_cast<int>(r)) runs_of_repeat.push_back(mode.runs[i]);
        }
        if (runs_of_repeat.empty() || floors[r].p50_us <= 0.0) continue;
        ratios.push_back(figures_of(runs_of_repeat).us_per_round / floors[r].p50_us);
    }
    return ratios;
}

std::string load_average() {
    std::ifstream in("/proc/loadavg");
    std::string one, five, fifteen;
    in >> one >> five >> fifteen;
    return in ? one + " " + five + " " + fifteen : std::string("unknown");
}

}  // namespace

int run_speed_bench(const SpeedBenchOptions& options, std::ostream& out, std::ostream& err) {
    std::vector<CaseSpec> specs;
    for (const std::string& file : options.cases) {
        try {
            CaseSpec spec = load_case_file(file);
            validate_for_run(spec, options.run);
            if (spec.mode != ClockMode::lockstep) {
                err << "rig bench: " << file << ": a real-time case runs at 1x by definition; give lockstep cases\n";
                return 2;
            }
            specs.push_back(std::move(spec));
        } catch (const std::exception& error) {
            err << "rig bench: " << error.what() << "\n";
            return 2;
        }
    }
    if (specs.empty()) {
        err << "rig bench: no case given\n";
        return 2;
    }
    // Where bench.json and the runs' traces go, checked before minutes of runs (harness/run/output_dir.h).
    try {
        prepare_output_directory(options.out_dir);
    } catch (const OutputDirError& error) {
        err << "rig bench: " << error.what() << "; nothing was run\n";
        return 2;
    }
    const std::string load_before = load_average();
    std::optional<DdsSecurityRun> credentials;
    if (options.dds_security) {
        try {
            credentials = make_dds_security_run(options.out_dir / "security");
        } catch (const std::exception& error) {
            err << "rig bench: --dds-security: " << error.what() << "\n";
            return 1;
        }
    }

    // The floor is measured once before each repeat of the process-mode runs,
    // and each repeat's cost is divided by the floor measured just before it:
    // on this 2-core machine the ping-pong alone moved between 57 and 81 us a
    // round trip from one invocation to the next (where the scheduler put the
    // two processes' threads), more than the rig's own cost moved, so a single
    // floor made the ratio a draw. It is measured twice, in the two placements
    // process mode runs in (rig/host/cpu_lease.h): the ping-pong's threads and
    // its second process on one leased CPU at SCHED_BATCH, as a lockstep case
    // runs by default, and left to the scheduler, as with `rig run --no-pin`.
    // Each process-mode row is judged against the floor of its own placement.
    std::vector<PingPongResult> floors_pinned, floors_free;
    std::uint64_t floor_switches_pinned = 0, floor_switches_free = 0;
    std::optional<PingPongResult> secured_floor;
    auto measure_floor = [&](bool pin) {
        const CpuLease cpu(pin);
        const std::uint64_t switches_before = context_switches_so_far();
        PingPongResult result = run_dds_pingpong(options.pingpong);
        (pin ? floor_switches_pinned : floor_switches_free) += context_switches_so_far() - switches_before;
        return result;
    };
    try {
        if (credentials) {
            const RigIdentityScope rig_identity(credentials);
            PingPongOptions secured = options.pingpong;
            secured.pong_environment = dds_security_environment(credentials->dir, kRigIdentity);
            const CpuLease cpu(true);
            secured_floor = run_dds_pingpong(secured);
        }
    } catch (const std::exception& error) {
        err << "rig bench: " << error.what() << "\n";
        return 1;
    }

    bool failed = false;
    // process: on one leased CPU (the default); process_unpinned: --no-pin.
    std::vector<ModeRuns> modes = {{"process", {}, {}}, {"process_unpinned", {}, {}}, {"in_process", {}, {}}};
    if (credentials) modes.push_back({"process_dds_security", {}, {}});
    std::map<std::string, std::set<std::string>> digests;  // case -> digests seen in every run of every mode
    for (ModeRuns& mode : modes) {
        for (int r = 0; r < options.repeat; ++r) {
            if (mode.mode == "process" || mode.mode == "process_unpinned") {
                try {
                    if (mode.mode == "process") {
                        floors_pinned.push_back(measure_floor(true));
                    } else {
                        floors_free.push_back(measure_floor(false));
                    }
                } catch (const std::exception& error) {
                    err << "rig bench: " << error.what() << "\n";
                    return 1;
                }
            }
            for (const CaseSpec& spec : specs) {
                RunOptions run_options = options.run;
                run_options.jobs = 1;
                run_options.in_process = mode.mode == "in_process";
                run_options.pin_cpu = mode.mode != "process_unpinned";
                run_options.out_dir = options.out_dir / mode.mode / std::to_string(r);
                const bool secured = mode.mode == "process_dds_security";
                if (secured) run_options.dds_security_dir = credentials->dir;
                const RigIdentityScope rig_identity(secured ? credentials : std::nullopt);
                const std::vector<CaseInstance> instances = expand_runs({spec}, run_options);
                const std::uint64_t switches_before = context_switches_so_far();
                const std::uint64_t allocations_before = stepping_allocations();
                const WallStopwatch whole;
                const CaseRun run = run_case(spec, instances.front().seed, instances.front().name, run_options);
                const double whole_wall_s = whole.elapsed_s();
                mode.context_switches += context_switches_so_far() - switches_before;
                mode.stepping_allocations += stepping_allocations() - allocations_before;
                const CaseResult& result = run.result;
                const std::string expected_mode = mode.mode == "in_process" ? "in_process" : "process";
                if (!result.error.empty() || result.controller_mode != expected_mode) {
                    err << "rig bench: " << result.name << " (" << mode.mode << ", run " << r + 1 << "): "
                        << (result.error.empty() ? "ran as " + result.controller_mode : result.error) << "\n";
                    failed = true;
                    continue;
                }
                digests[result.name].insert(result.trace_sha256);
                mode.whole_wall_s += whole_wall_s;
                mode.whole_sim_s += result.sim_seconds;
                mode.runs.push_back(result);
                mode.repeat_of.push_back(r);
            }
        }
    }
    bool digests_equal = true;
    for (const auto& [name, seen] : digests) {
        if (seen.size() != 1) {
            digests_equal = false;
            err << "rig bench: " << name << ": " << seen.size() << " different trace digests across runs and modes\n";
        }
    }

    const ModeFigures process = figures_of(modes[0].runs);
    const ModeFigures process_unpinned = figures_of(modes[1].runs);
    const ModeFigures in_process = figures_of(modes[2].runs);
    const FloorFigures pinned_floor = floor_figures_of(floors_pinned, options.pingpong.rounds);
    const FloorFigures free_floor = floor_figures_of(floors_free, options.pingpong.rounds);
    const std::vector<double> process_ratios = ratios_to_floor(modes[0], floors_pinned);
    const std::vector<double> process_unpinned_ratios = ratios_to_floor(modes[1], floors_free);
    const double process_ratio = percentile(process_ratios, 0.5);
    const double process_unpinned_ratio = percentile(process_unpinned_ratios, 0.5);
    double sim_per_case = 0.0;
    for (const CaseResult& run : modes[0].runs) sim_per_case += run.sim_seconds;
    if (!modes[0].runs.empty()) sim_per_case /= static_cast<double>(modes[0].runs.size());

    out << "rig bench: " << specs.size() << " case(s), " << options.repeat << " run(s) per case and mode, one at a time; "
        << std::thread::hardware_concurrency() << " cores; load average " << load_before << " before, "
        << load_average() << " after\n";
    out << "  simulated per case " << fixed_text(sim_per_case, 1) << " s; " << fixed_text(process.rounds_per_sim_s, 1)
        << " rounds per simulated second; trace digests "
        << (digests_equal ? "identical in every run of every mode" : "DIFFER (see above)") << "\n\n";
    out << "                                      us/round  rounds/s  x real time  start-up p50/p99 s  trace KB/sim-min  "
           "vs floor\n";
    auto floor_row = [&](const char* label, const FloorFigures& f) {
        out << "  " << label << std::setw(8) << fixed_text(f.result.p50_us, 1) << "  " << std::setw(8)
            << fixed_text(1e6 / std::max(f.result.p50_us, 1e-9), 0) << "  " << std::setw(11) << "-" << "  " << std::setw(18)
            << (fixed_text(f.result.matched_after_s, 3) + " (match)") << "  " << std::setw(16) << "-" << "  "
            << std::setw(8) << "1.00" << "   (p99 " << fixed_text(f.result.p99_us, 1) << " us; " << f.p50s.size() << " x "
            << f.result.rounds << " round trips, one before each repeat: p50 " << fixed_text(percentile(f.p50s, 0.0), 1)
            << "-" << fixed_text(percentile(f.p50s, 1.0), 1) << " us)\n";
    };
    auto row = [&](const char* label, const ModeFigures& f, double ratio) {
        out << "  " << label << std::setw(8) << fixed_text(f.us_per_round, 1) << "  " << std::setw(8)
            << fixed_text(f.rounds_per_s, 0) << "  " << std::setw(11) << fixed_text(f.x_real_time, 1) << "  " << std::setw(18)
            << (fixed_text(f.startup_p50_s, 3) + " / " + fixed_text(f.startup_p99_s, 3)) << "  " << std::setw(16)
            << fixed_text(f.trace_bytes_per_sim_minute / 1024.0, 1) << "  " << std::setw(8)
            << fixed_text(ratio, 2) << "\n";
    };
    floor_row("DDS ping-pong, 2 processes, 1 CPU  ", pinned_floor);
    row("process mode, 1 CPU (default)      ", process, process_ratio);
    row("in process (SIL), 1 CPU            ", in_process,
        in_process.us_per_round / std::max(pinned_floor.result.p50_us, 1e-9));
    floor_row("DDS ping-pong, 2 processes, any CPU", free_floor);
    row("process mode, any CPU (--no-pin)   ", process_unpinned, process_unpinned_ratio);
    std::optional<ModeFigures> secured;
    if (credentials) {
        secured = figures_of(modes[3].runs);
        out << "  DDS ping-pong, DDS-Security, 1 CPU" << std::setw(8) << fixed_text(secured_floor->p50_us, 1) << "  "
            << std::setw(8) << fixed_text(1e6 / std::max(secured_floor->p50_us, 1e-9), 0) << "  " << std::setw(11) << "-"
            << "  " << std::setw(18) << (fixed_text(secured_floor->matched_after_s, 3) + " (match)") << "  "
            << std::setw(16) << "-" << "  " << std::setw(8)
            << fixed_text(secured_floor->p50_us / std::max(pinned_floor.result.p50_us, 1e-9), 2) << "   (p99 "
            << fixed_text(secured_floor->p99_us, 1) << " us, " << secured_floor->rounds << " round trips)\n";
        row("process mode, DDS-Security, 1 CPU  ", *secured,
            secured->us_per_round / std::max(pinned_floor.result.p50_us, 1e-9));
        out << "  DDS-Security costs " << fixed_text(secured->us_per_round - process.us_per_round, 1)
            << " us per round in process mode (" << fixed_text(secured_floor->p50_us - pinned_floor.result.p50_us, 1)
            << " us per ping-pong round trip)\n";
    }
    out << "\n  us/round: stepping wall time / rounds (a round: the rig's nodes, a tick to the controller, its "
           "answer);\n  x real time: simulated / wall per case, start-up included; 1 CPU: the case's thread, Fast "
           "DDS's threads and the\n  controller process on one leased CPU at SCHED_BATCH (rig/host/cpu_lease.h), "
           "the ping-pong's likewise; vs floor:\n  us/round / the p50 of the ping-pong in the same placement "
           "(process mode: each repeat over the ping-pong\n  measured just before it, the median of those; SIL over "
           "the median one-CPU ping-pong).\n";
    out << "  x real time to the trace finished and judged (the whole run, as a sweep pays it): process mode "
        << fixed_text(whole_x_real_time(modes[0]), 1) << ", any CPU " << fixed_text(whole_x_real_time(modes[1]), 1)
        << ", SIL " << fixed_text(whole_x_real_time(modes[2]), 1) << "\n";
    // Hand-offs: a round trip of the ping-pong against a round (whole runs: start-up and judging included).
    auto per_round = [](std::uint64_t switches, std::uint64_t rounds) {
        return rounds > 0 ? static_cast<double>(switches) / static_cast<double>(rounds) : 0.0;
    };
    const std::uint64_t floor_round_trips =
        static_cast<std::uint64_t>(options.pingpong.rounds + options.pingpong.warmup_rounds);
    const double floor_switches_pinned_per_round = per_round(floor_switches_pinned, floor_round_trips * floors_pinned.size());
    const double floor_switches_free_per_round = per_round(floor_switches_free, floor_round_trips * floors_free.size());
    const double process_switches_per_round = per_round(modes[0].context_switches, process.rounds);
    const double process_unpinned_switches_per_round = per_round(modes[1].context_switches, process_unpinned.rounds);
    const double in_process_switches_per_round = per_round(modes[2].context_switches, in_process.rounds);
    out << "  context switches a round (both processes, every thread; a case's start-up and judging included):\n"
           "    1 CPU: ping-pong "
        << fixed_text(floor_switches_pinned_per_round, 1) << ", process mode " << fixed_text(process_switches_per_round, 1)
        << ", SIL " << fixed_text(in_process_switches_per_round, 1) << "; any CPU: ping-pong "
        << fixed_text(floor_switches_free_per_round, 1) << ", process mode " << fixed_text(process_unpinned_switches_per_round, 1)
        << "\n";
    // Allocations a round while stepping (issue 32): the rig's process only.
    const double process_allocations_per_round = per_round(modes[0].stepping_allocations, process.rounds);
    const double in_process_allocations_per_round = per_round(modes[2].stepping_allocations, in_process.rounds);
    if (heap_allocations_counted()) {
        out << "  heap allocations a round while stepping (operator new on the lockstep's thread: the rig's nodes, a\n"
               "  plugin, the recorder's drain; not the controller process's, nor SQLite's own malloc): process mode "
            << fixed_text(process_allocations_per_round, 1) << ", SIL " << fixed_text(in_process_allocations_per_round, 1)
            << "\n";
    } else {
        out << "  heap allocations: not counted (this program has no counting operator new, rig/host/heap_count.h)\n";
    }
    if (process.us_per_round > 0.0 && pinned_floor.result.p50_us > 0.0) {
        out << "  one CPU against any CPU: process mode " << fixed_text(process_unpinned.us_per_round / process.us_per_round, 2)
            << "x as fast a round, the ping-pong " << fixed_text(free_floor.result.p50_us / pinned_floor.result.p50_us, 2)
            << "x\n";
    }

    auto floor_json = [](const FloorFigures& f) {
        return nlohmann::json{{"rounds", f.result.rounds},
                              {"p50_us", f.result.p50_us},
                              {"p99_us", f.result.p99_us},
                              {"mean_us", f.result.mean_us},
                              {"matched_after_s", f.result.matched_after_s},
                              {"p50_us_per_repeat", f.p50s}};
    };
    nlohmann::json json = {
        {"load_average_before", load_before},
        {"load_average_after", load_average()},
        {"cores", std::thread::hardware_concurrency()},
        {"runs_per_case_and_mode", options.repeat},
        {"digests_identical", digests_equal},
        {"thread_id_cache", thread_id_cache_in_use()},
        {"pingpong", floor_json(pinned_floor)},
        {"pingpong_unpinned", floor_json(free_floor)},
    };
    for (const auto& [key, f, floor_us] :
         {std::tuple{"process", process, pinned_floor.result.p50_us},
          std::tuple{"process_unpinned", process_unpinned, free_floor.result.p50_us},
          std::tuple{"in_process", in_process, pinned_floor.result.p50_us}}) {
        json[key] = {{"us_per_round", f.us_per_round},
                     {"rounds_per_s", f.rounds_per_s},
                     {"rounds", f.rounds},
                     {"x_real_time", f.x_real_time},
                     {"startup_p50_s", f.startup_p50_s},
                     {"startup_p99_s", f.startup_p99_s},
                     {"trace_bytes_per_sim_minute", f.trace_bytes_per_sim_minute},
                     {"ratio_to_floor", f.us_per_round / std::max(floor_us, 1e-9)}};
    }
    json["process"]["x_real_time_judged"] = whole_x_real_time(modes[0]);
    json["process_unpinned"]["x_real_time_judged"] = whole_x_real_time(modes[1]);
    json["in_process"]["x_real_time_judged"] = whole_x_real_time(modes[2]);
    json["process"]["ratio_to_floor"] = process_ratio;
    json["process"]["ratio_to_floor_per_repeat"] = process_ratios;
    json["process_unpinned"]["ratio_to_floor"] = process_unpinned_ratio;
    json["process_unpinned"]["ratio_to_floor_per_repeat"] = process_unpinned_ratios;
    json["process"]["context_switches_per_round"] = process_switches_per_round;
    json["process_unpinned"]["context_switches_per_round"] = process_unpinned_switches_per_round;
    json["in_process"]["context_switches_per_round"] = in_process_switches_per_round;
    if (heap_allocations_counted()) {
        json["process"]["allocations_per_round"] = process_allocations_per_round;
        json["in_process"]["allocations_per_round"] = in_process_allocations_per_round;
    }
    json["pingpong"]["context_switches_per_round"] = floor_switches_pinned_per_round;
    json["pingpong_unpinned"]["context_switches_per_round"] = floor_switches_free_per_round;
    if (secured) {
        json["pingpong_dds_security"] = {{"rounds", secured_floor->rounds},
                                         {"p50_us", secured_floor->p50_us},
                                         {"p99_us", secured_floor->p99_us},
                                         {"mean_us", secured_floor->mean_us},
                                         {"matched_after_s", secured_floor->matched_after_s}};
        json["process_dds_security"] = {{"us_per_round", secured->us_per_round},
                                        {"rounds_per_s", secured->rounds_per_s},
                                        {"rounds", secured->rounds},
                                        {"x_real_time", secured->x_real_time},
                                        {"startup_p50_s", secured->startup_p50_s},
                                        {"startup_p99_s", secured->startup_p99_s},
                                        {"ratio_to_floor", secured->us_per_round / std::max(pinned_floor.result.p50_us, 1e-9)},
                                        {"extra_us_per_round", secured->us_per_round - process.us_per_round}};
    }
    std::filesystem::create_directories(options.out_dir);
    std::ofstream(options.out_dir / "bench.json") << json.dump(2) << "\n";
    out << "  written: " << (options.out_dir / "bench.json").string() << "\n";
    return failed || !digests_equal ? 1 : 0;
}

}  // namespace rig::harness
