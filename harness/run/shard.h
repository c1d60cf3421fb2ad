#pragma once
// `rig run --shard I/N` (a CI's own parallelism: a GitLab `parallel:` job, a
// Jenkins matrix cell): runs the cases of shard I of N. A case's shard comes
// from its name alone (FNV-1a 64 of the name, modulo N), so it stays in its
// shard when cases are added, removed or listed in another order, and every
// case is in exactly one shard. `rig merge` joins the shards' outputs
// (harness/commands/judge_command.h).
//
// `rig sweep --shard I/N` shards runs instead: a sweep is few cases over many
// seeds, so shards of whole cases would be as many as its cases and as uneven
// as their lengths. Run k (0-based) of the sweep's runs, in expand_runs()
// order (each case over every seed, case after case), is in shard k mod N + 1:
// shards differ by one run at most, and each holds about 1/N of every case's
// seeds, so their wall times match too. The order comes from the command line,
// the same in every job of a CI matrix; the merge checks that every shard ran
// the same cases and seeds, and holds exactly its runs (harness/report/sweep_shard.h).
#include <cstddef>
#include <cstdint>
#include <string>

namespace rig::harness {

struct Shard {
    int index = 1;  // 1..count
    int count = 1;
};

// "I/N" with 1 <= I <= N <= 1000; throws std::invalid_argument naming the text.
Shard parse_shard(const std::string& text);
// Which of N shards (1..N) a case of this name belongs to.
int shard_of(const std::string& case_name, int count);
inline bool in_shard(const std::string& case_name, const Shard& shard) {
    return shard_of(case_name, shard.count) == shard.index;
}
// Which of N shards (1..N) run k (0-based) of a sweep belongs to.
int shard_of_run(std::size_t run_index, int count);
inline bool run_in_shard(std::size_t run_index, const Shard& shard) {
    return shard_of_run(run_index, shard.count) == shard.index;
}

}  // namespace rig::harness
