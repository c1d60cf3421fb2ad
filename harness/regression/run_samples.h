#pragma once
// The runs of one `rig run` or `rig sweep` output, as samples per case and
// metric: what `rig compare`, `rig history` and the Bencher export read
// (docs/regression.md). results.json gives one run per case (or one per seed
// of a `seeds:` case); sweep.json gives every seed of every case.
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rig::harness {

struct RunSample {
    std::uint64_t seed = 0;
    std::string run;  // the run's name (NAME or NAME-seedN)
    std::string trace_sha256;
    bool passed = false;
    std::string error;
    std::map<std::string, double> metrics;
    // Metrics the run gave no value for, with why (a null value in the file reads "no value (NaN)").
    std::map<std::string, std::string> not_measured;
    // harness/run/run_identity.h; empty when the output did not record them.
    std::string case_sha256;
    std::string controller_sha256;
    std::string controller_config_sha256;
};

struct CaseSamples {
    std::string name;  // the case's name (not the run's)
    std::string file;
    std::map<std::string, double> limits;       // the limits the runs were judged against
    std::map<std::string, double> min_effects;  // the case file's compare.min_effect
    std::vector<RunSample> runs;                // by seed, ascending
};

struct RunSamples {
    std::filesystem::path source;  // the results.json or sweep.json read
    std::string kind;              // "run" or "sweep"
    std::string rig_version;
    std::string rig_commit;
    // When the run or sweep started (sweep.json's started_utc); empty when the output does not say.
    std::string started_utc;
    std::vector<CaseSamples> cases;  // by name
};

// Reads a run or sweep output: a directory holding results.json or sweep.json
// (not both), or either file. Throws std::runtime_error naming the file and
// what in it is wrong (not JSON, no `cases`, a run without a name, a metric
// that is not a number, the same seed of a case twice).
RunSamples load_run_samples(const std::filesystem::path& input);
// The same from parsed JSON (`kind` "run" for results.json, "sweep" for sweep.json).
RunSamples run_samples_from_json(const nlohmann::json& json, const std::string& kind, const std::filesystem::path& source);

}  // namespace rig::harness
