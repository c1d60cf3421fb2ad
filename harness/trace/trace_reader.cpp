#include "harness/trace/trace_reader.h"

#include <sqlite3.h>

#include <stdexcept>

#include "harness/trace/sha256.h"
#include "harness/trace/trace_cdr.h"
#include "harness/trace/trace_file.h"

namespace rig::harness {

TraceReader::TraceReader(const std::filesystem::path& file) : file_(file) {
    std::error_code error;
    const auto status = std::filesystem::status(file, error);
    if (error || !std::filesystem::exists(status)) throw std::runtime_error("trace " + file.string() + ": no such file");
    if (!std::filesystem::is_regular_file(status)) {
        throw std::runtime_error("trace " + file.string() + ": not a regular file");
    }
    if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
        const std::string reason = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
        sqlite3_close(db_);
        db_ = nullptr;
        throw std::runtime_error("trace " + file.string() + ": cannot open: " + reason);
    }
}

TraceReader::~TraceReader() { sqlite3_close(db_); }

bool TraceReader::has_table(const std::string& table) {
    bool found = false;
    rows("SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = '" + table + "'",
         [&](sqlite3_stmt*) { found = true; });
    return found;
}

void TraceReader::rows(const std::string& sql, const std::function<void(sqlite3_stmt*)>& row) {
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &statement, nullptr) != SQLITE_OK) {
        const std::string reason = sqlite3_errmsg(db_);
        throw std::runtime_error("trace " + file_.string() + ": " + reason +
                                 " (not a trace of this rig, or from another version of it?)");
    }
    int rc = SQLITE_ROW;
    try {
        while ((rc = sqlite3_step(statement)) == SQLITE_ROW) row(statement);
    } catch (...) {
        sqlite3_finalize(statement);
        throw;
    }
    sqlite3_finalize(statement);
    if (rc != SQLITE_DONE) throw std::runtime_error("trace " + file_.string() + ": " + sqlite3_errmsg(db_));
}

std::string TraceReader::text(sqlite3_stmt* row, int column) {
    const unsigned char* text = sqlite3_column_text(row, column);
    return text == nullptr ? std::string()
                           : std::string(reinterpret_cast<const char*>(text),
                                         static_cast<std::size_t>(sqlite3_column_bytes(row, column)));
}

std::int64_t TraceReader::integer(sqlite3_stmt* row, int column) { return sqlite3_column_int64(row, column); }

double TraceReader::real(sqlite3_stmt* row, int column) { return sqlite3_column_double(row, column); }

std::vector<unsigned char> TraceReader::blob(sqlite3_stmt* row, int column) {
    const auto* bytes = static_cast<const unsigned char*>(sqlite3_column_blob(row, column));
    if (bytes == nullptr) return {};
    return {bytes, bytes + sqlite3_column_bytes(row, column)};
}

const std::vector<RecordedSample>& RecordedTrace::samples(const std::string& topic) const {
    static const std::vector<RecordedSample> none;
    if (const auto done = parsed_.find(topic); done != parsed_.end()) return done->second;
    const auto stored = rows.find(topic);
    if (stored == rows.end()) return none;
    const SampleCodec* codec = nullptr;
    if (const auto type = sample_types.find(topic); type != sample_types.end()) {
        codec = sample_codec_named(type->second);  // read_trace checked it is known
    }
    std::vector<RecordedSample> parsed;
    parsed.reserve(stored->second.size());
    for (const TraceRow& row : stored->second) {
        RecordedSample sample;
        sample.t_ns = row.t_ns;
        sample.round = row.round;
        try {
            if (row.cdr.empty()) {
                sample.json = nlohmann::json::parse(row.json_text);
            } else if (codec != nullptr) {
                sample.json = codec->json_value(row.cdr.data(), row.cdr.size());
            } else {
                throw std::runtime_error("CDR bytes on topic " + topic + ", which has no type in sample_types");
            }
        } catch (const std::exception& error) {
            throw std::runtime_error("trace " + file.string() + ": samples row " + std::to_string(row.rowid) + ": " +
                                     error.what());
        }
        parsed.push_back(std::move(sample));
    }
    return parsed_.emplace(topic, std::move(parsed)).first->second;
}

std::string RecordedTrace::meta_or(const std::string& key, const std::string& fallback) const {
    const auto it = meta.find(key);
    return it == meta.end() ? fallback : it->second;
}

