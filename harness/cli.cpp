// `rig`: the rig's one command line (docs/running-cases.md, `rig --help`).
//   rig --version
//   rig run CASE_OR_DIR... [--out DIR] [--seed N] [--jobs N] [--in-process | --dds-security] [--domain N] [--no-pin] [--quiet | --verbose]
//   rig sweep CASE_OR_DIR... --seeds N [--first-seed N] [--keep-traces failed|all|none] [--out DIR] [--jobs N] [--in-process] [--no-pin]
//   rig bench CASE... [--repeat N] [--pingpong-rounds N] [--dds-security] [--out DIR]
//   rig judge OUT_DIR|TRACE... [--out NEW_DIR] [--check]
//   rig nmea decode FILE|-
//   rig dds-check [--samples N] [--log-dir DIR]
//   rig modbus serve [--tcp ADDRESS:PORT | --rtu DEVICE ...] [synthetic signal options]
//   rig emulate gnss CASE [--port DEVICE | --pty] [--baud N]
//   rig pty [...], rig hid list [...]
// A usage error (unknown command or option, missing or bad value) names the
// word at fault and exits 2; `rig --version` prints the version and commit.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <fstream>
#include <map>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <unistd.h>

#include "harness/nmea_decode_tool.h"
#include "harness/bench_emulate.h"
#include "harness/bench_hid.h"
#include "harness/cli_checks.h"
#include "harness/bench_modbus.h"
#include "harness/bench_serial.h"
#include "harness/build_info.h"
#include "harness/shard.h"
#include "harness/trace_mcap.h"
#include "harness/case_runner.h"
#include "harness/case_world.h"
#include "harness/dds_security_setup.h"
#include "harness/html_report.h"
#include "harness/judge_command.h"
#include "harness/output_dir.h"
#include "harness/results_writer.h"
#include "harness/run_interrupt.h"
#include "harness/run_progress.h"
#include "rig/runtime/clock.h"
#include "rig/config/config_error.h"
#include "harness/speed_bench.h"
#include "harness/sweep.h"
#include "rig/host/dds_check.h"
#include "rig/host/shm_cleanup.h"
#include "rig/host/dds_pingpong.h"
#include "rig/runtime/dds_security.h"

