#pragma once
// A search asked for (on the command line, or in a `search:` file beside its
// case) checked against its base case before anything runs: every varied key
// written in the file (as a number, unless varied over choices), each end of
// its range and each choice a valid case (the key's own bounds and choices, as
// the loader checks them), every metric asked for limited in the case.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "harness/falsify/case_evaluator.h"
#include "harness/falsify/falsify_search.h"

namespace rig::harness {

struct FalsifyRequest {
    std::filesystem::path case_file;
    std::vector<KeySetting> settings;  // --set on the base case
    std::vector<VaryRange> ranges;     // as parsed (integer and base filled in by prepare_search)
    std::vector<std::string> metrics;  // empty: every limited metric of the case
    std::uint64_t seeds = 0;           // per point; 0: the case's own seed (or its `seeds:`)
    SearchOptions options;
    std::filesystem::path search_file;  // where the request was read from; empty: the command line
};

// A `search:` file (named NAME.search.yaml, harness/spec/case_spec.h is_search_file):
//   search:
//     case: continuation.yaml              # relative to this file
//     vary: [ "vehicle.speed_km_h=3:12", "controller.positioning=gnss,fusion" ]
//     metrics: [ overlap_m ]               # optional; default every limited metric
//     set: [ "controller.threshold_m=5" ]  # optional, as --set
//     budget: 60                           # optional, as the command line's defaults
//     seeds: 1
//     method: crs2
//     start: 0
//     search_seed: 1
//     first: false
// Throws rig::ConfigError at file:line:col naming the key.
FalsifyRequest read_search_file(const std::filesystem::path& path);

struct PreparedSearch {
    FalsifyCase search_case;
    CaseSpec base;           // the base case with --set, as loaded
    std::string base_text;   // its file as written
};

// Throws rig::ConfigError or std::invalid_argument naming what is wrong and where.
PreparedSearch prepare_search(const FalsifyRequest& request, const RunOptions& options);

}  // namespace rig::harness
