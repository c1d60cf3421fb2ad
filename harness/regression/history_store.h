#pragma once
// The history database of `rig history` (docs/history.md): one SQLite file a
// CI keeps as an artifact or in a cache, holding every run's value of every
// metric per (branch, commit, case, seed), so that a controller's metrics can
// be followed over its commits and a step in them found.
//
// Tables (schema version kHistorySchemaVersion, in `history_schema`):
//   entries(id, branch, commit_sha, commit_order, date, source, kind,
//           rig_version, rig_commit)           one per `rig history add`
//   cases(entry_id, case_name, file)
//   limits(entry_id, case_name, metric, value)        the case's limits then
//   min_effects(entry_id, case_name, metric, value)   its compare.min_effect
//   runs(entry_id, case_name, seed, run, passed, error, trace_sha256,
//        case_sha256, controller_sha256, controller_config_sha256)
//   metric_values(entry_id, case_name, seed, metric, value, not_measured)
//        value NULL when the run gave none (not_measured says why)
//
// Commits are ordered per branch by `commit_order`: one more than the
// branch's highest when added (insertion order, as a CI adds each commit it
// builds), or the number given (`--order`, e.g. `git rev-list --count HEAD`,
// when jobs may finish out of order). The date is only shown, never used to
// order: it comes from `--date` or the output's started_utc.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/regression/run_samples.h"

namespace rig::harness {

inline constexpr int kHistorySchemaVersion = 1;

// The database cannot be read as a history (missing, not SQLite, another
// schema): `rig history` exits 2 on it.
struct HistoryUnreadable : std::runtime_error {
    using std::runtime_error::runtime_error;
};
// The entry was refused (its commit or order is taken on the branch) or could
// not be written (a full disk); the database is as it was: exit 1.
struct HistoryNotAdded : std::runtime_error {
    using std::runtime_error::runtime_error;
};

struct HistoryEntryOptions {
    std::string commit;  // 4 to 64 hex digits (stored in lower case)
    std::string branch = "main";
    std::optional<std::int64_t> order;  // none: after the branch's newest
    std::string date;                   // none: the output's started_utc, if it has one
    bool replace = false;               // replace the commit's entry on the branch (keeping its order unless given)
};

struct HistoryAdded {
    std::int64_t order = 0;
    std::string date;
    bool replaced = false;
    bool created = false;  // the database file was made by this add
    std::size_t cases = 0, runs = 0, values = 0;
};

// Adds the runs of one output as the entry of (branch, commit), creating the
// database when `database` does not exist. All in one transaction: on any
// error nothing is added, and a file this call created is removed again.
// Throws HistoryUnreadable, HistoryNotAdded, or std::invalid_argument for bad
// options (a commit that is not hex, a negative order, a date not ISO 8601).
HistoryAdded add_to_history(const std::filesystem::path& database, const RunSamples& samples,
                            const HistoryEntryOptions& options);

struct HistoryCommit {
    std::string commit;
    std::int64_t order = 0;
    std::string date;
    std::string source;  // the results.json or sweep.json it was added from
    std::string kind;    // "run" or "sweep"
    std::string rig_version, rig_commit;
    // The controller under test's digests at this commit, over the entry's runs
    // ("" when the output did not record them, "mixed" when its runs differ).
    std::string controller_sha256, controller_config_sha256;
};

// One run's value of a metric: none when the run did not measure it.
struct SeedValue {
    std::uint64_t seed = 0;
    std::optional<double> value;
};

// A metric of a case at one commit: every seed's value, and what the case said then.
struct HistoryPoint {
    std::size_t commit_index = 0;  // into BranchHistory::commits
    std::vector<SeedValue> seeds;  // by seed
    std::optional<double> limit;
    std::optional<double> case_min_effect;
};

struct HistorySeries {
    std::string case_name, metric;
    std::vector<HistoryPoint> points;  // by commit order, only commits that had the case and metric
};

struct BranchHistory {
    std::string branch;
    std::vector<HistoryCommit> commits;  // by order
    std::vector<HistorySeries> series;   // by case, then metric
};

struct History {
    std::filesystem::path database;
    std::vector<BranchHistory> branches;  // by name
    std::string newest_branch;            // the branch of the entry added last
};

// Reads the whole database, opened read-only (nothing is created or changed).
// Throws HistoryUnreadable naming the file and what is wrong.
History read_history(const std::filesystem::path& database);

}  // namespace rig::harness
