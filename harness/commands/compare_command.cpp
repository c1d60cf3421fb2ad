#include "harness/commands/compare_command.h"

#include <CLI/CLI.hpp>

#include <charconv>
#include <cmath>
#include <iostream>

#include "harness/output/atomic_file.h"
#include "harness/regression/bencher_format.h"
#include "harness/regression/compare_report.h"
#include "harness/regression/run_samples.h"
#include "harness/run/output_dir.h"

namespace rig::harness {

namespace {

// "overlap_m=0.1" -> (overlap_m, 0.1); an error names the argument.
std::pair<std::string, double> parse_min_effect(const std::string& text) {
    const auto equals = text.find('=');
    if (equals == std::string::npos || equals == 0) {
        throw std::invalid_argument("--min-effect " + text + ": write METRIC=SHIFT, e.g. overlap_m=0.1");
    }
    const std::string metric = text.substr(0, equals);
    const std::string number = text.substr(equals + 1);
    double value = 0.0;
    const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), value);
    if (error != std::errc{} || end != number.data() + number.size() || !std::isfinite(value) || value < 0.0) {
        throw std::invalid_argument("--min-effect " + text + ": the shift must be a number >= 0 in the metric's unit");
    }
    return {metric, value};
}

}  // namespace

CompareCommand::CompareCommand(CLI::App& app) {
    command_ = app.add_subcommand(
        "compare", "compare two outputs of rig run or rig sweep (base, head): which metrics regressed, and why");
    command_->add_option("base", base_, "the base: a run or sweep directory, or its results.json / sweep.json")->required();
    command_->add_option("head", head_, "the head (the change under test), the same")->required();
    command_->add_option("--out", out_dir_, "write compare.json, compare.md, compare.html and junit.xml here");
    command_->add_option("--alpha", settings_.alpha, "significance over the whole comparison (Holm), default 0.01")
        ->check(CLI::Range(1e-9, 0.5));
    command_->add_option("--min-effect", min_effects_,
                         "METRIC=SHIFT: the smallest shift called a regression (repeatable; over the case file's)");
    command_->add_flag("--any-seeds", settings_.any_seeds,
                       "compare sweeps over different seeds as independent samples");
    command_->add_option("--bmf", bmf_file_, "also write the head's metrics in Bencher's JSON format to this file");
    command_->add_flag("--quiet,-q", quiet_, "print only the last line");
}

bool CompareCommand::parsed() const { return command_->parsed(); }

int CompareCommand::run() {
    for (const std::string& text : min_effects_) {
        try {
            settings_.min_effects.insert(parse_min_effect(text));
        } catch (const std::invalid_argument& error) {
            std::cerr << "rig compare: " << error.what() << "\n";
            return 2;
        }
    }
    RunSamples base, head;
    try {
        base = load_run_samples(base_);
        head = load_run_samples(head_);
    } catch (const std::exception& error) {
        std::cerr << "rig compare: " << error.what() << "\n";
        return 2;
    }
    const Comparison comparison = compare_runs(base, head, settings_);
    const std::string table = compare_table(comparison);
    try {
        if (!out_dir_.empty()) {
            prepare_output_directory(out_dir_);
            const std::filesystem::path out(out_dir_);
            write_file_atomically(out / "compare.json", compare_json(comparison).dump(1) + "\n");
            write_file_atomically(out / "compare.md", compare_markdown(comparison));
            write_file_atomically(out / "compare.html", compare_html(comparison));
            write_file_atomically(out / "junit.xml", compare_junit(comparison));
        }
        if (!bmf_file_.empty()) write_file_atomically(bmf_file_, bencher_metric_format(head).dump(1) + "\n");
    } catch (const std::exception& error) {
        std::cout << table;
        std::cerr << "rig compare: outputs not written: " << error.what() << "\n";
        return kExitResultsNotWritten;
    }
    std::cout << (quiet_ ? table.substr(table.rfind('\n', table.size() - 2) + 1) : table);
    if (!quiet_ && !out_dir_.empty()) {
        std::cout << "compare: " << (std::filesystem::path(out_dir_) / "compare.md").string() << ", "
                  << (std::filesystem::path(out_dir_) / "compare.html").string() << "\n";
    }
    return comparison.regressions() > 0 ? 1 : 0;
}

}  // namespace rig::harness
