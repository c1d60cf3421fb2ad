#pragma once
// Reading a trace file (docs/trace-format.md; harness/trace/trace_file.h
// writes one). TraceReader is the one way the rig opens a trace: read_trace()
// reads a whole one for the judge through it, and `rig mcap` streams its rows
// through it. Nothing here knows a system: the samples stay as stored until a
// judge asks for a topic's, then become JSON values straight from their CDR
// bytes (harness/trace/trace_cdr.h; text is parsed only for a row that has no
// bytes: a format 2 trace, a hand-made one), and the deposition and
// landing-edge rows are the tables' own.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rig/runtime/clock.h"

struct sqlite3;
struct sqlite3_stmt;

namespace rig::harness {

// A trace opened read-only. Throws std::runtime_error naming the file: no such
// file, not a regular file, not an SQLite database.
class TraceReader {
public:
    explicit TraceReader(const std::filesystem::path& file);
    ~TraceReader();
    TraceReader(const TraceReader&) = delete;
    TraceReader& operator=(const TraceReader&) = delete;

    const std::filesystem::path& file() const { return file_; }
    bool has_table(const std::string& table);
    // Runs `sql`, calling `row` with each result row's statement; a statement
    // SQLite refuses (a table this trace lacks) throws naming the file.
    void rows(const std::string& sql, const std::function<void(sqlite3_stmt*)>& row);
    // Column values of a row.
    static std::string text(sqlite3_stmt* row, int column);
    static std::int64_t integer(sqlite3_stmt* row, int column);
    static double real(sqlite3_stmt* row, int column);
    static std::vector<unsigned char> blob(sqlite3_stmt* row, int column);  // empty for NULL

private:
    std::filesystem::path file_;
    sqlite3* db_ = nullptr;
};

// A sample of the trace's `samples` table, parsed.
struct RecordedSample {
    TimeNs t_ns = 0;
    int round = 0;
    nlohmann::json json;
};

// The same as stored: its JSON text, its CDR bytes (none when stored as text
// only) and where it is (for errors).
struct TraceRow {
    TimeNs t_ns = 0;
    int round = 0;
    std::int64_t rowid = 0;
    std::string json_text;
    std::vector<unsigned char> cdr;
};

struct RecordedDiscovery {
    TimeNs t_ns = 0;
    std::string participant;
    std::string guid_prefix;
    std::string endpoint;  // reader | writer
    std::string topic;
    std::string event;     // discovered | removed
};

struct RecordedForeignSample {
    TimeNs t_ns = 0;
    std::string topic;
    std::string participant;
};

// One cell of the `deposition` table (seed 000's spray on the ground).
struct RecordedDepositionCell {
    int pass = 0;
    std::size_t row = 0;
    int nozzle = 0;
    double dose_ul_cm2 = 0.0;
};

// One row of the `landing_edges` table: spray started (landing) or stopped reaching the ground.
struct RecordedLandingEdge {
    TimeNs t_ns = 0;
    bool landing = false;
};

// What the judge reads of a trace.
class RecordedTrace {
public:
    std::filesystem::path file;
    std::map<std::string, std::string> meta;
    std::map<std::string, std::vector<TraceRow>> rows;  // every topic's samples, in delivery order
    std::map<std::string, std::string> sample_types;    // topic -> the IDL type of its rows' bytes
    std::vector<RecordedDepositionCell> deposition;    // in the order written
    std::vector<RecordedLandingEdge> landing_edges;
    std::vector<RecordedDiscovery> discovery;
    std::vector<RecordedForeignSample> foreign_samples;
    // The digest recomputed from the tables (samples, deposition, landing edges),
    // to compare with meta's trace_sha256: a trace changed after its run differs.
    std::string recomputed_sha256;
    // The same for the samples' bytes, to compare with meta's cdr_sha256 (format 3).
    std::string recomputed_cdr_sha256;

    // The samples of `topic` parsed, in delivery order (none when it has none).
    // Parsed on first use and kept: a judge reads only the topics it judges.
    // Throws std::runtime_error naming the file and the row of malformed JSON or CDR.
    // Not for several threads at once.
    const std::vector<RecordedSample>& samples(const std::string& topic) const;
    // meta[key], or `fallback` when the trace has no such key.
    std::string meta_or(const std::string& key, const std::string& fallback = {}) const;

private:
    mutable std::map<std::string, std::vector<RecordedSample>> parsed_;
};

// Reads a trace written by TraceFile. Throws std::runtime_error naming the
// file and what is wrong (not SQLite, another trace format, a missing table or
// meta key).
RecordedTrace read_trace(const std::filesystem::path& file);

}  // namespace rig::harness