RecordedTrace read_trace(const std::filesystem::path& file) {
    TraceReader reader(file);
    RecordedTrace trace;
    trace.file = file;
    reader.rows("SELECT key, value FROM meta",
                [&](sqlite3_stmt* row) { trace.meta[TraceReader::text(row, 0)] = TraceReader::text(row, 1); });
    // Format 2 (text only) is read as it always was; format 3 adds the bytes.
    const auto format = trace.meta.find("trace_format");
    int format_number = 0;
    for (int known = kOldestTraceFormatRead; known <= kTraceFormat; ++known) {
        if (format != trace.meta.end() && format->second == std::to_string(known)) format_number = known;
    }
    if (format_number == 0) {
        throw std::runtime_error("trace " + file.string() + ": trace format " +
                                 (format == trace.meta.end() ? std::string("unknown") : format->second) +
                                 ", this rig reads formats " + std::to_string(kOldestTraceFormatRead) + " to " +
                                 std::to_string(kTraceFormat) + " (run the case again)");
    }
    const bool with_bytes = format_number >= 3;
    if (with_bytes) {
        reader.rows("SELECT topic, type FROM sample_types", [&](sqlite3_stmt* row) {
            const std::string topic = TraceReader::text(row, 0);
            const std::string type = TraceReader::text(row, 1);
            if (sample_codec_named(type) == nullptr) {
                throw std::runtime_error("trace " + file.string() + ": sample_types gives topic " + topic +
                                         " the type " + type + ", which this rig does not know");
            }
            trace.sample_types[topic] = type;
        });
    }
    // Every row goes through the digest, in the canonical form TraceFile takes it over.
    Sha256 digest;
    Sha256 cdr_digest;
    reader.rows(with_bytes ? "SELECT t_ns, round, topic, json, rowid, cdr FROM samples ORDER BY rowid"
                           : "SELECT t_ns, round, topic, json, rowid FROM samples ORDER BY rowid",
                [&](sqlite3_stmt* row) {
                    TraceRow sample;
                    sample.t_ns = TraceReader::integer(row, 0);
                    sample.round = static_cast<int>(TraceReader::integer(row, 1));
                    const std::string topic = TraceReader::text(row, 2);
                    sample.json_text = TraceReader::text(row, 3);
                    sample.rowid = TraceReader::integer(row, 4);
                    add_sample_digest(digest, sample.t_ns, sample.round, topic, sample.json_text);
                    if (with_bytes) {
                        sample.cdr = TraceReader::blob(row, 5);
                        if (!sample.cdr.empty()) {
                            add_cdr_digest(cdr_digest, sample.t_ns, sample.round, topic, sample.cdr.data(),
                                           sample.cdr.size());
                        }
                    }
                    trace.rows[topic].push_back(std::move(sample));
                });
    reader.rows("SELECT pass, row, nozzle, dose_ul_cm2 FROM deposition ORDER BY rowid", [&](sqlite3_stmt* row) {
        RecordedDepositionCell cell;
        cell.pass = static_cast<int>(TraceReader::integer(row, 0));
        cell.row = static_cast<std::size_t>(TraceReader::integer(row, 1));
        cell.nozzle = static_cast<int>(TraceReader::integer(row, 2));
        cell.dose_ul_cm2 = TraceReader::real(row, 3);
        add_deposition_digest(digest, cell.pass, cell.row, cell.nozzle, cell.dose_ul_cm2);
        trace.deposition.push_back(cell);
    });
    reader.rows("SELECT t_ns, landing FROM landing_edges ORDER BY rowid", [&](sqlite3_stmt* row) {
        const RecordedLandingEdge edge{TraceReader::integer(row, 0), TraceReader::integer(row, 1) != 0};
        add_landing_digest(digest, edge.t_ns, edge.landing);
        trace.landing_edges.push_back(edge);
    });
    trace.recomputed_sha256 = digest.hex();
    trace.recomputed_cdr_sha256 = cdr_digest.hex();
    reader.rows("SELECT t_ns, participant, guid_prefix, endpoint, topic, event FROM discovery ORDER BY rowid",
                [&](sqlite3_stmt* row) {
                    trace.discovery.push_back(RecordedDiscovery{
                        TraceReader::integer(row, 0), TraceReader::text(row, 1), TraceReader::text(row, 2),
                        TraceReader::text(row, 3), TraceReader::text(row, 4), TraceReader::text(row, 5)});
                });
    reader.rows("SELECT t_ns, topic, participant FROM foreign_samples ORDER BY rowid", [&](sqlite3_stmt* row) {
        trace.foreign_samples.push_back(RecordedForeignSample{TraceReader::integer(row, 0), TraceReader::text(row, 1),
                                                              TraceReader::text(row, 2)});
    });
    return trace;
}

}  // namespace rig::harness
