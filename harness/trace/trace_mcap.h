#pragma once
// A run's trace as MCAP (harness/trace/mcap_writer.h), so Foxglove or PlotJuggler
// open it: one channel per topic of the trace's `samples` (the topic's name,
// JSON messages as the trace stores them, a JSON Schema of the fields seen on
// it), the samples that other participants forged on `truth/*` or `device/*`
// on channels of their own (`foreign/<participant>/<topic>`), and the trace's
// `meta` as a Metadata record. Log time = the sample's simulated time t_ns
// (case time: Foxglove shows it counted from 1970-01-01); publish time the same.
//
//   rig mcap OUT_DIR|TRACE... [--out FILE]     (harness/commands/mcap_command.h, docs/trace-format.md "MCAP")
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace rig::harness {

struct TraceMcapSummary {
    std::uint64_t messages = 0;
    std::size_t channels = 0;
};

// Writes `trace`'s samples into `mcap` (replacing it); throws std::runtime_error
// naming the file and what went wrong (not a trace, unwritable output).
TraceMcapSummary write_trace_mcap(const std::filesystem::path& trace, const std::filesystem::path& mcap);

// The JSON Schema (draft 2020-12) that every one of `samples` (JSON texts)
// satisfies: objects by property, arrays by item, a type list where a field
// takes more than one (e.g. ["number", "null"]).
std::string json_schema_of(const std::vector<std::string>& samples, const std::string& title);

}  // namespace rig::harness
