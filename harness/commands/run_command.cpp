#include "harness/commands/run_command.h"

#include <CLI/CLI.hpp>
#include <unistd.h>

#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>

#include "harness/cli/cli_checks.h"
#include "harness/judge/verdict.h"
#include "harness/output/atomic_file.h"
#include "harness/regression/bencher_format.h"
#include "harness/regression/run_samples.h"
#include "harness/report/html_report.h"
#include "harness/report/results_writer.h"
#include "harness/report/sweep.h"
#include "harness/report/sweep_shard.h"
#include "harness/run/output_dir.h"
#include "harness/run/run_interrupt.h"
#include "harness/run/run_progress.h"
#include "harness/run/shard.h"
#include "harness/session/dds_security_setup.h"
#include "harness/systems/systems.h"
#include "rig/host/shm_cleanup.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/dds_security.h"

namespace rig::harness {

const char* const kNoPinHelp =
    "leave each lockstep case's threads and its controller process to the scheduler instead of one leased CPU "
    "(docs/speed.md; for a controller that steps on several threads)";

std::filesystem::path own_directory() {
    std::error_code error;
    const auto self = std::filesystem::read_symlink("/proc/self/exe", error);
    return error ? std::filesystem::current_path() : self.parent_path();
}

RunOptions default_run_options() {
    RunOptions options;
    options.controller_dir = own_directory();
    // lib/rig/ beside bin/, in the build tree as in an install (controller/CMakeLists.txt).
    options.plugin_dir = (own_directory() / RIG_PLUGIN_DIR_FROM_BIN).lexically_normal();
    return options;
}

void add_setting_option(CLI::App& command, std::vector<std::string>& setting_texts) {
    command.add_option("--set", setting_texts,
                       "KEY=VALUE: replace the value the case file writes at KEY (e.g. vehicle.speed_km_h=9, "
                       "gnss.dropouts[0].at_s=3), checked against the key's bounds like the file's own; repeatable")
        ->allow_extra_args(false);
}

std::optional<std::vector<KeySetting>> parse_setting_texts(const std::vector<std::string>& texts,
                                                           const std::string& command) {
    std::vector<KeySetting> settings;
    for (const std::string& text : texts) {
        try {
            settings.push_back(parse_key_setting(text));
        } catch (const std::invalid_argument& error) {
            std::cerr << command << ": --set " << error.what() << "\n";
            return std::nullopt;
        }
    }
    return settings;
}

namespace {

// What a shard of a run or a sweep holds, said on standard error before it runs.
void say_shard(const std::string& command, const Shard& shard, std::size_t held, std::size_t all,
               const std::string& what) {
    std::cerr << command << ": shard " << shard.index << "/" << shard.count << ": " << held << " of " << all << " "
              << what << " (join the shards' outputs with rig merge)\n";
}

// Every case file read and validated before anything starts (the errors go to
// standard error, and nothing is run: nullopt).
std::optional<std::vector<CaseSpec>> load_cases(const std::vector<std::string>& inputs,
                                                const std::vector<KeySetting>& settings, const RunOptions& options,
                                                const std::optional<Shard>& shard) {
    std::vector<CaseSpec> specs;
    try {
        // Every file is read and validated before anything starts.
        std::vector<std::string> errors;
        for (const auto& path : expand_case_paths(inputs)) {
            try {
                specs.push_back(load_case_file(path, settings));
                validate_for_run(specs.back(), options);
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
            say_shard("rig", *shard, specs.size(), all, "cases");
        }
    } catch (const std::exception& error) {
        std::cerr << "rig: " << error.what() << "\n";
        return std::nullopt;
    }
    return specs;
}

// --shard's value (nullopt without it); false after saying on standard error
// what is wrong with it.
bool shard_option_value(const CLI::Option* option, const std::string& text, const std::string& command,
                        std::optional<Shard>& shard) {
    if (option->count() == 0) return true;
    try {
        shard = parse_shard(text);
        return true;
    } catch (const std::invalid_argument& error) {
        std::cerr << command << ": " << error.what() << "\n";
        return false;
    }
}

// Refuses an output directory that cannot take results (before any case runs),
// makes the run's DDS-Security credentials if asked, then removes what killed
// participants of earlier runs left in /dev/shm.
bool prepare_run(const RunOptions& options, Verbosity verbosity) {
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
        !cleaned.removed.empty() && verbosity != Verbosity::quiet) {
        std::cerr << "rig: removed " << cleaned.removed.size() << " Fast DDS shared-memory segment(s) ("
                  << cleaned.bytes_freed / 1024 << " KiB) of participants that were killed, from "
                  << rig::kPosixShmDir.string() << "\n";
    }
    return true;
}

// Progress on standard error: a status line kept up to date on a terminal, a
// line per case elsewhere (a CI log); nothing with --quiet.
std::unique_ptr<RunObserver> progress_observer(Verbosity verbosity, int jobs,
                                                             TerminalProgress*& terminal) {
    terminal = nullptr;
    if (verbosity != Verbosity::quiet && isatty(STDERR_FILENO) != 0) {
        auto progress = std::make_unique<TerminalProgress>(std::cerr, verbosity, jobs, terminal_width(STDERR_FILENO));
        terminal = progress.get();
        return progress;
    }
    return std::make_unique<CaseLineLog>(std::cerr, verbosity);
}

// `--bmf FILE`: the metrics just written, in Bencher's format as well
// (harness/regression/bencher_format.h); false (told) when it cannot be written.
bool write_bencher_file(const std::string& command, const std::string& bmf_file, const nlohmann::json& written,
                        const std::string& kind, const std::filesystem::path& source) {
    if (bmf_file.empty()) return true;
    try {
        write_file_atomically(bmf_file, bencher_metric_format(run_samples_from_json(written, kind, source)).dump(1) + "\n");
        return true;
    } catch (const std::exception& error) {
        std::cerr << "rig " << command << ": --bmf " << bmf_file << " not written: " << error.what() << "\n";
        return false;
    }
}

int run_command(const std::vector<std::string>& inputs, const std::vector<KeySetting>& settings,
                const RunOptions& options, const std::optional<Shard>& shard, Verbosity verbosity,
                const std::string& bmf_file) {
    std::optional<std::vector<CaseSpec>> loaded = load_cases(inputs, settings, options, shard);
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
    if (results_problem.empty() &&
        !write_bencher_file("run", bmf_file, results_json(results, summary), "run", options.out_dir / "results.json")) {
        results_problem = "--bmf " + bmf_file + " could not be written";
    }
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
class SweepTraceKeeper final : public RunObserver {
public:
    SweepTraceKeeper(RunObserver& progress, std::string keep) : progress_(progress), keep_(std::move(keep)) {}
    void runs_planned(const std::vector<CaseInstance>& runs,
                      const std::vector<CaseSpec>& specs) override {
        progress_.runs_planned(runs, specs);
    }
    void case_started(std::size_t index) override { progress_.case_started(index); }
    void case_finished(std::size_t index, const CaseResult& result) override {
        progress_.case_finished(index, result);
        const bool keep = keep_ == "all" || (keep_ == "failed" && !case_passed(result));
        if (keep || result.trace_path.empty()) return;
        std::error_code ignored;
        std::filesystem::remove(result.trace_path, ignored);
    }
    CaseClock* case_clock(std::size_t index) override { return progress_.case_clock(index); }

private:
    RunObserver& progress_;
    std::string keep_;
};

struct SweepArguments {
    std::vector<KeySetting> settings;
    std::uint64_t seeds = 0;
    std::uint64_t first_seed = 1;
    std::string keep_traces = "failed";
    std::string bmf_file;
    std::optional<Shard> shard;
};


int sweep_command(const std::vector<std::string>& inputs, RunOptions options, const SweepArguments& sweep,
                  Verbosity verbosity) {
    if (sweep.first_seed > std::numeric_limits<std::uint64_t>::max() - (sweep.seeds - 1)) {
        std::cerr << "rig sweep: --first-seed " << sweep.first_seed << " with --seeds " << sweep.seeds
                  << " passes the largest seed (2^64 - 1)\n";
        return 2;
    }
    for (std::uint64_t k = 0; k < sweep.seeds; ++k) options.seed_sweep.push_back(sweep.first_seed + k);
    options.keep_figures = false;
    std::optional<std::vector<CaseSpec>> loaded = load_cases(inputs, sweep.settings, options, std::nullopt);
    if (!loaded) return 2;
    const std::vector<CaseSpec>& specs = *loaded;
    // Every case file was checked above, whichever shard its runs are in.
    options.sweep_shard = sweep.shard;
    for (const CaseSpec& spec : specs) {
        if (spec.mode == ClockMode::realtime) {
            std::cerr << "rig sweep: " << spec.source_path.string()
                      << ": a real-time case runs on the wall clock, so " << sweep.seeds
                      << " seeds would take that many times its length; sweep lockstep cases (rig run takes --seed)\n";
            return 2;
        }
    }
    if (!prepare_run(options, verbosity)) return 2;
    const std::size_t runs_in_sweep = specs.size() * options.seed_sweep.size();
    if (sweep.shard) say_shard("rig sweep", *sweep.shard, expand_runs(specs, options).size(), runs_in_sweep, "runs");
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
    nlohmann::json json = sweep_json(cases, instances, results, info);
    if (sweep.shard) json["shard"] = sweep_shard_json(*sweep.shard, specs, runs_in_sweep, instances, results);
    try {
        write_sweep_files(options.out_dir, json, cases, info);
        if (!write_bencher_file("sweep", sweep.bmf_file, json, "sweep", options.out_dir / "sweep.json")) {
            return kExitResultsNotWritten;
        }
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

}  // namespace

RunCommand::RunCommand(CLI::App& app) : options_(default_run_options()) {
    command_ = app.add_subcommand("run", "run case files (or directories of them) and judge them");
    CLI::App* run = command_;
    run->add_option("cases", inputs_, "case files or directories")->required();
    run->add_option("--out", options_.out_dir, "output directory (results.json, junit.xml, report, traces)");
    seed_option_ = run->add_option("--seed", seed_, "override every case's seed")->check(unsigned_decimal_check());
    run->add_option("--jobs", options_.jobs, "cases run at once, each on its own DDS domain")->check(CLI::Range(1, 16));
    domain_option_ =
        run->add_option("--domain", domain_, "run every case on this DDS domain (one case at a time), e.g. for an observer")
            ->check(CLI::Range(0, 232));
    shard_option_ = run->add_option(
        "--shard", shard_text_,
        "I/N: run only shard I of N of the cases (by name, stable), e.g. one job of a CI matrix; rig merge joins them");
    run->add_option("--bmf", bmf_file_, "also write every case's metrics in Bencher's JSON format to this file");
    add_setting_option(*run, setting_texts_);
    run->add_flag("--in-process", options_.in_process,
                  "software-in-the-loop: run each lockstep case's controller from its plugin inside the rig's process "
                  "(a case's controller.in_process wins; others run as processes, saying why)");
    run->add_flag("!--no-pin", options_.pin_cpu, kNoPinHelp);
    auto* dds_security_flag = run->add_flag(
        "--dds-security", dds_security_,
        "DDS-Security: PKI-DH authentication, access control and encryption, credentials made for this run in "
        "OUT/security (docs/dds-security.md); controllers run as processes");
    dds_security_flag->excludes("--in-process");
    auto* quiet_flag =
        run->add_flag("--quiet,-q", quiet_, "print only the failed cases and the count: no progress, no table");
    auto* verbose_flag = run->add_flag("--verbose,-v", verbose_,
                                       "also print each case as it starts, and every case's details after the table");
    quiet_flag->excludes(verbose_flag);
}

bool RunCommand::parsed() const { return command_->parsed(); }

int RunCommand::run() {
    RunOptions options = options_;
    if (seed_option_->count() > 0) options.seed_override = seed_;
    if (dds_security_) options.dds_security_dir = options.out_dir / "security";
    if (domain_option_->count() > 0) {
        if (options.jobs > 1) {
            std::cerr << "rig run: --domain " << domain_ << " puts every case on one domain: use it with --jobs 1\n";
            return 2;
        }
        options.domain = domain_;
    }
    std::optional<Shard> shard;
    if (!shard_option_value(shard_option_, shard_text_, "rig run", shard)) return 2;
    const std::optional<std::vector<KeySetting>> settings = parse_setting_texts(setting_texts_, "rig run");
    if (!settings) return 2;
    const auto verbosity = quiet_ ? Verbosity::quiet : verbose_ ? Verbosity::verbose : Verbosity::normal;
    return run_command(inputs_, *settings, options, shard, verbosity, bmf_file_);
}

SweepCommand::SweepCommand(CLI::App& app) : options_(default_run_options()) {
    options_.out_dir = "rig-sweep";
    command_ = app.add_subcommand(
        "sweep", "run lockstep cases over many seeds: every metric's p5 / p50 / p95 / max against its limit and the paper");
    CLI::App* sweep = command_;
    sweep->add_option("cases", inputs_, "lockstep case files or directories")->required();
    sweep->add_option("--seeds", seeds_, "seeds per case (1 .. 100000)")
        ->required()
        ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{100000}));
    sweep->add_option("--first-seed", first_seed_, "the first seed (default 1); seeds run N, N+1, ...")
        ->check(unsigned_decimal_check());
    sweep->add_option("--keep-traces", keep_traces_, "which runs keep their trace: failed (default), all or none")
        ->check(CLI::IsMember({"failed", "all", "none"}));
    sweep->add_option("--out", options_.out_dir, "output directory (sweep.json, sweep.txt, sweep.html, runs)");
    sweep->add_option("--jobs", options_.jobs, "runs at once, each on its own DDS domain")->check(CLI::Range(1, 16));
    sweep->add_flag("--in-process", options_.in_process,
                    "software-in-the-loop, as rig run --in-process (same digests, several times faster)");
    sweep->add_flag("!--no-pin", options_.pin_cpu, kNoPinHelp);
    shard_option_ = sweep->add_option("--shard", shard_text_,
                                      "I/N: run only shard I of N of the sweep's runs (case and seed pairs, dealt in "
                                      "turn), e.g. one job of a CI matrix; rig merge joins them");
    sweep->add_flag("--quiet,-q", quiet_, "print only the summary line: no progress, no table");
    sweep->add_option("--bmf", bmf_file_, "also write every case's metrics (median, min, max) in Bencher's JSON format to this file");
    add_setting_option(*sweep, setting_texts_);
}

bool SweepCommand::parsed() const { return command_->parsed(); }

int SweepCommand::run() {
    const std::optional<std::vector<KeySetting>> settings = parse_setting_texts(setting_texts_, "rig sweep");
    if (!settings) return 2;
    SweepArguments sweep{*settings, seeds_, first_seed_, keep_traces_, bmf_file_, std::nullopt};
    if (!shard_option_value(shard_option_, shard_text_, "rig sweep", sweep.shard)) return 2;
    return sweep_command(inputs_, options_, sweep, quiet_ ? Verbosity::quiet : Verbosity::normal);
}

}  // namespace rig::harness
