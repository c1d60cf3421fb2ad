#include "harness/commands/falsify_command.h"

#include <CLI/CLI.hpp>

#include <iostream>
#include <optional>

#include "harness/cli/cli_checks.h"
#include "harness/commands/run_command.h"
#include "harness/falsify/falsify_report.h"
#include "harness/falsify/falsify_setup.h"
#include "harness/output/atomic_file.h"
#include "harness/run/output_dir.h"
#include "harness/run/run_interrupt.h"
#include "rig/runtime/clock.h"
#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

// A line per point on standard error as the search goes (none with --quiet).
class PointLog final : public PointEvaluator {
public:
    PointLog(CaseEvaluator& evaluator, const std::vector<VaryRange>& ranges, bool quiet)
        : evaluator_(evaluator), ranges_(ranges), quiet_(quiet) {}
    std::vector<RunMargin> evaluate(const std::vector<std::vector<double>>& points) override {
        const std::vector<RunMargin> margins = evaluator_.evaluate(points);
        for (std::size_t index = 0; index < points.size() && !quiet_; ++index) {
            std::string line = "rig falsify: point " + std::to_string(++count_) + ":";
            for (std::size_t key = 0; key < ranges_.size(); ++key) {
                line += " " + ranges_[key].key + "=" + value_text(ranges_[key], points[index][key]);
            }
            const RunMargin& margin = margins[index];
            line += margin.margin          ? " margin " + significant_text(*margin.margin, 4) + " (" + margin.limiting_metric + ")"
                    : !margin.broken.empty() ? " broken: " + margin.broken
                                             : " invalid: " + margin.invalid;
            std::cerr << line << (margin.invalid.empty() && margin.falsifying() ? "  FALSIFYING" : "") << "\n";
        }
        return margins;
    }
    bool stopped() const override { return evaluator_.stopped(); }

private:
    CaseEvaluator& evaluator_;
    const std::vector<VaryRange>& ranges_;
    bool quiet_;
    std::size_t count_ = 0;
};

}  // namespace

FalsifyCommand::FalsifyCommand(CLI::App& app) : options_(default_run_options()) {
    command_ = app.add_subcommand(
        "falsify", "search a case's parameters for the point with the smallest margin to a limit (docs/falsify.md)");
    CLI::App* falsify = command_;
    falsify->add_option("case", input_, "the base case file, or a NAME.search.yaml file describing the search")
        ->required();
    falsify->add_option("--vary", vary_texts_, "KEY=LO:HI (a numeric key of the case file and its range) or KEY=A,B,... "
                                         "(a key and its choices); repeatable")
        ->allow_extra_args(false);
    falsify->add_option("--metric", metrics_, "a limited metric to judge (default: every limited metric); repeatable")
        ->allow_extra_args(false);
    add_setting_option(*falsify, setting_texts_);
    budget_option_ = falsify->add_option("--budget", budget_, "points evaluated at most (default 60)")
                         ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{100000}));
    seeds_option_ = falsify->add_option("--seeds", seeds_,
                                        "seeds per point, from the case's own on; a point's margin is its worst "
                                        "(default: the case's own seed, or its seeds: list)")
                        ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1000}));
    method_option_ = falsify->add_option("--method", method_, "crs2 (default), direct, isres, or random (the baseline)")
                         ->check(CLI::IsMember({"crs2", "direct", "isres", "random"}));
    start_option_ = falsify->add_option("--start", start_,
                                        "points of the Latin hypercube start design (default: 2 per key + 1, at least "
                                        "--jobs, at most a third of the budget)")
                        ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{100000}));
    search_seed_option_ =
        falsify->add_option("--search-seed", search_seed_, "seed of the search's own random numbers (default 1)")
            ->check(unsigned_decimal_check());
    falsify->add_flag("--first", first_, "stop at the first falsifying point");
    falsify->add_option("--jobs", options_.jobs, "runs at once, each on its own DDS domain")->check(CLI::Range(1, 16));
    falsify->add_flag("--in-process", options_.in_process,
                      "software-in-the-loop, as rig run --in-process (same digests, several times faster)");
    falsify->add_flag("!--no-pin", options_.pin_cpu, kNoPinHelp);
    falsify->add_flag("--quiet,-q", quiet_, "print only the summary line");
    falsify->add_option("--out", out_dir_, "output directory (falsify.json, worst.yaml, falsify.html, runs/)")
        ->required();
}

bool FalsifyCommand::parsed() const { return command_->parsed(); }

