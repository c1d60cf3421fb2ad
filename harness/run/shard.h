#pragma once
// `rig run --shard I/N` (a CI's own parallelism: a GitLab `parallel:` job, a
// Jenkins matrix cell): runs the cases of shard I of N. A case's shard comes
// from its name alone (FNV-1a 64 of the name, modulo N), so it stays in its
// shard when cases are added, removed or listed in another order, and every
// case is in exactly one shard. `rig merge` joins the shards' outputs
// (harness/commands/judge_command.h).
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

}  // namespace rig::harness
