#include "emulators/nmea_serial_sink.h"

#include <cctype>
#include <stdexcept>

namespace rig::emulators {
namespace {

// "$GPGGA,..." shortened for error messages, with CR and LF made visible.
std::string quoted_sentence(std::string_view sentence) {
    constexpr std::size_t kShown = 40;
    std::string shown;
    for (char c : sentence.substr(0, kShown)) {
        if (c == '\r') shown += "\\r";
        else if (c == '\n') shown += "\\n";
        else shown += c;
    }
    return "'" + shown + (sentence.size() > kShown ? "...'" : "'");
}

bool is_hex_digit(char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; }

}  // namespace

NmeaSerialSink::NmeaSerialSink(SerialPort& port, std::chrono::milliseconds write_timeout)
    : port_(port), write_timeout_(write_timeout) {}

std::string NmeaSerialSink::framing_error(std::string_view sentence) {
    // Shortest framed sentence: "$*HH\r\n".
    constexpr std::size_t kTrailerLength = 5;  // "*HH\r\n"
    if (sentence.empty()) return "empty sentence";
    if (sentence.front() != '$' && sentence.front() != '!') return "does not start with '$' or '!'";
    if (sentence.size() < 1 + kTrailerLength || sentence.substr(sentence.size() - 2) != "\r\n") {
        return "does not end with CR LF";
    }
    const std::size_t star = sentence.size() - kTrailerLength;
    if (sentence[star] != '*' || !is_hex_digit(sentence[star + 1]) || !is_hex_digit(sentence[star + 2])) {
        return "no '*HH' checksum before CR LF";
    }
    const std::string_view body = sentence.substr(0, star);
    if (body.find_first_of("\r\n") != std::string_view::npos) return "CR or LF inside the sentence";
    return {};
}

TimeNs NmeaSerialSink::wire_time_ns(std::size_t bytes) const { return rig::wire_time_ns(bytes, port_.settings()); }

TimeNs NmeaSerialSink::write_sentence(std::string_view sentence) {
    if (const std::string error = framing_error(sentence); !error.empty()) {
        throw std::invalid_argument("NMEA sentence " + quoted_sentence(sentence) + " not written to " + port_.path() + ": " +
                                    error);
    }
    port_.write_all(sentence, write_timeout_);
    ++sentences_written_;
    bytes_written_ += sentence.size();
    return wire_time_ns(sentence.size());
}

TimeNs NmeaSerialSink::write_epoch(std::span<const std::string> sentences) {
    for (std::size_t i = 0; i < sentences.size(); ++i) {
        if (const std::string error = framing_error(sentences[i]); !error.empty()) {
            throw std::invalid_argument("NMEA epoch not written to " + port_.path() + ": sentence " +
                                        std::to_string(i + 1) + " of " + std::to_string(sentences.size()) + " " +
                                        quoted_sentence(sentences[i]) + ": " + error);
        }
    }
    std::string epoch;
    for (const auto& sentence : sentences) epoch += sentence;
    port_.write_all(epoch, write_timeout_);
    sentences_written_ += sentences.size();
    bytes_written_ += epoch.size();
    return wire_time_ns(epoch.size());
}

TimeNs NmeaSerialSink::write_raw(std::string_view bytes) {
    port_.write_all(bytes, write_timeout_);
    bytes_written_ += bytes.size();
    return wire_time_ns(bytes.size());
}

}  // namespace rig::emulators