int FalsifyCommand::run() {
    FalsifyRequest request;
    try {
        if (is_search_file(input_)) {
            if (!vary_texts_.empty() || !setting_texts_.empty()) {
                std::cerr << "rig falsify: " << input_ << " is a search file: its vary and set are the search's "
                          << "(edit the file, or give the case with --vary)\n";
                return 2;
            }
            request = read_search_file(input_);
        } else {
            request.case_file = input_;
            for (const std::string& text : vary_texts_) request.ranges.push_back(parse_vary(text));
            const std::optional<std::vector<KeySetting>> settings = parse_setting_texts(setting_texts_, "rig falsify");
            if (!settings) return 2;
            request.settings = *settings;
        }
    } catch (const std::invalid_argument& error) {
        std::cerr << "rig falsify: --vary " << error.what() << "\n";
        return 2;
    } catch (const std::exception& error) {
        std::cerr << "rig falsify: " << error.what() << "\n";
        return 2;
    }
    // The command line wins over the search file.
    if (!metrics_.empty()) request.metrics = metrics_;
    if (budget_option_->count() > 0) request.options.budget = budget_;
    if (seeds_option_->count() > 0) request.seeds = seeds_;
    if (method_option_->count() > 0) request.options.method = *search_method_named(method_);
    if (start_option_->count() > 0) request.options.start_points = start_;
    if (search_seed_option_->count() > 0) request.options.seed = search_seed_;
    if (first_) request.options.stop_at_first = true;
    request.options.batch = static_cast<std::size_t>(options_.jobs);

    const std::filesystem::path out_dir = out_dir_;
    RunOptions options = options_;
    options.out_dir = out_dir / "runs";
    PreparedSearch prepared;
    try {
        prepared = prepare_search(request, options);
    } catch (const std::exception& error) {
        std::cerr << "rig falsify: " << error.what() << "; nothing was run\n";
        return 2;
    }
    try {
        // DIR/runs/ (DIR made with it) takes the runs; DIR itself the outputs.
        prepare_output_directory(options.out_dir);
    } catch (const OutputDirError& error) {
        std::cerr << "rig falsify: " << error.what() << "; nothing was run\n";
        return 2;
    }
    install_run_interrupt_handlers();
    const rig::WallStopwatch wall;
    CaseEvaluator evaluator(prepared.search_case, options, prepared.base.name);
    PointLog log(evaluator, prepared.search_case.ranges, quiet_);
    FalsifyRecord record;
    try {
        record.outcome = falsify_search(prepared.search_case.ranges, request.options, log);
    } catch (const std::exception& error) {
        std::cerr << "rig falsify: the search stopped: " << error.what() << "\n";
        return 2;
    }
    record.search_case = prepared.search_case;
    record.base_text = prepared.base_text;
    record.search_file = request.search_file;
    record.options = request.options;
    record.point_runs = evaluator.points();
    record.case_seed = prepared.base.seed;
    record.case_has_seed_list = !prepared.base.seeds.empty();
    try {
        (void)written_value(prepared.base_text, request.case_file.string(), "seed");
        record.case_writes_seed = true;
    } catch (const ConfigError&) {
        record.case_writes_seed = false;
    }
    record.wall_seconds = wall.elapsed_s();
    const std::string summary = falsify_summary(record, out_dir);
    try {
        write_file_atomically(out_dir / "falsify.json", falsify_json(record).dump(1) + "\n");
        const std::string worst = worst_case_text(record);
        if (!worst.empty()) write_file_atomically(out_dir / "worst.yaml", worst);
        std::vector<std::string> problems;
        write_file_atomically(out_dir / "falsify.html", falsify_html(record, problems));
        for (const std::string& problem : problems) std::cerr << "rig falsify: falsify.html: " << problem << "\n";
    } catch (const std::exception& error) {
        std::cout << summary << "\n";
        std::cerr << "rig falsify: outputs not written: " << error.what() << "\n";
        return kExitResultsNotWritten;
    }
    std::cout << summary << "\n";
    if (!quiet_) {
        std::cout << "falsify: " << (out_dir / "falsify.json").string() << ", " << (out_dir / "falsify.html").string()
                  << " (" << fixed_text(record.wall_seconds, 1) << " s)\n";
    }
    if (const int signal = run_interrupt_signal()) {
        std::cerr << "rig falsify: interrupted by signal " << signal << "; the points that ran are in falsify.json\n";
        return 128 + signal;
    }
    return record.outcome.first_falsifying ? 1 : 0;
}

}  // namespace rig::harness