namespace {

std::filesystem::path own_directory() {
    std::error_code error;
    const auto self = std::filesystem::read_symlink("/proc/self/exe", error);
    return error ? std::filesystem::current_path() : self.parent_path();
}

// Every case file read and validated before anything starts (the errors go to
// standard error, and nothing is run: nullopt).
std::optional<std::vector<rig::harness::CaseSpec>> load_cases(const std::vector<std::string>& inputs,
                                                              const rig::harness::RunOptions& options,
                                                              const std::optional<rig::harness::Shard>& shard) {
    using namespace rig::harness;
    std::vector<CaseSpec> specs;
    try {
        // Every file is read and validated before anything starts.
        std::vector<std::string> errors;
        for (const auto& path : expand_case_paths(inputs)) {
            try {
                specs.push_back(load_case_file(path));
                validate_for_run(specs.back(), options);
                // Dropouts and episodes against the case's length, which only its route gives
                // (a boundary case's route and devices are checked by its loader).
                if (specs.back().system == CaseSystem::breakpoint) {
                    const CaseWorld world = build_case_world(specs.back(), specs.back().seed);
                    check_case_timeline(specs.back(), rig::ns_to_seconds(world.end_ns), world.breakpoint_crossing_s);
                }
            } catch (const std::exception& error) {
                errors.push_back(error.what());
            }
        }
        // Two cases with one name would write the same cases/NAME/.
        for (const std::string& error : duplicate_case_name_errors(specs)) errors.push_back(error);
        // ... and so would a run of a `seeds:` case named like another case (NAME-seedN).
        if (errors.empty()) {
            std::map<std::string, std::size_t> runs_named;
            for (const CaseInstance& run : expand_runs(specs, options)) {
                const auto [earlier, inserted] = runs_named.emplace(run.name, run.spec_index);
                if (!inserted) {
                    errors.push_back(specs[run.spec_index].source_path.string() + ": its run '" + run.name +
                                     "' has the name of a run of " + specs[earlier->second].source_path.string() +
                                     "; both would write cases/" + run.name + "/: rename one");
                }
            }
        }
        if (!errors.empty()) {
            for (const auto& error : errors) std::cerr << "rig: " << error << "\n";
            std::cerr << "rig: " << errors.size() << " case file error(s); nothing was run\n";
            return std::nullopt;
        }
        // Every file was checked above, whichever shard it is in: a broken case fails every shard's job.
        if (shard) {
            const std::size_t all = specs.size();
            std::erase_if(specs, [&](const CaseSpec& spec) { return !in_shard(spec.name, *shard); });
            std::cerr << "rig: shard " << shard->index << "/" << shard->count << ": " << specs.size() << " of " << all
                      << " cases (join the shards' outputs with rig merge)\n";
        }
    } catch (const std::exception& error) {
        std::cerr << "rig: " << error.what() << "\n";
        return std::nullopt;
    }
    return specs;
}

// Refuses an output directory that cannot take results (before any case runs),
// makes the run's DDS-Security credentials if asked, then removes what killed
// participants of earlier runs left in /dev/shm.
bool prepare_run(const rig::harness::RunOptions& options, rig::harness::Verbosity verbosity) {
    using namespace rig::harness;
    try {
        prepare_output_directory(options.out_dir);
    } catch (const OutputDirError& error) {
        std::cerr << "rig: " << error.what() << "; nothing was run\n";
        return false;
    }
    // --dds-security: this run's credentials, before any participant exists
    // (docs/dds-security.md); every participant of the rig's holds its identity.
    if (options.dds_security_dir) {
        try {
            const DdsSecurityRun credentials = make_dds_security_run(*options.dds_security_dir);
            rig::use_dds_security_identity(credentials.identity_dir(kRigIdentity));
        } catch (const std::exception& error) {
            std::cerr << "rig: --dds-security: " << error.what() << "; nothing was run\n";
            return false;
        }
    }
    // Removed with --quiet too; only said without it (--quiet says only failures).
    if (const rig::ShmCleanup cleaned = rig::remove_dead_participant_segments();
        !cleaned.removed.empty() && verbosity != rig::harness::Verbosity::quiet) {
        std::cerr << "rig: removed " << cleaned.removed.size() << " Fast DDS shared-memory segment(s) ("
                  << cleaned.bytes_freed / 1024 << " KiB) of participants that were killed, from "
                  << rig::kPosixShmDir.string() << "\n";
    }
    return true;
}

// Progress on standard error: a status line kept up to date on a terminal, a
// line per case elsewhere (a CI log); nothing with --quiet.
std::unique_ptr<rig::harness::RunObserver> progress_observer(rig::harness::Verbosity verbosity, int jobs,
                                                             rig::harness::TerminalProgress*& terminal) {
    using namespace rig::harness;
    terminal = nullptr;
    if (verbosity != Verbosity::quiet && isatty(STDERR_FILENO) != 0) {
        auto progress = std::make_unique<TerminalProgress>(std::cerr, verbosity, jobs, terminal_width(STDERR_FILENO));
        terminal = progress.get();
        return progress;
    }
    return std::make_unique<CaseLineLog>(std::cerr, verbosity);
}

int run_command(const std::vector<std::string>& inputs, const rig::harness::RunOptions& options,
                const std::optional<rig::harness::Shard>& shard, rig::harness::Verbosity verbosity) {
    using namespace rig::harness;
    std::optional<std::vector<CaseSpec>> loaded = load_cases(inputs, options, shard);
    if (!loaded) return 2;
    const std::vector<CaseSpec>& specs = *loaded;
    // An output directory that cannot take results is refused now, not after the cases ran.
    if (!prepare_run(options, verbosity)) return 2;
    // SIGINT / SIGTERM from here on stop the cases, not the rig: the results of
    // what ran are still written (harness/run_interrupt.h).
    install_run_interrupt_handlers();
    const rig::WallStopwatch wall;
    const std::string started_utc = rig::utc_date_time_now();
    TerminalProgress* terminal = nullptr;
    const std::unique_ptr<RunObserver> observer = progress_observer(verbosity, options.jobs, terminal);
    RunPhaseWalls phase_walls;
    const auto runs = run_cases(specs, options, *observer, &phase_walls);
    if (terminal != nullptr) terminal->finish();
    std::vector<CaseResult> results;
    std::vector<CaseFigures> figures;
    for (const CaseRun& run : runs) {
        results.push_back(run.result);
        figures.push_back(run.figures);
    }
    RunSummary summary = summarize(results);
    summary.wall_seconds = wall.elapsed_s();  // with --jobs > 1 cases overlap
    summary.lockstep_wall_seconds = phase_walls.lockstep_seconds;
    summary.realtime_wall_seconds = phase_walls.realtime_seconds;
    summary.started_utc = started_utc;
    // A disk that filled during the run: the table still goes to the terminal,
    // the failure is told, never an abort (harness/output_dir.h).
    std::vector<std::string> report_problems;
    std::string results_problem;
    try {
        report_problems = write_results(options.out_dir, results, summary, figures, HtmlReportOptions{});
    } catch (const std::exception& error) {
        results_problem = error.what();
    }
    if (verbosity == Verbosity::quiet) {
        // What went wrong and the count, nothing else.
        for (const CaseResult& result : results) {
            if (case_passed(result)) continue;
            std::cout << (case_invalid(result) ? "INVALID " : "FAIL ") << result.name << ": "
                      << (result.failures.empty() || case_invalid(result) ? result.error : result.failures.front())
                      << "\n";
        }
        // The table's last line: "N passed, M failed" (and how many were invalid).
        const std::string table = result_table(results, summary, /*color=*/false);
        std::cout << table.substr(table.rfind('\n', table.size() - 2) + 1);
    } else {
        std::cout << result_table(results, summary, colour_wanted(STDOUT_FILENO));
        if (verbosity == Verbosity::verbose) std::cout << result_details(results);
    }
    for (const std::string& problem : report_problems) std::cerr << "rig: report: " << problem << "\n";
    if (!results_problem.empty()) {
        std::cerr << "rig: results not written: " << results_problem << "\n";
        for (const std::string& name : remove_stale_results(options.out_dir)) {
            std::cerr << "rig: removed " << (options.out_dir / name).string()
                      << " of an earlier run, so that it is not taken for this run's\n";
        }
        return kExitResultsNotWritten;
    }
    if (verbosity != Verbosity::quiet) {
        std::cout << "results: " << (options.out_dir / "results.json").string() << ", report: "
                  << (options.out_dir / "report.txt").string() << ", " << (options.out_dir / "report.html").string()
                  << "\n";
    }
    if (const int signal = run_interrupt_signal()) {
        std::cerr << "rig: interrupted by signal " << signal << "; the cases that ran are in the results\n";
        return 128 + signal;
    }
    // 3: nothing failed, but some real-time case could not judge its controller
    // (the rig was overloaded: docs/metrics.md "Verdicts"); run it again.
    if (summary.failed > 0) return 1;
    return summary.invalid > 0 ? 3 : 0;
}

// Forwards to the progress display, and removes each run's trace once it is
// judged unless the sweep keeps it (`--keep-traces`): a sweep of thousands of
// runs keeps numbers, and the traces worth opening.
class SweepTraceKeeper final : public rig::harness::RunObserver {
public:
    SweepTraceKeeper(rig::harness::RunObserver& progress, std::string keep) : progress_(progress), keep_(std::move(keep)) {}
    void runs_planned(const std::vector<rig::harness::CaseInstance>& runs,
                      const std::vector<rig::harness::CaseSpec>& specs) override {
        progress_.runs_planned(runs, specs);
    }
    void case_started(std::size_t index) override { progress_.case_started(index); }
    void case_finished(std::size_t index, const rig::harness::CaseResult& result) override {
        progress_.case_finished(index, result);
        const bool keep = keep_ == "all" || (keep_ == "failed" && !rig::harness::case_passed(result));
        if (keep || result.trace_path.empty()) return;
        std::error_code ignored;
        std::filesystem::remove(result.trace_path, ignored);
    }
    rig::harness::CaseClock* case_clock(std::size_t index) override { return progress_.case_clock(index); }

private:
    rig::harness::RunObserver& progress_;
    std::string keep_;
};

struct SweepArguments {
    std::uint64_t seeds = 0;
    std::uint64_t first_seed = 1;
    std::string keep_traces = "failed";
};

int sweep_command(const std::vector<std::string>& inputs, rig::harness::RunOptions options, const SweepArguments& sweep,
                  rig::harness::Verbosity verbosity) {
    using namespace rig::harness;
    if (sweep.first_seed > std::numeric_limits<std::uint64_t>::max() - (sweep.seeds - 1)) {
        std::cerr << "rig sweep: --first-seed " << sweep.first_seed << " with --seeds " << sweep.seeds
                  << " passes the largest seed (2^64 - 1)\n";
        return 2;
    }
    for (std::uint64_t k = 0; k < sweep.seeds; ++k) options.seed_sweep.push_back(sweep.first_seed + k);
    options.keep_figures = false;
    std::optional<std::vector<CaseSpec>> loaded = load_cases(inputs, options, std::nullopt);
    if (!loaded) return 2;
    const std::vector<CaseSpec>& specs = *loaded;
    for (const CaseSpec& spec : specs) {
        if (spec.mode == RunMode::realtime) {
            std::cerr << "rig sweep: " << spec.source_path.string()
                      << ": a real-time case runs on the wall clock, so " << sweep.seeds
                      << " seeds would take that many times its length; sweep lockstep cases (rig run takes --seed)\n";
            return 2;
        }
    }
    if (!prepare_run(options, verbosity)) return 2;
    install_run_interrupt_handlers();
    const rig::WallStopwatch wall;
    SweepInfo info;
    info.started_utc = rig::utc_date_time_now();
    info.seeds = options.seed_sweep;
    info.keep_traces = sweep.keep_traces;
    info.controller_mode = options.in_process ? "in_process" : "process";
    TerminalProgress* terminal = nullptr;
    const std::unique_ptr<RunObserver> progress = progress_observer(verbosity, options.jobs, terminal);
    SweepTraceKeeper keeper(*progress, sweep.keep_traces);
    const std::vector<CaseRun> runs = run_cases(specs, options, keeper);
    if (terminal != nullptr) terminal->finish();
    std::vector<CaseResult> results;
    bool all_passed = true;
    for (const CaseRun& run : runs) {
        results.push_back(run.result);
        info.sim_seconds += run.result.sim_seconds;
        all_passed = all_passed && case_passed(run.result);
    }
    info.wall_seconds = wall.elapsed_s();
    const std::vector<CaseInstance> instances = expand_runs(specs, options);
    const std::vector<CaseSweep> cases = summarize_sweep(specs, instances, results);
    const std::string table = sweep_table(cases, info);
    try {
        write_file_atomically(options.out_dir / "sweep.json", sweep_json(cases, instances, results, info).dump(1) + "\n");
        write_file_atomically(options.out_dir / "sweep.txt", table);
        write_file_atomically(options.out_dir / "sweep.html", sweep_html(cases, info));
    } catch (const std::exception& error) {
        std::cout << table;
        std::cerr << "rig sweep: results not written: " << error.what() << "\n";
        return kExitResultsNotWritten;
    }
    if (verbosity == Verbosity::quiet) {
        std::cout << table.substr(table.rfind('\n', table.size() - 2) + 1);
    } else {
        std::cout << table << "sweep: " << (options.out_dir / "sweep.json").string() << ", "
                  << (options.out_dir / "sweep.txt").string() << ", " << (options.out_dir / "sweep.html").string() << "\n";
    }
    if (const int signal = run_interrupt_signal()) {
        std::cerr << "rig sweep: interrupted by signal " << signal << "; the runs that ended are in the sweep\n";
        return 128 + signal;
    }
    return all_passed ? 0 : 1;
}

int nmea_decode_command(const std::string& input) {
    if (input == "-") return rig::nmea::decode_stream(std::cin, std::cout);
    return rig::nmea::decode_file(input, std::cout, std::cerr);
}

// Edit distance, for "did you mean" on a mistyped command.
std::size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t above = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diagonal = above;
        }
    }
    return row[b.size()];
}

