#include "harness/regression/run_samples.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

namespace rig::harness {

namespace {

namespace fs = std::filesystem;

// An error that already names the file and the place in it.
struct LocatedError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

[[noreturn]] void bad(const fs::path& source, const std::string& where, const std::string& what) {
    throw LocatedError(source.string() + ": " + where + ": " + what);
}

std::string text_or_empty(const nlohmann::json& object, const char* key) {
    if (!object.contains(key) || object.at(key).is_null()) return "";
    if (!object.at(key).is_string()) throw std::runtime_error(std::string(key) + " is not text");
    return object.at(key).get<std::string>();
}

std::map<std::string, double> numbers_of(const nlohmann::json& object, const char* key) {
    std::map<std::string, double> numbers;
    if (!object.contains(key) || object.at(key).is_null()) return numbers;
    if (!object.at(key).is_object()) throw std::runtime_error(std::string(key) + " is not an object");
    for (const auto& [name, value] : object.at(key).items()) {
        if (!value.is_number()) throw std::runtime_error(std::string(key) + "." + name + " is not a number");
        numbers[name] = value.get<double>();
    }
    return numbers;
}

// A run's metrics: a null value (NaN as results.json writes it) is a value
// the judge could not give, so it counts as not measured, never as zero.
RunSample sample_of(const nlohmann::json& run, std::uint64_t seed, const std::string& name) {
    RunSample sample;
    sample.seed = seed;
    sample.run = name;
    sample.trace_sha256 = text_or_empty(run, "trace_sha256");
    sample.passed = run.value("passed", false);
    sample.error = text_or_empty(run, "error");
    sample.case_sha256 = text_or_empty(run, "case_sha256");
    sample.controller_sha256 = text_or_empty(run, "controller_sha256");
    sample.controller_config_sha256 = text_or_empty(run, "controller_config_sha256");
    if (run.contains("metrics") && !run.at("metrics").is_object()) throw std::runtime_error("metrics is not an object");
    const nlohmann::json metrics = run.value("metrics", nlohmann::json::object());
    for (const auto& [metric, value] : metrics.items()) {
        if (value.is_null()) {
            sample.not_measured[metric] = "no value (NaN)";
        } else if (value.is_number()) {
            sample.metrics[metric] = value.get<double>();
        } else {
            throw std::runtime_error("metrics." + metric + " is not a number");
        }
    }
    if (run.contains("not_measured") && run.at("not_measured").is_object()) {
        for (const auto& [metric, why] : run.at("not_measured").items()) {
            if (!sample.metrics.count(metric)) sample.not_measured[metric] = why.is_string() ? why.get<std::string>() : why.dump();
        }
    }
    return sample;
}

// results.json's run name is NAME-seedN for a case with `seeds:`; older
// results lack `case`, so the suffix is taken off when it names the run's seed.
std::string case_name_of(const nlohmann::json& run, const std::string& run_name, std::uint64_t seed) {
    const std::string recorded = text_or_empty(run, "case");
    if (!recorded.empty()) return recorded;
    const std::string suffix = "-seed" + std::to_string(seed);
    if (run_name.size() > suffix.size() && run_name.compare(run_name.size() - suffix.size(), suffix.size(), suffix) == 0) {
        return run_name.substr(0, run_name.size() - suffix.size());
    }
    return run_name;
}

CaseSamples& case_named(std::map<std::string, CaseSamples>& cases, const std::string& name, const std::string& file) {
    CaseSamples& samples = cases[name];
    samples.name = name;
    if (samples.file.empty()) samples.file = file;
    return samples;
}

void add_run(CaseSamples& samples, RunSample run, const fs::path& source, const std::string& where) {
    for (const RunSample& known : samples.runs) {
        if (known.seed == run.seed) {
            bad(source, where, "case '" + samples.name + "' has seed " + std::to_string(run.seed) + " twice");
        }
    }
    samples.runs.push_back(std::move(run));
}

std::uint64_t seed_of(const nlohmann::json& run) {
    if (!run.contains("seed") || !run.at("seed").is_number_unsigned()) throw std::runtime_error("no seed (a whole number)");
    return run.at("seed").get<std::uint64_t>();
}

std::string name_of(const nlohmann::json& object, const char* key) {
    const std::string name = text_or_empty(object, key);
    if (name.empty()) throw std::runtime_error(std::string("no ") + key);
    return name;
}

}  // namespace

RunSamples run_samples_from_json(const nlohmann::json& json, const std::string& kind, const fs::path& source) {
    RunSamples samples;
    samples.source = source;
    samples.kind = kind;
    if (!json.is_object() || !json.contains("cases") || !json.at("cases").is_array()) {
        bad(source, "top level", "no `cases` array: not the output of rig run or rig sweep");
    }
    if (json.contains("rig") && json.at("rig").is_object()) {
        samples.rig_version = text_or_empty(json.at("rig"), "version");
        samples.rig_commit = text_or_empty(json.at("rig"), "commit");
    }
    if (json.contains("started_utc") && json.at("started_utc").is_string()) {
        samples.started_utc = json.at("started_utc").get<std::string>();
    }
    std::map<std::string, CaseSamples> cases;
    const nlohmann::json& listed = json.at("cases");
    for (std::size_t index = 0; index < listed.size(); ++index) {
        const std::string where = "cases[" + std::to_string(index) + "]";
        const nlohmann::json& item = listed[index];
        try {
            if (!item.is_object()) throw std::runtime_error("not an object");
            if (kind == "run") {
                const std::string run_name = name_of(item, "name");
                const std::uint64_t seed = seed_of(item);
                CaseSamples& found = case_named(cases, case_name_of(item, run_name, seed), text_or_empty(item, "file"));
                for (const auto& [metric, limit] : numbers_of(item, "limits")) found.limits[metric] = limit;
                for (const auto& [metric, effect] : numbers_of(item, "min_effects")) found.min_effects[metric] = effect;
                add_run(found, sample_of(item, seed, run_name), source, where);
            } else {
                CaseSamples& found = case_named(cases, name_of(item, "name"), text_or_empty(item, "file"));
                if (item.contains("bands") && item.at("bands").is_object()) {
                    for (const auto& [metric, band] : item.at("bands").items()) {
                        if (band.is_object() && band.contains("limit") && band.at("limit").is_number()) {
                            found.limits[metric] = band.at("limit").get<double>();
                        }
                    }
                }
                if (!item.contains("seeds") || !item.at("seeds").is_array()) throw std::runtime_error("no `seeds` array");
                const nlohmann::json& seeds = item.at("seeds");
                for (std::size_t k = 0; k < seeds.size(); ++k) {
                    try {
                        const nlohmann::json& run = seeds[k];
                        if (!run.is_object()) throw std::runtime_error("not an object");
                        const std::uint64_t seed = seed_of(run);
                        for (const auto& [metric, effect] : numbers_of(run, "min_effects")) found.min_effects[metric] = effect;
                        add_run(found, sample_of(run, seed, text_or_empty(run, "run")), source,
                                where + ".seeds[" + std::to_string(k) + "]");
                    } catch (const LocatedError&) {
                        throw;
                    } catch (const std::exception& error) {
                        bad(source, where + ".seeds[" + std::to_string(k) + "]", error.what());
                    }
                }
            }
        } catch (const LocatedError&) {
            throw;
        } catch (const std::exception& error) {
            bad(source, where, error.what());
        }
    }
    for (auto& [name, one_case] : cases) {
        std::sort(one_case.runs.begin(), one_case.runs.end(),
                  [](const RunSample& a, const RunSample& b) { return a.seed < b.seed; });
        samples.cases.push_back(std::move(one_case));
    }
    return samples;
}

RunSamples load_run_samples(const fs::path& input) {
    fs::path file = input;
    std::error_code error;
    if (fs::is_directory(input, error)) {
        const bool has_results = fs::exists(input / "results.json", error);
        const bool has_sweep = fs::exists(input / "sweep.json", error);
        if (has_results && has_sweep) {
            throw std::runtime_error(input.string() + ": holds both results.json and sweep.json; name the one to read");
        }
        if (!has_results && !has_sweep) {
            throw std::runtime_error(input.string() + ": neither results.json (rig run) nor sweep.json (rig sweep) is in it");
        }
        file = input / (has_sweep ? "sweep.json" : "results.json");
    } else if (!fs::exists(input, error)) {
        throw std::runtime_error(input.string() + ": no such file or directory");
    }
    const std::string kind = file.filename() == "sweep.json" ? "sweep" : "run";
    std::ifstream in(file);
    if (!in) throw std::runtime_error(file.string() + ": cannot be read");
    nlohmann::json json;
    try {
        json = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& parse_error) {
        throw std::runtime_error(file.string() + ": not JSON: " + parse_error.what());
    }
    // A file named otherwise says what it is by its keys: a sweep has `seeds`.
    const std::string found_kind = file.filename() == "results.json" || file.filename() == "sweep.json"
                                       ? kind
                                       : (json.is_object() && json.contains("seeds") ? "sweep" : "run");
    return run_samples_from_json(json, found_kind, file);
}

}  // namespace rig::harness
