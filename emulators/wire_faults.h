#pragma once
// Faults of the wires themselves, as case parameters (issue 14 item 4), in the
// way ArduPilot's simulated GPS has byte-loss and glitch parameters: what a
// noisy RS232 line or a receiver with an overrun UART does to the bytes, never
// to the truth. Each fault is a rate, off (0) by default, drawn from the case
// seed on a stream of its own (emulators/seeded_random.h), so that turning
// one on changes no other random number of the case.
//
//   NmeaWireFaults  the G970II's sentences as they leave the receiver
//                   (device/gnss/nmea, and so the serial line that carries it)
//   RtuLineNoise    the Modbus RTU slave's responses as they go on the line
//                   (rig/wire/modbus_slave.h RtuSlaveOptions::damage_response)
//
// Every fault is counted; the counts go into the trace and results.json.
#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "emulators/seeded_random.h"

namespace rig::emulators {

// Rates of the NMEA wire faults, in percent; each in [0, 100], 0 = off.
struct NmeaWireFaultRates {
    // Each byte of a sentence is lost with this probability (a UART overrun,
    // a dropped character on a noisy line): ArduPilot's SIM_GPS_BYTELOSS.
    double byte_loss_pct = 0.0;
    // Each sentence has its two checksum digits replaced by a wrong value with
    // this probability (a receiver or line that garbles the checksum).
    double corrupt_checksum_pct = 0.0;
    // Each sentence is cut off with this probability somewhere between its '$'
    // and its checksum's last digit, the rest (and CR LF) never sent: a
    // receiver that stops writing mid-sentence (a buffer overrun, a reset).
    double truncate_pct = 0.0;

    bool any() const { return byte_loss_pct > 0.0 || corrupt_checksum_pct > 0.0 || truncate_pct > 0.0; }
};

struct NmeaWireFaultCounts {
    std::uint64_t sentences = 0;             // sentences offered to the wire
    std::uint64_t sentences_damaged = 0;     // with at least one fault
    std::uint64_t sentences_lost = 0;        // every byte lost: nothing on the wire
    // Damaged in their text (not only in CR LF) and still accepted by the rig's
    // NMEA parser: well-formed, with a checksum that matches (NMEA's XOR
    // checksum cannot see two lost bytes of equal value, for instance).
    std::uint64_t sentences_damaged_parsed = 0;
    std::uint64_t bytes_lost = 0;
    std::uint64_t checksums_corrupted = 0;
    std::uint64_t sentences_truncated = 0;
};

// Applies the rates to each sentence in turn. Deterministic: the same seed and
// the same sentences give the same output, byte for byte. Draws nothing for a
// rate that is 0, and nothing at all when every rate is 0.
class NmeaWireFaults {
public:
    // The stream of the G970II's wire faults (the receiver's own noise is "gnss_g970").
    static constexpr std::string_view kStreamName = "gnss_g970.wire_faults";

    // Throws std::invalid_argument for a rate outside [0, 100] (or NaN).
    NmeaWireFaults(const NmeaWireFaultRates& rates, std::uint64_t seed);

    // The bytes that reach the wire for `sentence` ("$...*HH\r\n"); empty when
    // every byte was lost. Order: truncation, then the checksum (when it is
    // still there), then byte loss over what is left.
    std::string apply(std::string_view sentence);

    const NmeaWireFaultRates& rates() const { return rates_; }
    const NmeaWireFaultCounts& counts() const { return counts_; }

private:
    bool happens(double pct);
    NmeaWireFaultRates rates_;
    SeededRandom random_;
    NmeaWireFaultCounts counts_;
};

// Rates of the Modbus RTU line noise, in percent; each in [0, 100], 0 = off.
struct RtuLineNoiseRates {
    // Each response of the slave has one of its bytes hit (1 to 8 of its bits
    // flipped) with this probability: the master sees a CRC error.
    double corrupt_response_pct = 0.0;
    // After each response, a burst of 1 to 8 random bytes follows on the line
    // with this probability (a spike on the line between frames): the master
    // finds them in front of its next response.
    double noise_burst_pct = 0.0;

    bool any() const { return corrupt_response_pct > 0.0 || noise_burst_pct > 0.0; }
};

struct RtuLineNoiseCounts {
    std::uint64_t responses = 0;            // responses offered to the line
    std::uint64_t responses_corrupted = 0;
    std::uint64_t bits_flipped = 0;
    std::uint64_t noise_bursts = 0;
    std::uint64_t noise_bytes = 0;
};

// Applies the rates to each response frame in turn. Deterministic for a given
// seed and sequence of frames. Thread-safe: the slave's thread damages frames
// while the rig reads the counts.
class RtuLineNoise {
public:
    static constexpr std::string_view kStreamName = "modbus_rtu.line_noise";
    // Longest noise burst, bytes: a spike of a few character times.
    static constexpr int kMaxBurstBytes = 8;

    // Throws std::invalid_argument for a rate outside [0, 100] (or NaN).
    RtuLineNoise(const RtuLineNoiseRates& rates, std::uint64_t seed);

    // What goes on the line for the response `frame` (address .. CRC).
    std::vector<std::uint8_t> apply(std::vector<std::uint8_t> frame);

    const RtuLineNoiseRates& rates() const { return rates_; }
    RtuLineNoiseCounts counts() const;

private:
    bool happens(double pct);
    RtuLineNoiseRates rates_;
    mutable std::mutex mutex_;  // guards random_ and counts_
    SeededRandom random_;
    RtuLineNoiseCounts counts_;
};

}  // namespace rig::emulators
