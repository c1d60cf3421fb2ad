#pragma once
// Records every topic of a run to one SQLite file per case (open it with
// `sqlite3 trace.sqlite`, or any SQLite browser): table `samples(t_ns, round,
// topic, json)` in the exact order the lockstep rounds delivered them, plus
// per-topic views and a `meta` table. The SHA-256 of the canonical rows
// ("t_ns round topic json\n") is the case's trace_sha256: same case + same seed
// => same digest, bit for bit.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "emulators/deposition_grid.h"
#include "rig/clock.h"
#include "rig/dds_context.h"

struct sqlite3;
struct sqlite3_stmt;
struct evp_md_ctx_st;

namespace rig::harness {

class TraceRecorder {
public:
    TraceRecorder(DdsContext& dds, const std::filesystem::path& file);
    ~TraceRecorder();
    TraceRecorder(const TraceRecorder&) = delete;
    TraceRecorder& operator=(const TraceRecorder&) = delete;

    void set_meta(const std::string& key, const std::string& value);
    // Takes every sample that arrived and records it at (t, round).
    void drain(TimeNs t, int round);
    // Writes the plant's deposition grid (table `deposition`); part of the digest.
    void record_deposition(const emulators::DepositionGrid& grid);
    // Commits and closes the file; returns the hex SHA-256 of the trace.
    std::string finish();

    // Every sample recorded so far, by topic, for metric computation: (t, json).
    const std::vector<std::pair<TimeNs, nlohmann::json>>& samples(const std::string& topic) const;

private:
    struct Channel {
        std::string topic;
        std::function<std::vector<nlohmann::json>()> take;
    };
    template <class Msg>
    void add_channel(DdsContext& dds, const char* topic);
    void append(TimeNs t, int round, const std::string& topic, const nlohmann::json& json);

    std::vector<Channel> channels_;  // drained in this fixed order
    std::vector<std::shared_ptr<void>> readers_;
    std::map<std::string, std::vector<std::pair<TimeNs, nlohmann::json>>> by_topic_;
    sqlite3* db_ = nullptr;
    sqlite3_stmt* insert_ = nullptr;
    evp_md_ctx_st* digest_ = nullptr;
    std::string sha256_;
};

}  // namespace rig::harness
