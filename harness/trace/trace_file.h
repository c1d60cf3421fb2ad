#pragma once
// A trace file (SQLite; docs/trace-format.md): the rows of a run and the judge's
// only input. TraceFile writes one; TraceRecorder (harness/trace/trace_recorder.h)
// feeds it from DDS during a run, and tests write hand-made traces with it to
// judge them (harness/judge/judge_trace.h) without any DDS.
//   samples(t_ns, round, topic, json, cdr)  every sample, in delivery order:
//                                       its JSON text, and its CDR bytes when
//                                       recorded from its IDL type
//   sample_types(topic, type)           the IDL type of each topic's bytes
//   deposition, landing_edges           the spray on the ground (plant truth)
//   discovery                           endpoints other participants created
//   foreign_samples                     truth/device samples others wrote (forged)
//   meta                                the case, the judging plan, the outcome
// The SHA-256 of the canonical rows ("t_ns round topic json\n" per sample in
// order, then "deposition pass row nozzle dose\n" per cell and "landing t_ns
// 0|1\n" per edge) is the trace's digest; `rig judge` recomputes it from the
// tables. Discovery, forged samples and meta are not part of it (discovery's
// timing is the machine's, not the simulation's; a forged sample fails the run).
//
// Rows are committed in batches as they come (write-ahead log), so a rig killed
// mid-run leaves a readable file up to the last batch; finish() writes the
// outcome and the digest into meta and folds the log back into the one file.
//
// Samples are written off the lockstep round's critical path: append_sample()
// queues the sample's CDR bytes (harness/trace/trace_cdr.h; no text on the
// loop). Two threads of the file's own take them in the order queued, a batch
// at a time: one renders each sample's JSON text and adds it to the digests
// (so the digest is the same), the other inserts the rendered batch into
// SQLite. Each is about half of the work, so on a machine with a core to
// spare the two halves overlap (docs/speed.md). Every other call first waits
// for both to drain, so the file is only ever touched by one thread at a time;
// all calls come from the thread that runs the case. A write that fails (a
// full disk) is reported by the next call, naming the file.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/trace/sha256.h"
#include "harness/trace/trace_cdr.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/dds_context.h"

struct sqlite3;
struct sqlite3_stmt;

namespace rig::harness {

// Version of the trace layout (meta key `trace_format`); `rig judge` refuses
// traces it does not know how to read. Format 3 added the samples' CDR bytes
// (samples.cdr, sample_types, meta cdr_sha256); format 2 traces, text only,
// are still read and judged (their digest is the same kind).
inline constexpr int kTraceFormat = 3;
inline constexpr int kOldestTraceFormatRead = 2;

// How a case's run ended, for meta (keys `outcome`, `error_kind`, `error`, `end_ns`).
struct TraceOutcome {
    std::string status = "completed";  // completed | error | interrupted
    std::string error_kind;            // rig::FailureKind name when not completed
    std::string error;                 // what happened, naming the node
    TimeNs end_ns = 0;                 // the last simulated instant the run reached
};

// The canonical lines the digest is taken over (TraceFile adds them, the
// reader recomputes them: harness/trace/trace_reader.h), one per row:
// "t_ns round topic json\n", "deposition pass row nozzle dose\n" (the dose
// as nlohmann::json::dump() writes a double), "landing t_ns 0|1\n". Added
// piece by piece, with no line built in between (the rendering thread adds
// one per sample).
void add_sample_digest(Sha256& digest, TimeNs t, int round, std::string_view topic, std::string_view json_text);
void add_deposition_digest(Sha256& digest, int pass, std::size_t row, int nozzle, double dose_ul_cm2);
void add_landing_digest(Sha256& digest, TimeNs t, bool landing);
// What meta `cdr_sha256` is taken over for one sample stored as bytes: the line
// "t_ns round topic size\n", then the bytes. It shows a changed `cdr` column as
// trace_sha256 shows a changed `json` one (the judge reads the bytes).
void add_cdr_digest(Sha256& digest, TimeNs t, int round, std::string_view topic, const unsigned char* cdr,
                    std::size_t size);

// Spray on the ground for the `deposition` table (seed 000's grid along the
// track, harness/systems/breakpoint): its layout (meta `deposition_grid`) and
// the non-empty cells, in the order they go into the digest (pass, row, nozzle).
struct DepositionLayout {
    double first_row_centre_m = 0.0;
    double cell_along_m = 0.0;
    std::size_t rows = 0;
    int nozzle_count = 0;
    int passes = 0;
};
struct DepositionCell {
    int pass = 0;
    std::size_t row = 0;
    double along_m = 0.0;  // the row's centre
    int nozzle = 0;
    double dose_ul_cm2 = 0.0;
};
// When spray started (landing) or stopped reaching the ground (Table 1).
struct LandingEdgeRow {
    TimeNs t_ns = 0;
    bool landing = false;
};

class TraceFile {
public:
    // Creates the file (replacing one that is there). Throws std::runtime_error naming it.
    explicit TraceFile(const std::filesystem::path& file);
    // A file never finished is committed as "interrupted": what was written stays readable.
    ~TraceFile();
    TraceFile(const TraceFile&) = delete;
    TraceFile& operator=(const TraceFile&) = delete;

