#include "harness/commands/judge_command.h"

#include <unistd.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <set>

#include <nlohmann/json.hpp>

#include "harness/judge/verdict.h"
#include "harness/systems/systems.h"
#include "harness/report/html_report.h"
#include "harness/report/results_writer.h"
#include "harness/report/sweep_shard.h"
#include "harness/run/run_progress.h"

namespace rig::harness {

namespace {

namespace fs = std::filesystem;

struct Input {
    fs::path trace;
    fs::path out_dir;  // the run directory it came from (for --check); empty for a lone trace
};

nlohmann::json read_json(const fs::path& file) {
    std::ifstream in(file);
    if (!in) throw std::runtime_error("cannot read " + file.string());
    try {
        return nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& error) {
        throw std::runtime_error(file.string() + ": " + error.what());
    }
}

// The traces of a run directory, in its results.json's order when it has one.
std::vector<Input> traces_of_run(const fs::path& dir) {
    std::vector<Input> inputs;
    std::set<fs::path> listed;
    if (fs::exists(dir / "results.json")) {
        const nlohmann::json results = read_json(dir / "results.json");
        for (const nlohmann::json& one : results.at("cases")) {
            const fs::path trace = dir / "cases" / one.at("name").get<std::string>() / "trace.sqlite";
            if (fs::exists(trace) && listed.insert(trace).second) inputs.push_back({trace, dir});
        }
    }
    std::vector<fs::path> found;
    if (fs::is_directory(dir / "cases")) {
        for (const auto& entry : fs::directory_iterator(dir / "cases")) {
            const fs::path trace = entry.path() / "trace.sqlite";
            if (entry.is_directory() && fs::exists(trace) && !listed.count(trace)) found.push_back(trace);
        }
    }
    std::sort(found.begin(), found.end());
    for (const fs::path& trace : found) inputs.push_back({trace, dir});
    if (inputs.empty()) throw std::runtime_error(dir.string() + ": no cases/*/trace.sqlite in it");
    return inputs;
}

// Differences between a judged case and what results.json said of it.
std::vector<std::string> differences(const CaseResult& now, const nlohmann::json& before) {
    std::vector<std::string> found;
    auto differ = [&](const std::string& what, const std::string& was, const std::string& is) {
        found.push_back(now.name + ": " + what + " was " + was + ", now " + is);
    };
    const nlohmann::json& metrics = before.at("metrics");
    for (const auto& [name, value] : metrics.items()) {
        const auto it = now.metrics.find(name);
        if (it == now.metrics.end()) {
            differ("metric " + name, value.dump(), "absent");
        } else if (value.is_null() ? !std::isnan(it->second) : value.get<double>() != it->second) {
            differ("metric " + name, value.dump(), nlohmann::json(it->second).dump());
        }
    }
    for (const auto& [name, value] : now.metrics) {
        if (!metrics.contains(name)) differ("metric " + name, "absent", nlohmann::json(value).dump());
    }
    const nlohmann::json not_measured = before.value("not_measured", nlohmann::json::object());
    if (not_measured != nlohmann::json(now.not_measured)) {
        differ("not_measured", not_measured.dump(), nlohmann::json(now.not_measured).dump());
    }
    if (before.at("passed").get<bool>() != case_passed(now)) {
        differ("verdict", before.at("passed").dump(), case_passed(now) ? "true" : "false");
    }
    if (before.at("failures") != nlohmann::json(now.failures)) {
        differ("failures", before.at("failures").dump(), nlohmann::json(now.failures).dump());
    }
    if (before.at("trace_sha256").get<std::string>() != now.trace_sha256) {
        differ("trace_sha256", before.at("trace_sha256").get<std::string>(), now.trace_sha256);
    }
    return found;
}

// Differences between a judged case and its entry in a run's results.json
// (`results_file` names it in the message when the case is not there).
std::vector<std::string> differences_from_run(const CaseResult& now, const nlohmann::json& results,
                                              const fs::path& results_file) {
    for (const nlohmann::json& one : results.at("cases")) {
        if (one.at("name") == now.name) return differences(now, one);
    }
    return {now.name + ": not in " + results_file.string()};
}

// The exit status of a re-judging with `differences` from the recorded
// results: kExitRejudgedDiffers first, then as `rig run` (1 failed, 3 invalid, 0).
int rejudged_exit_status(const RunSummary& summary, std::size_t differences) {
    if (differences > 0) return kExitRejudgedDiffers;
    if (summary.failed > 0) return 1;
    return summary.invalid > 0 ? 3 : 0;  // as `rig run`: invalid runs, nothing failed
}

// Its last line: "re-judged: every metric, verdict and digest as recorded;
// 2 case(s) failed, as recorded (exit status 1)", or the differences' count
// and exit status 5. `recorded_by`: "recorded", "the shards recorded".
std::string rejudged_last_line(const RunSummary& summary, std::size_t differences, const std::string& recorded_by) {
    if (differences > 0) {
        return "re-judged: " + std::to_string(differences) + " difference(s) from the results " + recorded_by +
               ": the judging changed, whatever the verdicts (exit status " + std::to_string(kExitRejudgedDiffers) + ")";
    }
    std::string line = "re-judged: every metric, verdict and digest as " + recorded_by;
    if (summary.failed > 0) {
        line += "; " + std::to_string(summary.failed) + " case(s) failed, as recorded (exit status 1)";
    } else if (summary.invalid > 0) {
        line += "; " + std::to_string(summary.invalid) + " case(s) invalid, as recorded (exit status 3)";
    }
    return line;
}

// rig merge's --out: new or empty, so that nothing of another run is taken for the merge's.
void check_merge_out(const fs::path& out_dir) {
    if (out_dir.empty()) throw std::runtime_error("--out DIR is required");
    if (fs::exists(out_dir) && !(fs::is_directory(out_dir) && fs::is_empty(out_dir))) {
        throw std::runtime_error(out_dir.string() + " exists and is not an empty directory");
    }
}

// Whether the directories are rig sweep outputs (sweep.json) rather than rig
// run ones; throws, naming them, on a mix or on a directory holding both.
bool are_sweep_outputs(const std::vector<std::string>& dirs) {
    std::optional<std::string> a_sweep, a_run;
    for (const std::string& dir : dirs) {
        if (!fs::is_directory(dir)) throw std::runtime_error(dir + ": not a rig run --out directory, nor a rig sweep one");
        const bool sweep = fs::exists(fs::path(dir) / "sweep.json");
        if (sweep && fs::exists(fs::path(dir) / "results.json")) {
            throw std::runtime_error(dir + " holds both a rig run's results.json and a rig sweep's sweep.json: "
                                           "give each its own --out");
        }
        (sweep ? a_sweep : a_run) = dir;
    }
    if (a_sweep && a_run) {
        throw std::runtime_error(*a_sweep + " is the output of rig sweep, " + *a_run +
                                 " is not: merge the shards of one command");
    }
    return a_sweep.has_value();
}

// The outputs of rig sweep --shard I/N joined (harness/report/sweep_shard.h):
// each shard's cases/RUN/ (what it kept of each run) copied into --out, and
// sweep.json, sweep.txt and sweep.html written as one machine's sweep.
int merge_sweep_outputs(const MergeCommandOptions& options, std::ostream& out, std::ostream& err) {
    MergedSweep merged;
    try {
        std::vector<SweepShardOutput> outputs;
        for (const std::string& dir : options.shard_dirs) outputs.push_back({dir, read_json(fs::path(dir) / "sweep.json")});
        merged = merge_sweep_shards(outputs);
    } catch (const std::exception& error) {
        err << "rig merge: " << error.what() << "\n";
        return 2;
    }
    try {
        fs::create_directories(options.out_dir / "cases");
        for (std::size_t i = 0; i < options.shard_dirs.size(); ++i) {
            for (const std::string& run : merged.runs_of_shard[i]) {
                const fs::path kept = fs::path(options.shard_dirs[i]) / "cases" / run;
                if (fs::is_directory(kept)) fs::copy(kept, options.out_dir / "cases" / run, fs::copy_options::recursive);
            }
        }
        write_sweep_files(options.out_dir, merged.json, merged.cases, merged.info);
    } catch (const std::exception& error) {
        err << "rig merge: cannot write the merged sweep in " << options.out_dir.string() << ": " << error.what() << "\n";
        return 2;
    }
    std::size_t passed = 0;
    for (const CaseSweep& sweep : merged.cases) passed += sweep.passed;
    out << sweep_table(merged.cases, merged.info) << "merged " << merged.runs << " runs from "
        << options.shard_dirs.size() << " shards\n"
        << "sweep: " << (options.out_dir / "sweep.json").string() << ", " << (options.out_dir / "sweep.txt").string()
        << ", " << (options.out_dir / "sweep.html").string() << "\n";
    return passed == merged.runs ? 0 : 1;  // as rig sweep
}

}  // namespace

int run_judge_command(const JudgeCommandOptions& options, std::ostream& out, std::ostream& err) {
    std::vector<Input> inputs;
    try {
        for (const std::string& argument : options.inputs) {
            const fs::path path(argument);
            if (fs::is_directory(path)) {
                for (Input& input : traces_of_run(path)) inputs.push_back(std::move(input));
            } else if (fs::exists(path)) {
                inputs.push_back({path, {}});
            } else {
                throw std::runtime_error(argument + ": no such file or directory");
            }
        }
    } catch (const std::exception& error) {
        err << "rig judge: " << error.what() << "\n";
        return 2;
    }
    std::vector<CaseResult> results;
    std::vector<CaseFigures> figures;
    for (const Input& input : inputs) {
        try {
            CaseRun run = judge_trace(read_trace(input.trace));
            results.push_back(std::move(run.result));
            figures.push_back(std::move(run.figures));
        } catch (const std::exception& error) {
            err << "rig judge: " << error.what() << "\n";
            return 2;
        }
    }
    RunSummary summary = summarize(results);

    std::vector<std::string> differing;
    if (options.check) {
        std::map<fs::path, nlohmann::json> before_by_dir;
        for (std::size_t i = 0; i < inputs.size(); ++i) {
            if (inputs[i].out_dir.empty()) {
                err << "rig judge: --check needs run directories, not trace files (" << inputs[i].trace.string() << ")\n";
                return 2;
            }
            if (!before_by_dir.count(inputs[i].out_dir)) {
                try {
                    before_by_dir[inputs[i].out_dir] = read_json(inputs[i].out_dir / "results.json");
                } catch (const std::exception& error) {
                    err << "rig judge: --check: " << error.what() << "\n";
                    return 2;
                }
            }
            for (std::string& difference :
                 differences_from_run(results[i], before_by_dir[inputs[i].out_dir], inputs[i].out_dir / "results.json")) {
                differing.push_back(std::move(difference));
            }
        }
    }
    if (!options.out_dir.empty()) {
        try {
            for (const std::string& problem : write_results(options.out_dir, results, summary, figures, HtmlReportOptions{})) {
                err << "rig judge: report: " << problem << "\n";
            }
        } catch (const std::exception& error) {
            err << "rig judge: cannot write the results in " << options.out_dir.string() << ": " << error.what() << "\n";
            return 2;
        }
    }
    out << result_table(results, summary, colour_wanted(STDOUT_FILENO));
    if (!options.out_dir.empty()) out << "results: " << (options.out_dir / "results.json").string() << "\n";
    if (options.check) {
        // Last: a CI reads from it whether the controller failed or the judging changed.
        for (const std::string& difference : differing) out << "differs: " << difference << "\n";
        out << rejudged_last_line(summary, differing.size(), "recorded") << "\n";
    }
    return rejudged_exit_status(summary, differing.size());
}

int run_merge_command(const MergeCommandOptions& options, std::ostream& out, std::ostream& err) {
    struct RunShard {
        fs::path dir;
        nlohmann::json results;
        std::vector<fs::path> case_dirs;
    };
    std::vector<RunShard> shards;
    try {
        check_merge_out(options.out_dir);
        if (are_sweep_outputs(options.shard_dirs)) return merge_sweep_outputs(options, out, err);
        std::map<std::string, fs::path> shard_of_case;
        for (const std::string& argument : options.shard_dirs) {
            RunShard shard{argument, {}, {}};
            shard.results = read_json(shard.dir / "results.json");
            for (const Input& input : traces_of_run(shard.dir)) {
                const fs::path case_dir = input.trace.parent_path();
                const std::string name = case_dir.filename().string();
                const auto [earlier, inserted] = shard_of_case.emplace(name, shard.dir);
                if (!inserted) {
                    throw std::runtime_error("case " + name + " is in both " + earlier->second.string() + " and " +
                                             shard.dir.string() + ": not shards of one suite");
                }
                shard.case_dirs.push_back(case_dir);
            }
            shards.push_back(std::move(shard));
        }
    } catch (const std::exception& error) {
        err << "rig merge: " << error.what() << "\n";
        return 2;
    }

    std::vector<CaseResult> results;
    std::vector<CaseFigures> figures;
    std::vector<std::string> differing;
    try {
        fs::create_directories(options.out_dir / "cases");
        for (const RunShard& shard : shards) {
            for (const fs::path& case_dir : shard.case_dirs) {
                const fs::path copy = options.out_dir / "cases" / case_dir.filename();
                fs::copy(case_dir, copy, fs::copy_options::recursive);
                CaseRun run = judge_trace(read_trace(copy / "trace.sqlite"));
                for (std::string& difference : differences_from_run(run.result, shard.results, shard.dir / "results.json")) {
                    differing.push_back(std::move(difference));
                }
                results.push_back(std::move(run.result));
                figures.push_back(std::move(run.figures));
            }
        }
    } catch (const std::exception& error) {
        err << "rig merge: " << error.what() << "\n";
        return 2;
    }
    RunSummary summary = summarize(results);
    try {
        for (const std::string& problem : write_results(options.out_dir, results, summary, figures, HtmlReportOptions{})) {
            err << "rig merge: report: " << problem << "\n";
        }
    } catch (const std::exception& error) {
        err << "rig merge: cannot write the results in " << options.out_dir.string() << ": " << error.what() << "\n";
        return 2;
    }
    out << result_table(results, summary, isatty(STDOUT_FILENO) != 0);
    out << "merged " << results.size() << " cases from " << shards.size() << " shards into "
        << (options.out_dir / "results.json").string() << "\n";
    for (const std::string& difference : differing) out << "differs: " << difference << "\n";
    out << rejudged_last_line(summary, differing.size(), "the shards recorded") << "\n";
    return rejudged_exit_status(summary, differing.size());
}

JudgeCommand::JudgeCommand(CLI::App& app) {
    command_ = app.add_subcommand(
        "judge", "judge recorded traces again (a run's --out directory, or trace files): same results contract");
    command_->add_option("runs_or_traces", options_.inputs, "rig run --out directories or trace.sqlite files")->required();
    command_->add_option("--out", options_.out_dir, "write results.json, junit.xml and the reports here");
    command_->add_flag("--check", options_.check,
                       "compare with each directory's results.json: metrics, verdicts and digests must be the same");
}

bool JudgeCommand::parsed() const { return command_->parsed(); }

int JudgeCommand::run() { return run_judge_command(options_, std::cout, std::cerr); }

MergeCommand::MergeCommand(CLI::App& app) {
    command_ = app.add_subcommand(
        "merge", "join the outputs of rig run --shard I/N into one run directory (results.json, junit.xml, reports), or "
                 "those of rig sweep --shard I/N into one sweep (sweep.json, sweep.txt, sweep.html)");
    command_->add_option("shard_outs", options_.shard_dirs, "the shards' rig run or rig sweep --out directories")
        ->required();
    command_->add_option("--out", options_.out_dir, "the merged run directory (new or empty)")->required();
}

bool MergeCommand::parsed() const { return command_->parsed(); }

int MergeCommand::run() { return run_merge_command(options_, std::cout, std::cerr); }

}  // namespace rig::harness
