// NMEA 0183 sentence parser for the reference controller (the RS232 GNSS input).
//
// Firmware-like contract: any byte string may come in; the parser never reads out
// of bounds, never throws on bad input (only std::bad_alloc can escape) and always
// answers with either a decoded sentence or one error code plus a message that
// names what is wrong and where.
//
// Table-driven, in the spirit of gpsd's driver_nmea0183.c: a table of framing
// checks, a table of accepted talkers, a table of decoded sentence layouts
// (type, field counts, decoder) and a list of standard sentences that are
// recognised but not decoded.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace rig::nmea {

// NMEA 0183 limits a sentence to 82 characters including '$' and CR LF.
inline constexpr std::size_t kNmeaMaxSentenceLength = 82;
// Real receivers exceed that: the Trimble RTK receiver in nmea-rtk.log prints
// 8-decimal minutes and reaches 93 characters.  Accept up to 120 by default so
// such receivers work, while still bounding what a garbage line can cost.
inline constexpr std::size_t kDefaultMaxSentenceLength = 120;

struct ParseOptions {
    // Counted from '$' to the checksum's last digit, plus 2 for CR LF whether or
    // not the line still carries them.  Leading whitespace is not counted.
    std::size_t max_sentence_length = kDefaultMaxSentenceLength;
};

struct UtcTime {
    int hour = 0;
    int minute = 0;
    double second = 0.0;  // 0 <= second < 61 (60.x only during a leap second)

    double seconds_of_day() const { return hour * 3600.0 + minute * 60.0 + second; }
    friend bool operator==(const UtcTime&, const UtcTime&) = default;
};

struct Date {
    int year = 0;
    int month = 0;  // 1..12
    int day = 0;    // 1..31, valid for the month
    friend bool operator==(const Date&, const Date&) = default;
};

// WGS84 degrees, north and east positive.  Latitude and longitude are only ever
// reported together: a sentence with one but not the other is an error.
struct Position {
    double lat_deg = 0.0;
    double lon_deg = 0.0;
    friend bool operator==(const Position&, const Position&) = default;
};

// RMC field 2 and GLL field 6.
enum class DataStatus : char { valid = 'A', invalid = 'V' };

// Every field is optional because NMEA leaves a field empty when the receiver
// has no value for it (no fix yet, no differential station...).
struct GgaData {
    std::optional<UtcTime> utc_time;
    std::optional<Position> position;
    // 0 invalid, 1 GPS, 2 DGPS, 3 PPS, 4 RTK fixed, 5 RTK float, 6 dead reckoning,
    // 7 manual input, 8 simulator.
    std::optional<int> fix_quality;
    std::optional<int> satellites_used;
    std::optional<double> hdop;
    std::optional<double> altitude_msl_m;
    std::optional<double> geoid_separation_m;  // WGS84 ellipsoid above mean sea level
    std::optional<double> differential_age_s;
    std::optional<int> differential_station_id;
};

struct RmcData {
    std::optional<UtcTime> utc_time;
    std::optional<DataStatus> status;
    std::optional<Position> position;
    std::optional<double> speed_knots;
    std::optional<double> speed_m_s;  // derived from speed_knots
    std::optional<double> course_true_deg;
    std::optional<Date> date;
    std::optional<double> magnetic_variation_deg;  // east positive
    std::optional<char> mode;                      // NMEA 2.3 FAA mode: A D E F M N P R S
    std::optional<char> navigational_status;       // NMEA 4.1: S C U V
};

struct VtgData {
    std::optional<double> course_true_deg;
    std::optional<double> course_magnetic_deg;
    std::optional<double> speed_knots;
    std::optional<double> speed_km_h;
    std::optional<double> speed_m_s;  // derived from speed_knots, else from speed_km_h
    std::optional<char> mode;
};

struct GllData {
    std::optional<Position> position;
    std::optional<UtcTime> utc_time;
    std::optional<DataStatus> status;
    std::optional<char> mode;
};

struct ZdaData {
    std::optional<UtcTime> utc_time;
    std::optional<Date> date;
    std::optional<int> local_zone_hours;
    std::optional<int> local_zone_minutes;
};

struct HdtData {
    std::optional<double> heading_true_deg;
};

// A well-formed sentence of a type this parser knows but does not decode
// (GSA, GSV, TXT, proprietary $P...): not an error.  The raw fields (after the
// address) are kept so that a caller can still look at them.
struct UndecodedData {
    std::vector<std::string> fields;
};

using SentenceData = std::variant<GgaData, RmcData, VtgData, GllData, ZdaData, HdtData, UndecodedData>;

struct Sentence {
    // Two-letter talker ("GP", "GN"...), or "P" for a proprietary sentence, whose
    // type is then the rest of the address (manufacturer + sentence, e.g. "SRFEPE").
    std::string talker;
    std::string type;
    SentenceData data;

    bool is_proprietary() const { return talker == "P"; }
    bool is_decoded() const { return !std::holds_alternative<UndecodedData>(data); }
};

enum class ParseErrorCode {
    empty_line,                // nothing but whitespace / CR LF
    line_too_long,             // longer than ParseOptions::max_sentence_length
    missing_start_delimiter,   // does not start with '$'
    non_printable_character,   // control character or byte outside ASCII
    embedded_start_delimiter,  // a second '$' or '!': sentences run together
    missing_checksum,          // no '*'
    malformed_checksum,        // '*' not followed by exactly two hex digits
    checksum_mismatch,
    malformed_address,  // not talker (2 letters) + type (3 letters), nor $P...
    unknown_talker,
    unknown_sentence_type,
    too_few_fields,
    too_many_fields,
    bad_field_syntax,    // e.g. letters in a number, N/S field 'X'
    field_out_of_range,  // e.g. minutes >= 60, hour 25, month 13
};

std::string_view to_string(ParseErrorCode code);

struct ParseError {
    ParseErrorCode code{};
    std::string message;
};

struct ParseResult {
    std::optional<Sentence> sentence;  // set exactly when error is not
    std::optional<ParseError> error;

    bool ok() const { return sentence.has_value(); }
};

// Parses one line, with or without trailing CR/LF; leading whitespace is ignored.
ParseResult parse_sentence(std::string_view line, const ParseOptions& options = {});

// XOR of all characters of body, which is the text between '$' and '*'.
std::uint8_t nmea_checksum(std::string_view body);

// Knots to metres per second (1 knot = 1852 m / 3600 s, exactly).
inline constexpr double kMetresPerSecondPerKnot = 1852.0 / 3600.0;

}  // namespace rig::nmea
