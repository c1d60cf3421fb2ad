#include "harness/run/shard.h"

#include <charconv>
#include <stdexcept>

namespace rig::harness {

namespace {
constexpr int kMostShards = 1000;

int whole_number(const std::string& text, const std::string& part) {
    int value = 0;
    const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), value);
    if (part.empty() || error != std::errc() || end != part.data() + part.size()) {
        throw std::invalid_argument("--shard '" + text + "': '" + part + "' is not a whole number (I/N, e.g. 2/4)");
    }
    return value;
}
}  // namespace

Shard parse_shard(const std::string& text) {
    const std::size_t slash = text.find('/');
    if (slash == std::string::npos) throw std::invalid_argument("--shard '" + text + "': not I/N (e.g. 2/4)");
    Shard shard{whole_number(text, text.substr(0, slash)), whole_number(text, text.substr(slash + 1))};
    if (shard.count < 1 || shard.count > kMostShards || shard.index < 1 || shard.index > shard.count) {
        throw std::invalid_argument("--shard '" + text + "': needs 1 <= I <= N <= " + std::to_string(kMostShards));
    }
    return shard;
}

int shard_of(const std::string& case_name, int count) {
    // FNV-1a, 64 bit: a fixed function of the name's bytes, the same on every machine.
    std::uint64_t hash = 0xcbf29ce484222325ULL;
    for (const unsigned char byte : case_name) {
        hash ^= byte;
        hash *= 0x100000001b3ULL;
    }
    return static_cast<int>(hash % static_cast<std::uint64_t>(count)) + 1;
}

int shard_of_run(std::size_t run_index, int count) {
    return static_cast<int>(run_index % static_cast<std::size_t>(count)) + 1;
}

}  // namespace rig::harness
