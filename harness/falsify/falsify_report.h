#pragma once
// What `rig falsify` writes (issue 30, docs/falsify.md): falsify.json (every
// point: its values, each seed's metrics and digest, its margin), worst.yaml
// (the base case with the worst point's values written in, runnable as it
// is), falsify.html (the margin over each parameter and each pair, the
// limit's contour, the falsifying points marked) and the summary line.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "harness/falsify/case_evaluator.h"
#include "harness/falsify/falsify_search.h"

namespace rig::harness {

inline constexpr int kFalsifySchemaVersion = 1;

// A finished search, as the outputs need it.
struct FalsifyRecord {
    FalsifyCase search_case;
    std::string base_text;          // the base case file as written (before --set)
    std::filesystem::path search_file;  // the `search:` file it came from; empty: the command line
    SearchOptions options;
    SearchOutcome outcome;
    std::vector<PointRuns> point_runs;  // point_runs[i] is outcome.points[i]'s
    std::uint64_t case_seed = 1;        // the seed the base case runs with (`seed:`)
    bool case_writes_seed = false;      // whether the file writes `seed:` (worst.yaml can set it)
    bool case_has_seed_list = false;    // the file has `seeds:` (each seed is its own run)
    double wall_seconds = 0.0;
};

// How many runs the search made (points that ran times seeds).
std::size_t runs_made(const FalsifyRecord& record);

nlohmann::json falsify_json(const FalsifyRecord& record);

// The worst point's settings for worst.yaml: its values, and the seed of its
// worst run when the search ran several and the file writes `seed:`.
std::vector<KeySetting> worst_settings(const FalsifyRecord& record);
// worst.yaml: the base case's text with worst_settings() written in, after a
// comment saying where it came from. Empty when no point has a worst (every
// one was invalid).
std::string worst_case_text(const FalsifyRecord& record);

// One line: FALSIFIED and where, or that none was found and the smallest margin.
std::string falsify_summary(const FalsifyRecord& record, const std::filesystem::path& out_dir);

// falsify.html's text; problems drawing its figures go into `problems`.
std::string falsify_html(const FalsifyRecord& record, std::vector<std::string>& problems);

}  // namespace rig::harness
