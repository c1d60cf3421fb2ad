#include "harness/commands/history_command.h"

#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <system_error>

#include "harness/output/atomic_file.h"
#include "harness/regression/history_report.h"
#include "harness/regression/history_store.h"
#include "harness/regression/run_samples.h"

namespace rig::harness {

namespace fs = std::filesystem;

int run_history_add(const HistoryAddOptions& options, std::ostream& out, std::ostream& err) {
    RunSamples samples;
    try {
        samples = load_run_samples(options.results);
    } catch (const std::exception& error) {
        err << "rig history add: " << error.what() << "\n";
        return 2;
    }
    HistoryEntryOptions entry;
    entry.commit = options.commit;
    entry.branch = options.branch;
    entry.order = options.order;
    entry.date = options.date;
    entry.replace = options.replace;
    try {
        const HistoryAdded added = add_to_history(options.database, samples, entry);
        out << (added.replaced ? "replaced" : "added") << " commit " << options.commit << " on branch " << options.branch
            << " (order " << added.order << (added.date.empty() ? "" : ", " + added.date) << ") in "
            << options.database << (added.created ? " (new)" : "") << ": " << added.cases << " case"
            << (added.cases == 1 ? "" : "s") << ", " << added.runs << " run" << (added.runs == 1 ? "" : "s") << ", "
            << added.values << " values, from " << samples.source.string() << "\n";
        return 0;
    } catch (const HistoryNotAdded& error) {
        err << "rig history add: " << error.what() << " (nothing was added)\n";
        return 1;
    } catch (const std::exception& error) {
        err << "rig history add: " << error.what() << "\n";
        return 2;
    }
}

int run_history_report(const HistoryReportOptions& options, std::ostream& out, std::ostream& err) {
    History history;
    try {
        history = read_history(options.database);
    } catch (const std::exception& error) {
        err << "rig history report: " << error.what() << "\n";
        return 2;
    }
    const fs::path out_dir(options.out_dir);
    std::error_code error_code;
    if (fs::exists(out_dir, error_code) && !fs::is_directory(out_dir, error_code)) {
        err << "rig history report: --out " << out_dir.string() << " is a file, not a directory\n";
        return 2;
    }
    try {
        const std::vector<AnalysedBranch> analysed = analyse_history(history, options.change_points);
        const std::string json = history_json(history, analysed, options.change_points).dump(1) + "\n";
        const std::string html = history_html(history, analysed, options.change_points);
        fs::create_directories(out_dir);
        write_file_atomically(out_dir / "history.json", json);
        write_file_atomically(out_dir / "history.html", html);
        std::size_t series = 0, change_points = 0, worse = 0;
        for (const AnalysedBranch& branch : analysed) {
            for (const AnalysedSeries& one : branch.series) {
                ++series;
                change_points += one.judged.change_points.size();
                for (const ChangePoint& change : one.judged.change_points) worse += change.worse ? 1 : 0;
            }
        }
        out << (out_dir / "history.html").string() << ", " << (out_dir / "history.json").string() << ": "
            << history.branches.size() << " branch" << (history.branches.size() == 1 ? "" : "es") << ", " << series
            << " series, " << change_points << " change point" << (change_points == 1 ? "" : "s") << " (" << worse
            << " for the worse)\n";
        return 0;
    } catch (const std::exception& error) {
        err << "rig history report: " << error.what() << "\n";
        return 1;
    }
}

int run_history_check(const HistoryCheckOptions& options, std::ostream& out, std::ostream& err) {
    try {
        const History history = read_history(options.database);
        const HistoryCheck check = check_history(history, options.branch, options.change_points);
        out << history_check_text(check);
        return check.worse.empty() ? 0 : 1;
    } catch (const std::exception& error) {
        err << "rig history check: " << error.what() << "\n";
        return 2;
    }
}

namespace {

void add_change_point_options(CLI::App* command, ChangePointOptions& options) {
    command->add_option("--alpha", options.alpha,
                        "the chance that a series of noise alone shows a change point (default 0.01)")
        ->check(CLI::Range(0.0001, 0.5));
    command->add_option("--permutations", options.permutations,
                        "permutations of the change-point test at most (default 999)")
        ->check(CLI::Range(99, 99999));
}

}  // namespace

HistoryCommand::HistoryCommand(CLI::App& app) {
    command_ = app.add_subcommand("history", "a controller's metrics over its commits: add runs, report, check for a step");
    command_->require_subcommand(1);

    add_ = command_->add_subcommand("add", "add a rig run or rig sweep output as a commit's entry in the history");
    add_->add_option("results", add_options_.results, "results.json, sweep.json or the directory holding one")->required();
    add_->add_option("--commit", add_options_.commit, "the commit the runs were of (hex)")->required();
    add_->add_option("--branch", add_options_.branch, "the branch (default main)");
    add_->add_option("--order", order_, "the commit's place on the branch (default: after the newest; e.g. git rev-list --count HEAD)")
        ->check(CLI::NonNegativeNumber);
    add_->add_option("--date", add_options_.date, "the commit's date, ISO 8601 (default: the output's started_utc)");
    add_->add_flag("--replace", add_options_.replace, "replace the commit's entry when the branch has it");
    add_->add_option("--db", add_options_.database, "the history database (SQLite; made when missing)")->required();

    report_ = command_->add_subcommand("report", "write history.html and history.json: every series and its change points");
    report_->add_option("--db", report_options_.database, "the history database")->required();
    report_->add_option("--out", report_options_.out_dir, "the directory to write them in (made when missing)")->required();
    add_change_point_options(report_, report_options_.change_points);

    check_ = command_->add_subcommand("check", "exit 1 when the newest commit is a change point for the worse");
    check_->add_option("--db", check_options_.database, "the history database")->required();
    check_->add_option("--branch", check_options_.branch, "the branch (default: the branch added to last)");
    add_change_point_options(check_, check_options_.change_points);
}

bool HistoryCommand::parsed() const { return command_->parsed(); }

int HistoryCommand::run() {
    if (add_->parsed()) {
        if (order_ >= 0) add_options_.order = order_;
        return run_history_add(add_options_, std::cout, std::cerr);
    }
    if (report_->parsed()) return run_history_report(report_options_, std::cout, std::cerr);
    if (check_->parsed()) return run_history_check(check_options_, std::cout, std::cerr);
    return 2;
}

}  // namespace rig::harness
