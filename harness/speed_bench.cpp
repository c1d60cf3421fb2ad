#include "harness/speed_bench.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <map>
#include <ostream>
#include <set>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "harness/dds_security_setup.h"
#include "harness/output_dir.h"
#include "harness/case_spec.h"
#include "harness/results_writer.h"
#include "rig/runtime/dds_security.h"

namespace rig::harness {
namespace {

struct ModeRuns {
    std::string mode;  // process, in_process, process_dds_security
    std::vector<CaseResult> runs;
    std::vector<int> repeat_of;  // per run: which repeat (0-based) it belongs to
};

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

std::string load_average() {
    std::ifstream in("/proc/loadavg");
    std::string one, five, fifteen;
    in >> one >> five >> fifteen;
    return in ? one + " " + five + " " + fifteen : std::string("unknown");
}

std::string fixed(double value, int digits) {
    std::ostringstream text;
    text << std::fixed << std::setprecision(digits) << value;
    return text.str();
}

}  // namespace

int run_speed_bench(const SpeedBenchOptions& options, std::ostream& out, std::ostream& err) {
    std::vector<CaseSpec> specs;
    for (const std::string& file : options.cases) {
        try {
            CaseSpec spec = load_case_file(file);
            validate_for_run(spec, options.run);
            if (spec.mode != RunMode::lockstep) {
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
    // Where bench.json and the runs' traces go, checked before minutes of runs (harness/output_dir.h).
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
    // floor made the ratio a draw.
    std::vector<PingPongResult> floors;
    std::optional<PingPongResult> secured_floor;
    try {
        if (credentials) {
            const RigIdentityScope rig_identity(credentials);
            PingPongOptions secured = options.pingpong;
            secured.pong_environment = dds_security_environment(credentials->dir, kRigIdentity);
            secured_floor = run_dds_pingpong(secured);
        }
    } catch (const std::exception& error) {
        err << "rig bench: " << error.what() << "\n";
        return 1;
    }

    bool failed = false;
    std::vector<ModeRuns> modes = {{"process", {}, {}}, {"in_process", {}, {}}};
    if (credentials) modes.push_back({"process_dds_security", {}, {}});
    std::map<std::string, std::set<std::string>> digests;  // case -> digests seen in every run of both modes
    for (ModeRuns& mode : modes) {
        for (int r = 0; r < options.repeat; ++r) {
            if (mode.mode == "process") {
                try {
                    floors.push_back(run_dds_pingpong(options.pingpong));
                } catch (const std::exception& error) {
                    err << "rig bench: " << error.what() << "\n";
                    return 1;
                }
            }
            for (const CaseSpec& spec : specs) {
                RunOptions run_options = options.run;
                run_options.jobs = 1;
                run_options.in_process = mode.mode == "in_process";
                run_options.out_dir = options.out_dir / mode.mode / std::to_string(r);
                const bool secured = mode.mode == "process_dds_security";
                if (secured) run_options.dds_security_dir = credentials->dir;
                const RigIdentityScope rig_identity(secured ? credentials : std::nullopt);
                const std::vector<CaseInstance> instances = expand_runs({spec}, run_options);
                const CaseRun run = run_case(spec, instances.front().seed, instances.front().name, run_options);
                const CaseResult& result = run.result;
                const std::string expected_mode = secured ? "process" : mode.mode;
                if (!result.error.empty() || result.controller_mode != expected_mode) {
                    err << "rig bench: " << result.name << " (" << mode.mode << ", run " << r + 1 << "): "
                        << (result.error.empty() ? "ran as " + result.controller_mode : result.error) << "\n";
                    failed = true;
                    continue;
                }
                digests[result.name].insert(result.trace_sha256);
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
    const ModeFigures in_process = figures_of(modes[1].runs);
    // The floor row: medians over the repeats' ping-pongs.
    PingPongResult floor;
    std::vector<double> floor_p50s;
    {
        std::vector<double> p99s, means, matched;
        for (const PingPongResult& slice : floors) {
            floor_p50s.push_back(slice.p50_us);
            p99s.push_back(slice.p99_us);
            means.push_back(slice.mean_us);
            matched.push_back(slice.matched_after_s);
        }
        floor.rounds = options.pingpong.rounds;
        floor.p50_us = percentile(floor_p50s, 0.5);
        floor.p99_us = percentile(p99s, 0.5);
        floor.mean_us = percentile(means, 0.5);
        floor.matched_after_s = percentile(matched, 0.5);
    }
    const double floor_us = floor.p50_us;
    // Process mode against the floor: each repeat's us/round over the ping-pong
    // measured just before it; the median of those.
    std::vector<double> process_ratios;
    for (std::size_t r = 0; r < floors.size(); ++r) {
        std::vector<CaseResult> runs_of_repeat;
        for (std::size_t i = 0; i < modes[0].runs.size(); ++i) {
            if (modes[0].repeat_of[i] == static_cast<int>(r)) runs_of_repeat.push_back(modes[0].runs[i]);
        }
        if (runs_of_repeat.empty() || floors[r].p50_us <= 0.0) continue;
        process_ratios.push_back(figures_of(runs_of_repeat).us_per_round / floors[r].p50_us);
    }
    const double process_ratio = percentile(process_ratios, 0.5);
    double sim_per_case = 0.0;
    for (const CaseResult& run : modes[0].runs) sim_per_case += run.sim_seconds;
    if (!modes[0].runs.empty()) sim_per_case /= static_cast<double>(modes[0].runs.size());

    out << "rig bench: " << specs.size() << " case(s), " << options.repeat << " run(s) per case and mode, one at a time; "
        << std::thread::hardware_concurrency() << " cores; load average " << load_before << " before, "
        << load_average() << " after\n";
    out << "  simulated per case " << fixed(sim_per_case, 1) << " s; " << fixed(process.rounds_per_sim_s, 1)
        << " rounds per simulated second; trace digests "
        << (digests_equal ? (credentials ? "identical in every run of every mode" : "identical in every run of both modes") : "DIFFER (see above)") << "\n\n";
    out << "                               us/round  rounds/s  x real time  start-up p50/p99 s  trace KB/sim-min  "
           "vs floor\n";
    out << "  DDS ping-pong, 2 processes   " << std::setw(8) << fixed(floor.p50_us, 1) << "  " << std::setw(8)
        << fixed(1e6 / std::max(floor.p50_us, 1e-9), 0) << "  " << std::setw(11) << "-" << "  " << std::setw(18)
        << (fixed(floor.matched_after_s, 3) + " (match)") << "  " << std::setw(16) << "-" << "  " << std::setw(8)
        << "1.00" << "   (p99 " << fixed(floor.p99_us, 1) << " us; " << floors.size() << " x " << floor.rounds
        << " round trips, one before each repeat: p50 " << fixed(percentile(floor_p50s, 0.0), 1) << "-"
        << fixed(percentile(floor_p50s, 1.0), 1) << " us)\n";
    auto row = [&](const char* label, const ModeFigures& f, double ratio) {
        out << "  " << label << std::setw(8) << fixed(f.us_per_round, 1) << "  " << std::setw(8)
            << fixed(f.rounds_per_s, 0) << "  " << std::setw(11) << fixed(f.x_real_time, 1) << "  " << std::setw(18)
            << (fixed(f.startup_p50_s, 3) + " / " + fixed(f.startup_p99_s, 3)) << "  " << std::setw(16)
            << fixed(f.trace_bytes_per_sim_minute / 1024.0, 1) << "  " << std::setw(8)
            << fixed(ratio, 2) << "\n";
    };
    row("process mode                 ", process, process_ratio);
    row("in process (SIL)             ", in_process, in_process.us_per_round / std::max(floor_us, 1e-9));
    std::optional<ModeFigures> secured;
    if (credentials) {
        secured = figures_of(modes[2].runs);
        out << "  DDS ping-pong, DDS-Security  " << std::setw(8) << fixed(secured_floor->p50_us, 1) << "  "
            << std::setw(8) << fixed(1e6 / std::max(secured_floor->p50_us, 1e-9), 0) << "  " << std::setw(11) << "-"
            << "  " << std::setw(18) << (fixed(secured_floor->matched_after_s, 3) + " (match)") << "  "
            << std::setw(16) << "-" << "  " << std::setw(8) << fixed(secured_floor->p50_us / std::max(floor_us, 1e-9), 2)
            << "   (p99 " << fixed(secured_floor->p99_us, 1) << " us, " << secured_floor->rounds << " round trips)\n";
        row("process mode, DDS-Security   ", *secured, secured->us_per_round / std::max(floor_us, 1e-9));
        out << "  DDS-Security costs " << fixed(secured->us_per_round - process.us_per_round, 1)
            << " us per round in process mode (" << fixed(secured_floor->p50_us - floor_us, 1)
            << " us per ping-pong round trip)\n";
    }
    out << "\n  us/round: stepping wall time / rounds (a round: the rig's nodes, a tick to the controller, its "
           "answer);\n  x real time: simulated / wall per case, start-up included; vs floor: us/round / ping-pong "
           "p50 (process mode: each repeat\n  over the ping-pong measured just before it, the median of "
           "those; the other rows over the median ping-pong).\n";

    nlohmann::json json = {
        {"load_average_before", load_before},
        {"load_average_after", load_average()},
        {"cores", std::thread::hardware_concurrency()},
        {"runs_per_case_and_mode", options.repeat},
        {"digests_identical", digests_equal},
        {"pingpong", {{"rounds", floor.rounds}, {"p50_us", floor.p50_us}, {"p99_us", floor.p99_us},
                      {"mean_us", floor.mean_us}, {"matched_after_s", floor.matched_after_s},
                      {"p50_us_per_repeat", floor_p50s}}},
    };
    for (const auto& [key, f] : {std::pair{"process", process}, std::pair{"in_process", in_process}}) {
        json[key] = {{"us_per_round", f.us_per_round},
                     {"rounds_per_s", f.rounds_per_s},
                     {"rounds", f.rounds},
                     {"x_real_time", f.x_real_time},
                     {"startup_p50_s", f.startup_p50_s},
                     {"startup_p99_s", f.startup_p99_s},
                     {"trace_bytes_per_sim_minute", f.trace_bytes_per_sim_minute},
                     {"ratio_to_floor", f.us_per_round / std::max(floor_us, 1e-9)}};
    }
    json["process"]["ratio_to_floor"] = process_ratio;
    json["process"]["ratio_to_floor_per_repeat"] = process_ratios;
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
                                        {"ratio_to_floor", secured->us_per_round / std::max(floor_us, 1e-9)},
                                        {"extra_us_per_round", secured->us_per_round - process.us_per_round}};
    }
    std::filesystem::create_directories(options.out_dir);
    std::ofstream(options.out_dir / "bench.json") << json.dump(2) << "\n";
    out << "  written: " << (options.out_dir / "bench.json").string() << "\n";
    return failed || !digests_equal ? 1 : 0;
}

}  // namespace rig::harness