    const std::filesystem::path& path() const { return file_; }
    void set_meta(const std::string& key, const std::string& value);
    // Rows of a topic name it by its slot. A topic with a codec stores its
    // samples as bytes too (append_sample), its type in `sample_types`; one
    // without takes only JSON text (append_text, append). A topic has one type:
    // another codec for it throws std::logic_error.
    std::uint32_t topic_slot(const std::string& topic, const SampleCodec* codec = nullptr);
    // A sample of a topic whose slot has `Msg`'s codec. Only its CDR bytes are
    // made here; the rendering thread renders its JSON text.
    template <class Msg>
    void append_sample(TimeNs t, int round, std::uint32_t slot, const Msg& sample) {
        append_bytes(t, round, slot, &sample_codec<Msg>(), &sample);
    }
    // A sample as JSON text, exactly as nlohmann::json::dump() writes it (the
    // digest is taken over it; harness/trace/trace_json.h writes it so).
    void append_text(TimeNs t, int round, const std::string& topic, std::string json_text);
    // The same from a JSON value (hand-made traces, tests).
    void append(TimeNs t, int round, const std::string& topic, const nlohmann::json& json) {
        append_text(t, round, topic, json.dump());
    }
    // Text is not a JSON value: it would be stored as one JSON string (append_text takes text).
    void append(TimeNs t, int round, const std::string& topic, const std::string& json_text) = delete;
    void append_foreign(TimeNs t, int round, const std::string& topic, const std::string& participant,
                        const std::string& guid_prefix, const std::string& json_text);
    void record_discoveries(TimeNs t, const std::vector<DiscoveredEndpoint>& endpoints);
    void record_deposition(const DepositionLayout& layout, const std::vector<DepositionCell>& cells);
    void record_landing_edges(const std::vector<LandingEdgeRow>& edges);
    // Outcome and digest into meta, commit, close; returns the hex SHA-256.
    // Later calls return the same digest.
    std::string finish(const TraceOutcome& outcome);
    bool finished() const { return db_ == nullptr && !sha256_.empty(); }
    std::uint64_t sample_count() const { return rows_; }
    // The last instant a sample was appended at (for an unfinished file's end).
    TimeNs last_t_ns() const { return last_t_ns_; }

private:
    struct PendingRow {
        TimeNs t = 0;
        int round = 0;
        std::uint32_t slot = 0;
        bool binary = false;          // CDR bytes in the queue's bytes, else json_text
        std::uint32_t cdr_size = 0;
        std::size_t cdr_offset = 0;
        std::string json_text;
    };
    struct Topic {
        std::string name;
        const SampleCodec* codec = nullptr;
    };
    // Rows taken off the queue together, with their CDR bytes and, once
    // rendered, each row's JSON text (a text row's is in the row itself).
    // Batches are reused: a steady run allocates no new ones.
    struct Batch {
        std::vector<PendingRow> rows;
        std::vector<unsigned char> bytes;
        std::vector<std::string> rendered;  // per row; empty for a text row
    };
    void append_bytes(TimeNs t, int round, std::uint32_t slot, const SampleCodec* codec, const void* sample);
    // Waits for room in the queue (under queue_mutex_); throws the writer's error.
    void wait_for_room(std::unique_lock<std::mutex>& lock);
    // Records the first SQLite error (see first_error_), then throws it naming the file.
    [[noreturn]] void fail(const std::string& sqlite_error);
    void exec(const char* sql);
    // On the rendering thread: each row's text, into the digests.
    void render_batch(Batch& batch);
    // On the storing thread: the rendered rows into `samples`.
    void store_batch(const Batch& batch);
    void render_loop();
    void store_loop();
    // Records a thread's error (the first one) for the caller's next call.
    void keep_writer_error(const std::string& error);
    // Until every queued row is written; throws the writer's error, if any.
    void sync();
    void stop_writer() noexcept;

    std::filesystem::path file_;
    sqlite3* db_ = nullptr;
    sqlite3_stmt* insert_ = nullptr;
    Sha256 digest_;
    Sha256 cdr_digest_;
    // Slot -> topic; grown only while both writer threads are idle (after sync()).
    std::vector<Topic> topics_;
    std::uint64_t rows_ = 0;
    std::uint64_t rows_in_batch_ = 0;
    TimeNs last_t_ns_ = 0;
    std::string digest_text_;  // the digest, once computed (finish may be retried)
    std::string cdr_digest_text_;
    std::string sha256_;       // set once the file is closed

    // The two writer threads and their queues (bounded: a slow disk slows the
    // run down rather than filling memory).
    std::mutex queue_mutex_;
    std::condition_variable queued_;    // rows to render, or stop
    std::condition_variable rendered_;  // a batch to store, or rendering ended
    std::condition_variable drained_;   // a thread went idle, or room in a queue
    std::vector<PendingRow> queue_;
    std::vector<unsigned char> queue_bytes_;  // the queued rows' CDR, back to back
    std::deque<Batch> to_store_;        // rendered, in order
    std::vector<Batch> spare_batches_;  // stored, their buffers kept
    bool rendering_ = false;            // the rendering thread holds a batch
    bool storing_ = false;              // the storing thread holds a batch
    bool rendering_ended_ = false;      // stopping, and every row rendered
    bool stopping_ = false;
    bool flush_ = false;               // sync() waits: write whatever is queued
    std::string writer_error_;
    // The first SQLite error on either thread, kept for finish(): a write that
    // failed on the caller's thread (a discovery row on a full disk) is caught
    // by the run, and without it finish() could only say "a write failed".
    std::string first_error_;
    std::thread renderer_;
    std::thread storer_;
};

}  // namespace rig::harness
