#pragma once
// The case's wire faults (emulators/wire_faults.h) between the run and the
// judge: what the run injected goes into the trace, and the judge reports it
// beside what the trace itself shows, as metrics in results.json:
//
//   GNSS (gnss.wire_faults; meta `gnss_wire_faults`, only when a rate is on)
//     gnss_sentences_count            sentences on device/gnss/nmea (what the wire carried)
//     gnss_bad_sentences_count        of them, those the rig's NMEA parser rejects
//     gnss_damaged_sentences_count    sentences the faults damaged (injected), of which
//     gnss_lost_sentences_count         every byte lost: nothing on the wire
//     gnss_damaged_sentences_parsed_count  damaged and still well-formed with a right
//                                     checksum (NMEA's XOR misses two equal lost bytes)
//     gnss_bytes_lost_count, gnss_corrupt_checksums_count, gnss_truncated_sentences_count
//     controller_nmea_rejected_count  the controller's own count (its last status), when it publishes one
// The Modbus RTU line's noise (board.line_noise) is the session's: its counts
// are in results.json's board_io block (harness/session/line_noise.h).
#include <cstdint>

#include <nlohmann/json.hpp>

#include "emulators/wire_faults.h"
#include "harness/judge/metric_set.h"
#include "harness/systems/breakpoint/breakpoint_case.h"
#include "harness/trace/trace_reader.h"

namespace rig::harness {

// The trace's meta key for the GNSS faults.
inline constexpr const char* kGnssWireFaultsMeta = "gnss_wire_faults";

emulators::NmeaWireFaultRates nmea_wire_fault_rates(const GnssWireFaultsSpec& spec);
// {"rates": {...pct}, "injected": {...counts}} for the trace's meta.
nlohmann::json gnss_wire_fault_json(const GnssWireFaultsSpec& spec, const emulators::NmeaWireFaultCounts& counts);

// The metrics above from a trace with meta `gnss_wire_faults`; none without it.
// Throws std::runtime_error for a malformed meta value.
MetricSet gnss_wire_fault_metrics(const RecordedTrace& trace);

}  // namespace rig::harness
