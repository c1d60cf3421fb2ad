#include "harness/report/sweep_shard.h"

#include <algorithm>
#include <limits>
#include <map>
#include <stdexcept>
#include <utility>

#include "harness/output/atomic_file.h"

namespace rig::harness {

namespace fs = std::filesystem;

nlohmann::json sweep_shard_json(const Shard& shard, const std::vector<CaseSpec>& specs, std::size_t runs_in_sweep,
                                const std::vector<CaseInstance>& held, const std::vector<CaseResult>& results) {
    nlohmann::json cases = nlohmann::json::array();
    for (const CaseSpec& spec : specs) cases.push_back({{"name", spec.name}, {"paper", spec.paper.values}});
    nlohmann::json runs = nlohmann::json::array();
    for (std::size_t i = 0; i < held.size() && i < results.size(); ++i) {
        const CaseResult& result = results[i];
        runs.push_back({{"run", held[i].name},
                        {"limits", result.limits},
                        {"sim_seconds", result.sim_seconds},
                        {"error_kind", result.error_kind},
                        {"expected_error", result.expected_error}});
    }
    return {{"index", shard.index},
            {"count", shard.count},
            {"runs_in_sweep", runs_in_sweep},
            {"cases", std::move(cases)},
            {"runs", std::move(runs)}};
}

void write_sweep_files(const fs::path& out_dir, const nlohmann::json& json, const std::vector<CaseSweep>& cases,
                       const SweepInfo& info) {
    write_file_atomically(out_dir / "sweep.json", json.dump(1) + "\n");
    write_file_atomically(out_dir / "sweep.txt", sweep_table(cases, info));
    write_file_atomically(out_dir / "sweep.html", sweep_html(cases, info));
}

namespace {

// What one shard's sweep.json says, read and checked on its own.
struct ShardRead {
    fs::path dir;
    int index = 0;
    int count = 0;
    // What every shard of one sweep shares, by what a message calls it.
    std::vector<std::pair<std::string, nlohmann::json>> sweep_identity;
    std::vector<std::string> held;              // the runs it holds, in the order it ran them
    std::map<std::string, nlohmann::json> entries;  // run -> its cases[].seeds entry
    std::map<std::string, std::size_t> case_of_entry;  // run -> the index of the case it is listed under
    std::map<std::string, nlohmann::json> extras;  // run -> its shard.runs entry
    std::string started_utc;
    double wall_seconds = 0.0;
};

std::string sweep_file(const fs::path& dir) { return (dir / "sweep.json").string(); }

// A value for a message: short, whole when it is.
std::string shown(const nlohmann::json& value) {
    constexpr std::size_t kLongest = 160;
    const std::string text = value.dump();
    return text.size() <= kLongest ? text : text.substr(0, kLongest) + "...";
}

ShardRead read_shard(const SweepShardOutput& output) {
    const nlohmann::json& sweep = output.sweep;
    ShardRead shard;
    shard.dir = output.dir;
    if (!sweep.is_object() || !sweep.contains("shard")) {
        throw std::runtime_error(sweep_file(output.dir) +
                                 ": a sweep without --shard, not a shard: only the outputs of rig sweep --shard I/N merge");
    }
    const nlohmann::json& about = sweep.at("shard");
    shard.index = about.at("index").get<int>();
    shard.count = about.at("count").get<int>();
    if (shard.count < 1 || shard.index < 1 || shard.index > shard.count) {
        throw std::runtime_error(sweep_file(output.dir) + ": shard " + std::to_string(shard.index) + " of " +
                                 std::to_string(shard.count) + " cannot be");
    }
    if (about.at("cases").size() != sweep.at("cases").size()) {
        throw std::runtime_error(sweep_file(output.dir) + ": its shard object and its cases list other cases");
    }
    nlohmann::json cases = nlohmann::json::array();
    for (const nlohmann::json& item : sweep.at("cases")) {
        cases.push_back({{"name", item.at("name")}, {"file", item.at("file")}, {"paper_source", item.at("paper_source")}});
    }
    shard.sweep_identity = {{"rig version", sweep.at("rig")},
                            {"sweep.json schema", sweep.at("schema_version")},
                            {"seeds", sweep.at("seeds")},
                            {"cases", std::move(cases)},
                            {"paper numbers", about.at("cases")},
                            {"keep_traces", sweep.at("keep_traces")},
                            {"controller_mode", sweep.at("controller_mode")},
                            {"shard count", about.at("count")},
                            {"runs in the sweep", about.at("runs_in_sweep")}};
    for (const nlohmann::json& run : about.at("runs")) {
        const std::string name = run.at("run").get<std::string>();
        if (!shard.extras.emplace(name, run).second) {
            throw std::runtime_error(sweep_file(output.dir) + ": run " + name + " is listed twice");
        }
        shard.held.push_back(name);
    }
    const nlohmann::json& listed_cases = sweep.at("cases");
    for (std::size_t case_index = 0; case_index < listed_cases.size(); ++case_index) {
        for (const nlohmann::json& entry : listed_cases[case_index].at("seeds")) {
            const std::string name = entry.at("run").get<std::string>();
            if (!shard.extras.contains(name) || !shard.entries.emplace(name, entry).second) {
                throw std::runtime_error(sweep_file(output.dir) + ": run " + name +
                                         " is not once among the runs its shard object lists");
            }
            shard.case_of_entry[name] = case_index;
        }
    }
    if (shard.entries.size() != shard.extras.size()) {
        throw std::runtime_error(sweep_file(output.dir) + ": its shard object lists " +
                                 std::to_string(shard.extras.size()) + " runs, its cases " +
                                 std::to_string(shard.entries.size()));
    }
    shard.started_utc = sweep.at("started_utc").get<std::string>();
    shard.wall_seconds = sweep.at("wall_seconds").get<double>();
    return shard;
}

// A run as far as the bands, pass rates and totals need it: its seeds entry
// (verdict, metrics, what was not measured, failures, error, digest) and its
// shard.runs entry.
CaseResult rebuilt_result(const nlohmann::json& entry, const nlohmann::json& extra) {
    CaseResult result;
    result.name = entry.at("run").get<std::string>();
    result.seed = entry.at("seed").get<std::uint64_t>();
    result.passed = entry.at("passed").get<bool>();
    for (const auto& [name, value] : entry.at("metrics").items()) {
        // A non-finite value is written as null; the bands take both as not measured.
        result.metrics[name] = value.is_null() ? std::numeric_limits<double>::quiet_NaN() : value.get<double>();
    }
    result.failures = entry.at("failures").get<std::vector<std::string>>();
    result.error = entry.at("error").is_null() ? "" : entry.at("error").get<std::string>();
    result.trace_sha256 = entry.at("trace_sha256").get<std::string>();
    result.not_measured = entry.at("not_measured").get<std::map<std::string, std::string>>();
    result.limits = extra.at("limits").get<std::map<std::string, double>>();
    result.sim_seconds = extra.at("sim_seconds").get<double>();
    result.error_kind = extra.at("error_kind").get<std::string>();
    result.expected_error = extra.at("expected_error").get<std::string>();
    return result;
}

std::string run_list(const std::vector<std::string>& runs) {
    std::string text;
    for (const std::string& run : runs) text += (text.empty() ? "" : ", ") + run;
    return text.empty() ? "none" : text;
}

}  // namespace

MergedSweep merge_sweep_shards(const std::vector<SweepShardOutput>& outputs) {
    if (outputs.empty()) throw std::runtime_error("no shard to merge");
    std::vector<ShardRead> shards;
    for (const SweepShardOutput& output : outputs) {
        try {
            shards.push_back(read_shard(output));
        } catch (const nlohmann::json::exception& error) {
            throw std::runtime_error(sweep_file(output.dir) + ": not a rig sweep.json: " + error.what());
        }
    }
    const ShardRead& first = shards.front();
    std::map<int, const ShardRead*> shard_by_index;
    for (const ShardRead& shard : shards) {
        for (std::size_t i = 0; i < first.sweep_identity.size(); ++i) {
            const auto& [what, value] = shard.sweep_identity[i];
            if (value != first.sweep_identity[i].second) {
                throw std::runtime_error(shard.dir.string() + " is not a shard of the sweep in " + first.dir.string() +
                                         ": its " + what + " " + shown(value) + ", not " +
                                         shown(first.sweep_identity[i].second));
            }
        }
        const auto [earlier, inserted] = shard_by_index.emplace(shard.index, &shard);
        if (!inserted) {
            throw std::runtime_error(earlier->second->dir.string() + " and " + shard.dir.string() + " are both shard " +
                                     std::to_string(shard.index) + "/" + std::to_string(shard.count));
        }
    }
    for (int index = 1; index <= first.count; ++index) {
        if (!shard_by_index.contains(index)) {
            throw std::runtime_error("shard " + std::to_string(index) + "/" + std::to_string(first.count) +
                                     " is missing (the shards given: " + std::to_string(shards.size()) + " of " +
                                     std::to_string(first.count) + ")");
        }
    }

    // The sweep's case files as far as the bands need them, and its runs in
    // the order one machine runs them.
    const nlohmann::json& first_sweep = outputs.front().sweep;
    std::vector<CaseSpec> specs;
    RunOptions sweep_options;
    std::size_t runs_in_sweep = 0;
    try {
        const nlohmann::json& paper_numbers = first_sweep.at("shard").at("cases");
        for (std::size_t i = 0; i < first_sweep.at("cases").size(); ++i) {
            const nlohmann::json& item = first_sweep.at("cases")[i];
            CaseSpec spec;
            spec.name = item.at("name").get<std::string>();
            spec.source_path = item.at("file").get<std::string>();
            spec.paper.source = item.at("paper_source").is_null() ? "" : item.at("paper_source").get<std::string>();
            spec.paper.values = paper_numbers.at(i).at("paper").get<std::map<std::string, double>>();
            specs.push_back(std::move(spec));
        }
        sweep_options.seed_sweep = first_sweep.at("seeds").get<std::vector<std::uint64_t>>();
        runs_in_sweep = first_sweep.at("shard").at("runs_in_sweep").get<std::size_t>();
    } catch (const nlohmann::json::exception& error) {
        throw std::runtime_error(sweep_file(first.dir) + ": not a rig sweep.json: " + error.what());
    }
    const std::vector<CaseInstance> runs = expand_runs(specs, sweep_options);
    if (runs.size() != runs_in_sweep) {
        throw std::runtime_error(sweep_file(first.dir) + ": " + std::to_string(runs_in_sweep) + " runs in the sweep, but " +
                                 std::to_string(specs.size()) + " cases over " +
                                 std::to_string(sweep_options.seed_sweep.size()) + " seeds are " +
                                 std::to_string(runs.size()));
    }

    std::map<int, std::vector<std::string>> expected_runs;
    for (std::size_t k = 0; k < runs.size(); ++k) expected_runs[shard_of_run(k, first.count)].push_back(runs[k].name);
    for (const ShardRead& shard : shards) {
        if (shard.held != expected_runs[shard.index]) {
            throw std::runtime_error(shard.dir.string() + ": shard " + std::to_string(shard.index) + "/" +
                                     std::to_string(shard.count) + " holds runs " + run_list(shard.held) +
                                     ", but its runs are " + run_list(expected_runs[shard.index]));
        }
    }

    MergedSweep merged;
    merged.runs = runs.size();
    std::vector<CaseResult> results;
    std::vector<nlohmann::json> entries_of_case(specs.size(), nlohmann::json::array());
    for (std::size_t k = 0; k < runs.size(); ++k) {
        const ShardRead& shard = *shard_by_index.at(shard_of_run(k, first.count));
        const std::string& name = runs[k].name;
        if (shard.case_of_entry.at(name) != runs[k].spec_index) {
            throw std::runtime_error(sweep_file(shard.dir) + ": run " + name + " is listed under another case");
        }
        const nlohmann::json& entry = shard.entries.at(name);
        try {
            results.push_back(rebuilt_result(entry, shard.extras.at(name)));
        } catch (const nlohmann::json::exception& error) {
            throw std::runtime_error(sweep_file(shard.dir) + ": run " + name + ": " + error.what());
        }
        if (results.back().seed != runs[k].seed) {
            throw std::runtime_error(sweep_file(shard.dir) + ": run " + name + " has seed " +
                                     std::to_string(results.back().seed) + ", not " + std::to_string(runs[k].seed));
        }
        entries_of_case[runs[k].spec_index].push_back(entry);
        merged.info.sim_seconds += results.back().sim_seconds;  // in one machine's order: the same sum, bit for bit
    }

    merged.info.seeds = sweep_options.seed_sweep;
    merged.info.keep_traces = first_sweep.at("keep_traces").get<std::string>();
    merged.info.controller_mode = first_sweep.at("controller_mode").get<std::string>();
    merged.info.started_utc = first.started_utc;
    for (const auto& [index, shard] : shard_by_index) {
        // ISO 8601 UTC times of one form: the earliest is the least text.
        merged.info.started_utc = std::min(merged.info.started_utc, shard->started_utc);
        merged.info.wall_seconds += shard->wall_seconds;
    }
    merged.cases = summarize_sweep(specs, runs, results);
    merged.json = sweep_json(merged.cases, runs, results, merged.info);
    if (merged.json.at("schema_version") != first_sweep.at("schema_version")) {
        throw std::runtime_error(sweep_file(first.dir) + ": sweep.json schema " + first_sweep.at("schema_version").dump() +
                                 ", this rig writes " + merged.json.at("schema_version").dump());
    }
    // What the shards' rig wrote, which this rig may not be.
    merged.json["rig"] = first_sweep.at("rig");
    // Each run's entry as its shard wrote it: every field, today's and those a
    // later rig adds, as one machine would have written it.
    for (std::size_t i = 0; i < specs.size(); ++i) merged.json["cases"][i]["seeds"] = std::move(entries_of_case[i]);
    for (const ShardRead& shard : shards) merged.runs_of_shard.push_back(shard.held);
    return merged;
}

}  // namespace rig::harness
