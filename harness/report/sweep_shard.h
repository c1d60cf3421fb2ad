#pragma once
// `rig sweep --shard I/N` and `rig merge` of its outputs (docs/running-cases.md
// "Sharding a sweep"): a sweep of a whole suite over many seeds spread over
// the jobs of a CI matrix, joined into the sweep.json, sweep.txt and sweep.html
// one machine would have written.
//
// A shard's sweep.json is a sweep of the runs it holds (harness/run/shard.h
// shard_of_run), with the whole sweep's seed list, plus a "shard" object:
// which shard of how many, how many runs the whole sweep has, and what the
// bands of the whole sweep need that a sweep.json does not otherwise keep:
// each case's paper numbers and each held run's limits, simulated seconds and
// error kinds. The merge keeps each run's entry in
// `cases[].seeds` as its shard wrote it, and computes the bands, pass rates
// and totals again from every run, in the order one machine runs them, so
// they come out bit for bit.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/report/sweep.h"
#include "harness/run/case_runner.h"
#include "harness/run/shard.h"
#include "harness/spec/case_spec.h"

namespace rig::harness {

// The "shard" object of a shard's sweep.json: `held[i]` is the run `results[i]`
// came from; `runs_in_sweep` counts every shard's runs.
nlohmann::json sweep_shard_json(const Shard& shard, const std::vector<CaseSpec>& specs, std::size_t runs_in_sweep,
                                const std::vector<CaseInstance>& held, const std::vector<CaseResult>& results);

// sweep.json, sweep.txt and sweep.html in `out_dir`, each replaced whole
// (harness/output/atomic_file.h); throws what the disk refused.
void write_sweep_files(const std::filesystem::path& out_dir, const nlohmann::json& json, const std::vector<CaseSweep>& cases,
                       const SweepInfo& info);

// One shard's output directory and its sweep.json.
struct SweepShardOutput {
    std::filesystem::path dir;
    nlohmann::json sweep;
};

struct MergedSweep {
    nlohmann::json json;  // sweep.json
    std::vector<CaseSweep> cases;
    SweepInfo info;
    std::size_t runs = 0;
    // Per shard, in the order given, the runs it holds (their cases/RUN/ go
    // into the merged directory).
    std::vector<std::vector<std::string>> runs_of_shard;
};

// The shards joined. The wall-clock fields are the only ones one machine's
// sweep would have written otherwise: started_utc is the earliest shard's
// start, wall_seconds the sum of the shards' (the machine time the sweep
// took, whatever the CI ran at once). Throws std::runtime_error naming the
// directory when the shards are not every shard of one sweep: a shard missing
// or given twice, a sweep without --shard, or shards of other cases, seeds,
// options or rig versions.
MergedSweep merge_sweep_shards(const std::vector<SweepShardOutput>& shards);

}  // namespace rig::harness
