#include "emulators/wire_faults.h"

#include <cmath>
#include <stdexcept>

#include "rig/nmea/nmea_parser.h"

namespace rig::emulators {

namespace {

void check_rate(double pct, const char* name) {
    if (!(pct >= 0.0 && pct <= 100.0)) {
        throw std::invalid_argument(std::string("wire fault rate ") + name + " must be in [0, 100] %, got " +
                                    std::to_string(pct));
    }
}

// A whole number uniform in [low, high] from one draw.
std::size_t uniform_index(SeededRandom& random, std::size_t low, std::size_t high) {
    const auto span = static_cast<double>(high - low + 1);
    const auto offset = static_cast<std::size_t>(random.uniform01() * span);
    return low + std::min<std::size_t>(offset, high - low);
}

std::string_view without_line_end(std::string_view text) {
    while (!text.empty() && (text.back() == '\r' || text.back() == '\n')) text.remove_suffix(1);
    return text;
}

char hex_digit(unsigned value) { return "0123456789ABCDEF"[value & 0xF]; }

unsigned hex_value(char digit) {
    if (digit >= '0' && digit <= '9') return static_cast<unsigned>(digit - '0');
    if (digit >= 'A' && digit <= 'F') return static_cast<unsigned>(digit - 'A' + 10);
    if (digit >= 'a' && digit <= 'f') return static_cast<unsigned>(digit - 'a' + 10);
    return 0;
}

}  // namespace

// ---------------------------------------------------------------- NMEA

NmeaWireFaults::NmeaWireFaults(const NmeaWireFaultRates& rates, std::uint64_t seed)
    : rates_(rates), random_(seed, kStreamName) {
    check_rate(rates.byte_loss_pct, "byte_loss_pct");
    check_rate(rates.corrupt_checksum_pct, "corrupt_checksum_pct");
    check_rate(rates.truncate_pct, "truncate_pct");
}

bool NmeaWireFaults::happens(double pct) { return pct > 0.0 && random_.uniform01() * 100.0 < pct; }

std::string NmeaWireFaults::apply(std::string_view sentence) {
    ++counts_.sentences;
    std::string wire(sentence);
    if (!rates_.any()) return wire;
    bool damaged = false;
    // The checksum's '*': the last one, three characters from the end of the
    // text before CR LF (the encoder frames every sentence so).
    const std::size_t star = wire.rfind('*');
    const bool has_checksum = star != std::string::npos && star + 2 < wire.size();

    if (happens(rates_.truncate_pct)) {
        // Keep 1 .. up to the checksum's first digit: at least the '$', never the whole checksum.
        const std::size_t keep_at_most = has_checksum ? star + 2 : std::max<std::size_t>(wire.size(), 2) - 1;
        wire.resize(uniform_index(random_, 1, keep_at_most));
        ++counts_.sentences_truncated;
        damaged = true;
    }
    if (happens(rates_.corrupt_checksum_pct) && has_checksum && star + 2 < wire.size()) {
        // XOR with 1..255: always another value, as a garbled checksum is.
        const unsigned written = hex_value(wire[star + 1]) << 4 | hex_value(wire[star + 2]);
        const unsigned garble = 1 + static_cast<unsigned>(uniform_index(random_, 0, 254));
        const unsigned wrong = (written ^ garble) & 0xFF;
        wire[star + 1] = hex_digit(wrong >> 4);
        wire[star + 2] = hex_digit(wrong);
        ++counts_.checksums_corrupted;
        damaged = true;
    }
    if (rates_.byte_loss_pct > 0.0) {
        std::string kept;
        kept.reserve(wire.size());
        for (const char byte : wire) {
            if (happens(rates_.byte_loss_pct)) {
                ++counts_.bytes_lost;
                damaged = true;
            } else {
                kept += byte;
            }
        }
        wire = std::move(kept);
    }
    if (damaged) ++counts_.sentences_damaged;
    if (wire.empty()) ++counts_.sentences_lost;
    if (damaged && !wire.empty() && without_line_end(wire) != without_line_end(sentence) &&
        nmea::parse_sentence(wire).ok()) {
        ++counts_.sentences_damaged_parsed;
    }
    return wire;
}

// ---------------------------------------------------------------- Modbus RTU

RtuLineNoise::RtuLineNoise(const RtuLineNoiseRates& rates, std::uint64_t seed) : rates_(rates), random_(seed, kStreamName) {
    check_rate(rates.corrupt_response_pct, "corrupt_response_pct");
    check_rate(rates.noise_burst_pct, "noise_burst_pct");
}

bool RtuLineNoise::happens(double pct) { return pct > 0.0 && random_.uniform01() * 100.0 < pct; }

std::vector<std::uint8_t> RtuLineNoise::apply(std::vector<std::uint8_t> frame) {
    std::lock_guard lock(mutex_);
    ++counts_.responses;
    if (!frame.empty() && happens(rates_.corrupt_response_pct)) {
        // One byte hit: a nonzero XOR mask, so the byte always changes. The
        // CRC-16 of Modbus detects every error confined to one byte.
        const std::size_t at = uniform_index(random_, 0, frame.size() - 1);
        const auto mask = static_cast<std::uint8_t>(1 + uniform_index(random_, 0, 254));
        frame[at] ^= mask;
        for (std::uint8_t bits = mask; bits != 0; bits &= static_cast<std::uint8_t>(bits - 1)) ++counts_.bits_flipped;
        ++counts_.responses_corrupted;
    }
    if (happens(rates_.noise_burst_pct)) {
        const std::size_t length = uniform_index(random_, 1, kMaxBurstBytes);
        for (std::size_t i = 0; i < length; ++i) frame.push_back(static_cast<std::uint8_t>(random_.next_u64() & 0xFF));
        ++counts_.noise_bursts;
        counts_.noise_bytes += length;
    }
    return frame;
}

RtuLineNoiseCounts RtuLineNoise::counts() const {
    std::lock_guard lock(mutex_);
    return counts_;
}

}  // namespace rig::emulators