// A usage error as one line naming the word at fault, then exit status 2 (the
// shell convention for a command used wrongly; CLI11's own codes are 1xx).
// Help and --version are not errors: CLI11 prints them and they exit 0.
int usage_error(const CLI::App& app, const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) return app.exit(error);
    // The command the error is in: the deepest subcommand that was reached.
    const CLI::App* command = &app;
    std::string path = "rig";
    for (bool deeper = true; deeper;) {
        deeper = false;
        for (const CLI::App* sub : command->get_subcommands([](const CLI::App*) { return true; })) {
            if (sub->parsed()) {
                command = sub;
                path += " " + sub->get_name();
                deeper = true;
                break;
            }
        }
    }
    std::vector<std::string> commands;
    for (const CLI::App* sub : command->get_subcommands([](const CLI::App*) { return true; })) {
        if (!sub->get_group().empty()) commands.push_back(sub->get_name());
    }
    std::vector<std::string> extras = app.remaining(/*recurse=*/true);
    std::string message;
    const bool needs_command = !commands.empty() && command->get_require_subcommand_min() > 0 &&
                               dynamic_cast<const CLI::RequiredError*>(&error) != nullptr;
    if (needs_command || dynamic_cast<const CLI::ExtrasError*>(&error) != nullptr) {
        const auto word = std::find_if(extras.begin(), extras.end(), [](const std::string& w) { return !w.empty(); });
        std::string list;
        for (const std::string& name : commands) list += (list.empty() ? "" : ", ") + name;
        if (word == extras.end()) {
            message = "missing command (commands: " + list + ")";
        } else if (word->front() == '-') {
            message = "unknown option '" + *word + "' (" + path + " --help lists the options)";
        } else if (needs_command) {
            std::string suggestion;
            for (const std::string& name : commands) {
                if (edit_distance(*word, name) <= 2) {
                    suggestion = "did you mean '" + name + "'? ";
                    break;
                }
            }
            message = "unknown command '" + *word + "' (" + suggestion + "commands: " + list + ")";
        } else {
            message = "unexpected argument '" + *word + "' (" + path + " --help says what it takes)";
        }
    } else {
        // CLI11's text names the option or argument: "--jobs: Value 99 not in
        // range 1 to 16", "--out: 1 required TEXT missing", "cases is required".
        message = std::string(error.what()) + " (" + path + " --help)";
    }
    std::cerr << path << ": " << message << "\n";
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Sprayer HIL rig: runs timed cases against a controller under test and judges them from truth"};
    app.require_subcommand(1);
    app.set_version_flag("--version",
                         "rig " + std::string(rig::harness::rig_version()) + " (commit " +
                             std::string(rig::harness::rig_commit()) + ")",
                         "print the rig's version and the commit it was built from, and exit");

    rig::harness::RunOptions run_options;
    run_options.controller_executable = own_directory() / "rig-controller";
    // lib/rig/ beside bin/, in the build tree as in an install (controller/CMakeLists.txt).
    run_options.controller_plugin = (own_directory() / RIG_PLUGIN_DIR_FROM_BIN / "rig-controller-plugin.so").lexically_normal();
    std::vector<std::string> case_inputs;
    std::uint64_t seed = 0;
    auto* run = app.add_subcommand("run", "run case files (or directories of them) and judge them");
    run->add_option("cases", case_inputs, "case files or directories")->required();
    run->add_option("--out", run_options.out_dir, "output directory (results.json, junit.xml, report, traces)");
    auto* seed_option = run->add_option("--seed", seed, "override every case's seed")->check(rig::harness::unsigned_decimal_check());
    run->add_option("--jobs", run_options.jobs, "cases run at once, each on its own DDS domain")
        ->check(CLI::Range(1, 16));
    std::uint32_t domain = 0;
    auto* domain_option =
        run->add_option("--domain", domain, "run every case on this DDS domain (one case at a time), e.g. for an observer")
            ->check(CLI::Range(0, 232));
    std::string shard_text;
    auto* shard_option = run->add_option(
        "--shard", shard_text,
        "I/N: run only shard I of N of the cases (by name, stable), e.g. one job of a CI matrix; rig merge joins them");
    run->add_flag("--in-process", run_options.in_process,
                  "software-in-the-loop: run each lockstep case's controller from its plugin inside the rig's process "
                  "(a case's controller.in_process wins; others run as processes, saying why)");
    constexpr const char* kNoPinHelp =
        "leave each lockstep case's threads and its controller process to the scheduler instead of one leased CPU "
        "(README \"Speed\"; for a controller that steps on several threads)";
    run->add_flag("!--no-pin", run_options.pin_cpu, kNoPinHelp);
    bool run_quiet = false;
    bool run_verbose = false;
    bool run_dds_security = false;
    auto* dds_security_flag = run->add_flag(
        "--dds-security", run_dds_security,
        "DDS-Security: PKI-DH authentication, access control and encryption, credentials made for this run in "
        "OUT/security (docs/dds-security.md); controllers run as processes");
    dds_security_flag->excludes("--in-process");
    auto* quiet_flag = run->add_flag("--quiet,-q", run_quiet,
                                     "print only the failed cases and the count: no progress, no table");
    auto* verbose_flag = run->add_flag("--verbose,-v", run_verbose,
                                       "also print each case as it starts, and every case's details after the table");
    quiet_flag->excludes(verbose_flag);

    rig::harness::JudgeCommandOptions judge_options;
    auto* judge = app.add_subcommand(
        "judge", "judge recorded traces again (a run's --out directory, or trace files): same results contract");
    judge->add_option("runs_or_traces", judge_options.inputs, "rig run --out directories or trace.sqlite files")->required();
    judge->add_option("--out", judge_options.out_dir, "write results.json, junit.xml and the reports here");
    judge->add_flag("--check", judge_options.check,
                    "compare with each directory's results.json: metrics, verdicts and digests must be the same");

    rig::harness::MergeCommandOptions merge_options;
    auto* merge = app.add_subcommand(
        "merge", "join the outputs of rig run --shard I/N into one run directory (results.json, junit.xml, reports)");
    merge->add_option("shard_outs", merge_options.shard_dirs, "the shards' rig run --out directories")->required();
    merge->add_option("--out", merge_options.out_dir, "the merged run directory (new or empty)")->required();

    rig::harness::RunOptions sweep_options = run_options;
    sweep_options.out_dir = "rig-sweep";
    std::vector<std::string> sweep_inputs;
    SweepArguments sweep_arguments;
    auto* sweep = app.add_subcommand(
        "sweep", "run lockstep cases over many seeds: every metric's p5 / p50 / p95 / max against its limit and the paper");
    sweep->add_option("cases", sweep_inputs, "lockstep case files or directories")->required();
    sweep->add_option("--seeds", sweep_arguments.seeds, "seeds per case (1 .. 100000)")
        ->required()
        ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{100000}));
    sweep->add_option("--first-seed", sweep_arguments.first_seed, "the first seed (default 1); seeds run N, N+1, ...")
        ->check(rig::harness::unsigned_decimal_check());
    sweep->add_option("--keep-traces", sweep_arguments.keep_traces,
                      "which runs keep their trace: failed (default), all or none")
        ->check(CLI::IsMember({"failed", "all", "none"}));
    sweep->add_option("--out", sweep_options.out_dir, "output directory (sweep.json, sweep.txt, sweep.html, runs)");
    sweep->add_option("--jobs", sweep_options.jobs, "runs at once, each on its own DDS domain")->check(CLI::Range(1, 16));
    sweep->add_flag("--in-process", sweep_options.in_process,
                    "software-in-the-loop, as rig run --in-process (same digests, several times faster)");
    sweep->add_flag("!--no-pin", sweep_options.pin_cpu, kNoPinHelp);
    bool sweep_quiet = false;
    sweep->add_flag("--quiet,-q", sweep_quiet, "print only the summary line: no progress, no table");

    auto* nmea = app.add_subcommand("nmea", "NMEA tools");
    nmea->require_subcommand(1);
    std::string nmea_input;
    auto* decode = nmea->add_subcommand("decode", "decode NMEA lines with the controller's parser, one JSON per line");
    decode->add_option("input", nmea_input, "file, or - for standard input")->required();

    // Bench wire adapters: `rig pty`, `rig hid list` (harness/bench_serial.h, harness/bench_hid.h).
    const rig::harness::PtyBenchCommand pty_bench(app);
    const rig::harness::HidBenchCommand hid_bench(app);
    const rig::harness::EmulateBenchCommand emulate_bench(app);
    const rig::harness::McapCommand mcap_command(app);

    rig::DdsCheckOptions check_options;
    check_options.echo_executable = own_directory() / "rig";
    check_options.log_dir = std::filesystem::temp_directory_path();
    bool check_echo = false;
    std::uint32_t check_domain = 0;
    auto* check = app.add_subcommand(
        "dds-check", "bench self-test: ping/pong with a second process over the loopback DDS profile");
    check->add_option("--samples", check_options.samples, "round trips")->check(CLI::Range(1, 100000));
    check->add_option("--log-dir", check_options.log_dir, "where the echo process writes its log");
    check->add_flag("--echo", check_echo, "internal: be the echo side")->group("");
    check->add_option("--domain", check_domain, "internal: the echo side's domain")->group("");

    rig::harness::SpeedBenchOptions bench_options;
    bool bench_pong = false;
    std::uint32_t bench_domain = 0;
    auto* bench = app.add_subcommand(
        "bench", "what lockstep costs: runs cases in process and in-process (SIL) mode beside a DDS ping-pong floor");
    bench->add_option("cases", bench_options.cases, "lockstep case files");
    bench->add_option("--repeat", bench_options.repeat, "runs per case and mode")->check(CLI::Range(1, 1000));
    bench->add_option("--pingpong-rounds", bench_options.pingpong.rounds, "timed DDS round trips")
        ->check(CLI::Range(10, 1000000));
    bench->add_option("--out", bench_options.out_dir, "traces and bench.json");
    bench->add_flag("--dds-security", bench_options.dds_security,
                    "also process mode and the ping-pong with DDS-Security (credentials in OUT/security)");
    bench->add_flag("--pong", bench_pong, "internal: be the ping-pong's second process")->group("");
    bench->add_option("--domain", bench_domain, "internal: the second process's domain")->group("");

    rig::harness::ModbusServeOptions modbus_serve_options;
    auto* modbus = app.add_subcommand("modbus", "Modbus bench wire tools");
    modbus->require_subcommand(1);
    auto* modbus_serve = rig::harness::add_modbus_serve_subcommand(*modbus, modbus_serve_options);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        return usage_error(app, error);
    }
    // Only --dds-security secures the rig's participants: RIG_DDS_SECURITY_DIR
    // is the controller's contract, read here by the bench's second process alone.
    if (!(bench->parsed() && bench_pong)) rig::use_dds_security_identity(std::filesystem::path());
    if (pty_bench.parsed()) return pty_bench.run();
    if (hid_bench.parsed()) return hid_bench.run();
    if (emulate_bench.parsed()) return emulate_bench.run();
    if (mcap_command.parsed()) return mcap_command.run();
    if (run->parsed()) {
        if (seed_option->count() > 0) run_options.seed_override = seed;
        if (run_dds_security) run_options.dds_security_dir = run_options.out_dir / "security";
        if (domain_option->count() > 0) {
            if (run_options.jobs > 1) {
                std::cerr << "rig run: --domain " << domain << " puts every case on one domain: use it with --jobs 1\n";
                return 2;
            }
            run_options.domain = domain;
        }
        std::optional<rig::harness::Shard> shard;
        if (shard_option->count() > 0) {
            try {
                shard = rig::harness::parse_shard(shard_text);
            } catch (const std::invalid_argument& error) {
                std::cerr << "rig run: " << error.what() << "\n";
                return 2;
            }
        }
        const auto verbosity = run_quiet     ? rig::harness::Verbosity::quiet
                               : run_verbose ? rig::harness::Verbosity::verbose
                                             : rig::harness::Verbosity::normal;
        return run_command(case_inputs, run_options, shard, verbosity);
    }
    if (sweep->parsed()) {
        return sweep_command(sweep_inputs, sweep_options, sweep_arguments,
                             sweep_quiet ? rig::harness::Verbosity::quiet : rig::harness::Verbosity::normal);
    }
    if (judge->parsed()) return rig::harness::run_judge_command(judge_options, std::cout, std::cerr);
    if (merge->parsed()) return rig::harness::run_merge_command(merge_options, std::cout, std::cerr);
    if (decode->parsed()) return nmea_decode_command(nmea_input);
    if (modbus_serve->parsed()) return rig::harness::run_modbus_serve_command(modbus_serve_options);
    if (bench->parsed()) {
        try {
            if (bench_pong) return rig::run_dds_pong(bench_domain, bench_options.pingpong.rounds);
            bench_options.run = run_options;
            bench_options.pingpong.pong_executable = own_directory() / "rig";
            bench_options.pingpong.log_dir = bench_options.out_dir;
            return rig::harness::run_speed_bench(bench_options, std::cout, std::cerr);
        } catch (const std::exception& error) {
            std::cerr << "rig bench: " << error.what() << "\n";
            return 1;
        }
    }
    if (check->parsed()) {
        try {
            if (check_echo) return rig::run_dds_echo(check_domain, check_options.samples, std::cout);
            return rig::run_dds_check(check_options, std::cout);
        } catch (const std::exception& error) {
            std::cerr << "rig dds-check: " << error.what() << "\n";
            return 1;
        }
    }
    return 2;
}
