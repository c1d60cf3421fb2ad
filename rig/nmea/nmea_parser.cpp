#include "rig/nmea/nmea_parser.h"
#include "rig/text/number_text.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <limits>
#include <system_error>
#include <utility>

namespace rig::nmea {
namespace {

constexpr double kUnbounded = std::numeric_limits<double>::max();

bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_upper(char c) { return c >= 'A' && c <= 'Z'; }
bool is_printable_ascii(char c) {
    const auto byte = static_cast<unsigned char>(c);
    return byte >= 0x20 && byte <= 0x7E;
}
bool all_digits(std::string_view text) {
    for (char c : text) {
        if (!is_digit(c)) return false;
    }
    return true;
}
int hex_digit_value(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
}

std::string hex_byte(unsigned char byte) {
    constexpr std::string_view kHexDigits = "0123456789ABCDEF";
    std::string text = "0x";
    text += kHexDigits[byte >> 4];
    text += kHexDigits[byte & 0x0F];
    return text;
}

// Quotes input text for a message.  Bytes that are not printable ASCII are shown
// as \xHH so that a message is always clean ASCII (it ends up in JSON and logs),
// and long text is cut so that a 10 kB line cannot produce a 10 kB message.
std::string quoted(std::string_view text) {
    constexpr std::size_t kMaxQuotedChars = 24;
    std::string out = "'";
    for (std::size_t i = 0; i < text.size() && i < kMaxQuotedChars; ++i) {
        if (is_printable_ascii(text[i])) {
            out += text[i];
        } else {
            out += "\\x";
            out += hex_byte(static_cast<unsigned char>(text[i])).substr(2);
        }
    }
    if (text.size() > kMaxQuotedChars) out += "...";
    out += '\'';
    return out;
}

std::string format_limit(double value) { return shortest_text(value); }

ParseError make_error(ParseErrorCode code, std::string message) { return ParseError{code, std::move(message)}; }

// ---------------------------------------------------------------------------
// Framing: the checks every sentence goes through before its fields are looked at.

struct RawLine {
    std::string_view text;           // from the first non-blank up to (not incl.) CR/LF
    std::size_t leading_blanks = 0;  // so that columns refer to the caller's line

    std::size_t column(std::size_t index) const { return leading_blanks + index + 1; }
};

RawLine strip_line(std::string_view line) {
    std::size_t begin = 0;
    while (begin < line.size() && (line[begin] == ' ' || line[begin] == '\t')) ++begin;
    std::size_t end = line.size();
    while (end > begin && (line[end - 1] == '\r' || line[end - 1] == '\n')) --end;
    return RawLine{line.substr(begin, end - begin), begin};
}

using FramingCheck = std::optional<ParseError> (*)(const RawLine&, const ParseOptions&);

std::optional<ParseError> check_not_empty(const RawLine& raw, const ParseOptions&) {
    if (!raw.text.empty()) return std::nullopt;
    return make_error(ParseErrorCode::empty_line, "empty line");
}

std::optional<ParseError> check_length(const RawLine& raw, const ParseOptions& options) {
    constexpr std::size_t kCrLfLength = 2;
    const std::size_t length = raw.text.size() + kCrLfLength;
    if (length <= options.max_sentence_length) return std::nullopt;
    return make_error(ParseErrorCode::line_too_long,
                      "sentence is " + std::to_string(length) + " characters including CR LF; the limit is " +
                          std::to_string(options.max_sentence_length) + " (NMEA 0183 says " +
                          std::to_string(kNmeaMaxSentenceLength) + ")");
}

std::optional<ParseError> check_start_delimiter(const RawLine& raw, const ParseOptions&) {
    if (raw.text.front() == '$') return std::nullopt;
    return make_error(ParseErrorCode::missing_start_delimiter, "sentence must start with '$', starts with " +
                                                                   quoted(raw.text.substr(0, 1)) + " at column " +
                                                                   std::to_string(raw.column(0)));
}

std::optional<ParseError> check_printable(const RawLine& raw, const ParseOptions&) {
    for (std::size_t i = 0; i < raw.text.size(); ++i) {
        if (!is_printable_ascii(raw.text[i])) {
            return make_error(ParseErrorCode::non_printable_character,
                              "byte " + hex_byte(static_cast<unsigned char>(raw.text[i])) + " at column " +
                                  std::to_string(raw.column(i)) + " is not printable ASCII");
        }
    }
    return std::nullopt;
}

// '$' and '!' are reserved start delimiters in NMEA 0183; inside a sentence they
// mean a receiver (or a serial line) lost the end of one sentence and ran straight
// into the next, as in triton400.log.
std::optional<ParseError> check_single_sentence(const RawLine& raw, const ParseOptions&) {
    const std::size_t second_start = raw.text.find_first_of("$!", 1);
    if (second_start == std::string_view::npos) return std::nullopt;
    return make_error(ParseErrorCode::embedded_start_delimiter,
                      "start delimiter '" + std::string(1, raw.text[second_start]) + "' at column " +
                          std::to_string(raw.column(second_start)) + " inside a sentence: two sentences run together?");
}

std::optional<ParseError> check_checksum_present(const RawLine& raw, const ParseOptions&) {
    if (raw.text.find('*') != std::string_view::npos) return std::nullopt;
    return make_error(ParseErrorCode::missing_checksum, "no '*' checksum delimiter");
}

std::optional<ParseError> check_checksum_format(const RawLine& raw, const ParseOptions&) {
    const std::size_t star = raw.text.find('*');
    const std::string_view checksum = raw.text.substr(star + 1);
    if (checksum.size() == 2 && hex_digit_value(checksum[0]) >= 0 && hex_digit_value(checksum[1]) >= 0) {
        return std::nullopt;
    }
    return make_error(ParseErrorCode::malformed_checksum, "'*' at column " + std::to_string(raw.column(star)) +
                                                              " must be followed by exactly two hex digits, found " +
                                                              quoted(checksum));
}

std::optional<ParseError> check_checksum_value(const RawLine& raw, const ParseOptions&) {
    const std::size_t star = raw.text.find('*');
    const int declared = hex_digit_value(raw.text[star + 1]) * 16 + hex_digit_value(raw.text[star + 2]);
    const std::uint8_t computed = nmea_checksum(raw.text.substr(1, star - 1));
    if (declared == computed) return std::nullopt;
    return make_error(ParseErrorCode::checksum_mismatch, "checksum mismatch: sentence says " +
                                                             hex_byte(static_cast<unsigned char>(declared)) +
                                                             ", computed " + hex_byte(computed));
}

// In order: each check may rely on those before it (e.g. the checksum checks on
// the '*' found by check_checksum_present).
constexpr std::array<FramingCheck, 8> kFramingChecks{
    check_not_empty,       check_length,           check_start_delimiter, check_printable,
    check_single_sentence, check_checksum_present, check_checksum_format, check_checksum_value,
};

// ---------------------------------------------------------------------------
// Field decoding.

// Two-digit RMC years: GPS time starts on 1980-01-06, so no receiver can report
// a fix before 1980; 80-99 are therefore 1980-1999 and 00-79 are 2000-2079.
int year_from_two_digits(int yy) { return yy >= 80 ? 1900 + yy : 2000 + yy; }

bool is_leap_year(int year) { return (year % 4 == 0 && year % 100 != 0) || year % 400 == 0; }

int days_in_month(int year, int month) {
    constexpr std::array<int, 12> kDays{31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    if (month == 2 && is_leap_year(year)) return 29;
    return kDays[static_cast<std::size_t>(month - 1)];
}

// [-]digits, nothing else.
bool is_integer_syntax(std::string_view text, bool allow_negative) {
    if (allow_negative && !text.empty() && text.front() == '-') text.remove_prefix(1);
    return !text.empty() && all_digits(text);
}

// [-]digits[.digits] with at least one digit; no exponent, no "inf"/"nan", no '+'.
bool is_decimal_syntax(std::string_view text) {
    if (!text.empty() && text.front() == '-') text.remove_prefix(1);
    bool seen_point = false;
    std::size_t digits = 0;
    for (char c : text) {
        if (is_digit(c)) {
            ++digits;
        } else if (c == '.' && !seen_point) {
            seen_point = true;
        } else {
            return false;
        }
    }
    return digits > 0;
}

// Two-digit unsigned integer at text[offset]; the caller has checked the digits.
int two_digits(std::string_view text, std::size_t offset) {
    return (text[offset] - '0') * 10 + (text[offset + 1] - '0');
}

std::optional<double> to_double(std::string_view text) {
    double value = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value, std::chars_format::fixed);
    if (ec != std::errc{} || end != text.data() + text.size()) return std::nullopt;
    return value;
}

// Reads the fields of one sentence by NMEA field number (1 = first field after
// the address).  Fields past the end of a short sentence read as empty.  The
// first error is kept and every later read returns nullopt, so a decoder is
// straight-line code that reads its layout in order and checks error() once.
class FieldReader {
public:
    FieldReader(std::string_view sentence_type, const std::vector<std::string_view>& fields)
        : sentence_type_(sentence_type), fields_(fields) {}

    const std::optional<ParseError>& error() const { return error_; }

    std::optional<int> integer(std::size_t number, std::string_view name, int min, int max) {
        const std::string_view text = field(number);
        if (error_ || text.empty()) return std::nullopt;
        if (!is_integer_syntax(text, min < 0)) {
            fail(ParseErrorCode::bad_field_syntax, number, name, quoted(text) + " is not an integer");
            return std::nullopt;
        }
        int value = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (ec != std::errc{} || end != text.data() + text.size() || value < min || value > max) {
            fail(ParseErrorCode::field_out_of_range, number, name,
                 quoted(text) + " is outside " + std::to_string(min) + ".." + std::to_string(max));
            return std::nullopt;
        }
        return value;
    }

    std::optional<double> number(std::size_t number, std::string_view name, double min, double max) {
        const std::string_view text = field(number);
        if (error_ || text.empty()) return std::nullopt;
        const std::optional<double> value = is_decimal_syntax(text) ? to_double(text) : std::optional<double>{};
        if (!value) {
            fail(ParseErrorCode::bad_field_syntax, number, name, quoted(text) + " is not a number");
            return std::nullopt;
        }
        if (*value < min) {
            fail(ParseErrorCode::field_out_of_range, number, name, quoted(text) + " is below " + format_limit(min));
            return std::nullopt;
        }
        if (*value > max) {
            fail(ParseErrorCode::field_out_of_range, number, name, quoted(text) + " is above " + format_limit(max));
            return std::nullopt;
        }
        return value;
    }

    // hhmmss[.s...]
    std::optional<UtcTime> utc_time(std::size_t number) {
        constexpr std::string_view kName = "UTC time";
        const std::string_view text = field(number);
        if (error_ || text.empty()) return std::nullopt;
        const bool syntax_ok = text.size() >= 6 && all_digits(text.substr(0, 6)) &&
                               (text.size() == 6 || (text.size() > 7 && text[6] == '.' && all_digits(text.substr(7))));
        const std::optional<double> second = syntax_ok ? to_double(text.substr(4)) : std::nullopt;
        if (!second) {
            fail(ParseErrorCode::bad_field_syntax, number, kName, quoted(text) + " is not hhmmss.ss");
            return std::nullopt;
        }
        const UtcTime time{two_digits(text, 0), two_digits(text, 2), *second};
        // 60.x seconds are legal: UTC inserts leap seconds as 23:59:60.
        constexpr double kSecondsLimit = 61.0;
        if (time.hour > 23 || time.minute > 59 || time.second >= kSecondsLimit) {
            fail(ParseErrorCode::field_out_of_range, number, kName,
                 quoted(text) + " is not a time of day (hour 0-23, minute 0-59, second below 61)");
            return std::nullopt;
        }
        return time;
    }

    // ddmmyy
    std::optional<Date> ddmmyy_date(std::size_t number) {
        constexpr std::string_view kName = "date";
        const std::string_view text = field(number);
        if (error_ || text.empty()) return std::nullopt;
        if (text.size() != 6 || !all_digits(text)) {
            fail(ParseErrorCode::bad_field_syntax, number, kName, quoted(text) + " is not ddmmyy");
            return std::nullopt;
        }
        const Date date{year_from_two_digits(two_digits(text, 4)), two_digits(text, 2), two_digits(text, 0)};
        return checked_date(number, kName, text, date);
    }

    // Day, month and four-digit year in three fields (ZDA).  All three or none.
    std::optional<Date> split_date(std::size_t day_number) {
        const std::optional<int> day = integer(day_number, "day", 0, 99);
        const std::optional<int> month = integer(day_number + 1, "month", 0, 99);
        const std::optional<int> year = integer(day_number + 2, "year", 0, 9999);
        if (error_) return std::nullopt;
        if (!day && !month && !year) return std::nullopt;
        if (!day || !month || !year) {
            fail(ParseErrorCode::bad_field_syntax, day_number, "date",
                 "day, month and year must be all present or all empty");
            return std::nullopt;
        }
        const std::string text = std::string(field(day_number)) + "/" + std::string(field(day_number + 1)) + "/" +
                                 std::string(field(day_number + 2));
        return checked_date(day_number, "date", text, Date{*year, *month, *day});
    }

    // Four fields: latitude ddmm.mmmm, N/S, longitude dddmm.mmmm, E/W.
    std::optional<Position> position(std::size_t latitude_number) {
        const std::size_t ns_number = latitude_number + 1;
        const std::size_t longitude_number = latitude_number + 2;
        const std::size_t ew_number = latitude_number + 3;
        constexpr int kLatitudeDegreeDigits = 2;
        constexpr int kLongitudeDegreeDigits = 3;
        const std::optional<double> latitude = coordinate(latitude_number, "latitude", kLatitudeDegreeDigits, 90.0);
        const std::optional<char> north_south = letter(ns_number, "N/S", "NS");
        const std::optional<double> longitude =
            coordinate(longitude_number, "longitude", kLongitudeDegreeDigits, 180.0);
        const std::optional<char> east_west = letter(ew_number, "E/W", "EW");
        if (error_) return std::nullopt;
        if (latitude && !north_south) {
            fail(ParseErrorCode::bad_field_syntax, ns_number, "N/S", "empty but latitude is given");
        } else if (longitude && !east_west) {
            fail(ParseErrorCode::bad_field_syntax, ew_number, "E/W", "empty but longitude is given");
        } else if (latitude && !longitude) {
            fail(ParseErrorCode::bad_field_syntax, longitude_number, "longitude", "empty but latitude is given");
        } else if (longitude && !latitude) {
            fail(ParseErrorCode::bad_field_syntax, latitude_number, "latitude", "empty but longitude is given");
        }
        if (error_ || !latitude) return std::nullopt;
        return Position{*north_south == 'S' ? -*latitude : *latitude, *east_west == 'W' ? -*longitude : *longitude};
    }

    // One letter out of `allowed`.
    std::optional<char> letter(std::size_t number, std::string_view name, std::string_view allowed) {
        const std::string_view text = field(number);
        if (error_ || text.empty()) return std::nullopt;
        if (text.size() != 1 || allowed.find(text.front()) == std::string_view::npos) {
            std::string choices;
            for (char c : allowed) {
                if (!choices.empty()) choices += '/';
                choices += c;
            }
            fail(ParseErrorCode::bad_field_syntax, number, name, quoted(text) + " is not " + choices);
            return std::nullopt;
        }
        return text.front();
    }

    // A unit letter after a value ('M' for metres...): empty or exactly `unit`.
    void unit(std::size_t number, std::string_view name, char expected) {
        const std::string_view text = field(number);
        if (error_ || text.empty()) return;
        if (text.size() != 1 || text.front() != expected) {
            fail(ParseErrorCode::bad_field_syntax, number, name,
                 quoted(text) + " is not '" + std::string(1, expected) + "'");
        }
    }

private:
    std::string_view field(std::size_t number) const {
        return number < fields_.size() ? fields_[number] : std::string_view{};
    }

    void fail(ParseErrorCode code, std::size_t number, std::string_view name, std::string_view what) {
        if (error_) return;
        error_ = make_error(code, std::string(sentence_type_) + " field " + std::to_string(number) + " (" +
                                      std::string(name) + "): " + std::string(what));
    }

    std::optional<Date> checked_date(std::size_t number, std::string_view name, std::string_view text,
                                     const Date& date) {
        if (date.month < 1 || date.month > 12 || date.day < 1 || date.day > days_in_month(date.year, date.month)) {
            fail(ParseErrorCode::field_out_of_range, number, name,
                 quoted(text) + " is not a calendar date (day " + std::to_string(date.day) + ", month " +
                     std::to_string(date.month) + ")");
            return std::nullopt;
        }
        return date;
    }

    // ddmm.mmmm (latitude, 2 degree digits) or dddmm.mmmm (longitude, 3), any number
    // of decimals; unsigned (the hemisphere is the next field).
    std::optional<double> coordinate(std::size_t number, std::string_view name, int degree_digits, double max_deg) {
        const std::string_view text = field(number);
        if (error_ || text.empty()) return std::nullopt;
        const auto integer_digits = static_cast<std::size_t>(degree_digits) + 2;
        const bool syntax_ok =
            text.size() >= integer_digits && all_digits(text.substr(0, integer_digits)) &&
            (text.size() == integer_digits || (text.size() > integer_digits + 1 && text[integer_digits] == '.' &&
                                               all_digits(text.substr(integer_digits + 1))));
        const std::string_view minutes_text = text.substr(std::min(text.size(), integer_digits - 2));
        const std::optional<double> minutes = syntax_ok ? to_double(minutes_text) : std::nullopt;
        if (!minutes) {
            fail(ParseErrorCode::bad_field_syntax, number, name,
                 quoted(text) + " is not " + std::string(static_cast<std::size_t>(degree_digits), 'd') + "mm.mmmm");
            return std::nullopt;
        }
        int degrees = 0;
        for (std::size_t i = 0; i + 2 < integer_digits; ++i) degrees = degrees * 10 + (text[i] - '0');
        if (*minutes >= 60.0) {
            fail(ParseErrorCode::field_out_of_range, number, name,
                 "minutes " + quoted(minutes_text) + " must be below 60");
            return std::nullopt;
        }
        const double value = degrees + *minutes / 60.0;
        if (value > max_deg) {
            fail(ParseErrorCode::field_out_of_range, number, name,
                 quoted(text) + " is beyond " + format_limit(max_deg) + " degrees");
            return std::nullopt;
        }
        return value;
    }

    std::string_view sentence_type_;
    const std::vector<std::string_view>& fields_;
    std::optional<ParseError> error_;
};

// NMEA 2.3 FAA mode indicator: Autonomous, Differential, Estimated, Float RTK,
// Manual, Not valid, Precise, RTK fixed, Simulator.
constexpr std::string_view kModeIndicators = "ADEFMNPRS";
constexpr std::string_view kStatusLetters = "AV";

std::optional<DataStatus> to_status(std::optional<char> letter) {
    if (!letter) return std::nullopt;
    return *letter == 'A' ? DataStatus::valid : DataStatus::invalid;
}

SentenceData decode_gga(FieldReader& fields) {
    GgaData gga;
    gga.utc_time = fields.utc_time(1);
    gga.position = fields.position(2);
    gga.fix_quality = fields.integer(6, "fix quality", 0, 8);
    gga.satellites_used = fields.integer(7, "satellites used", 0, 99);  // two-digit field
    gga.hdop = fields.number(8, "HDOP", 0.0, kUnbounded);
    gga.altitude_msl_m = fields.number(9, "altitude MSL", -kUnbounded, kUnbounded);
    fields.unit(10, "altitude units", 'M');
    gga.geoid_separation_m = fields.number(11, "geoid separation", -kUnbounded, kUnbounded);
    fields.unit(12, "geoid separation units", 'M');
    gga.differential_age_s = fields.number(13, "age of differential", 0.0, kUnbounded);
    // NMEA 0183 reference station ids are 0000-1023.
    gga.differential_station_id = fields.integer(14, "differential station id", 0, 1023);
    return gga;
}

SentenceData decode_rmc(FieldReader& fields) {
    RmcData rmc;
    rmc.utc_time = fields.utc_time(1);
    rmc.status = to_status(fields.letter(2, "status", kStatusLetters));
    rmc.position = fields.position(3);
    rmc.speed_knots = fields.number(7, "speed over ground", 0.0, kUnbounded);
    if (rmc.speed_knots) rmc.speed_m_s = *rmc.speed_knots * kMetresPerSecondPerKnot;
    rmc.course_true_deg = fields.number(8, "course over ground", 0.0, 360.0);
    rmc.date = fields.ddmmyy_date(9);
    const std::optional<double> variation = fields.number(10, "magnetic variation", 0.0, 180.0);
    const std::optional<char> variation_direction = fields.letter(11, "variation E/W", "EW");
    if (variation) {
        rmc.magnetic_variation_deg = variation_direction == 'W' ? -*variation : *variation;
    }
    rmc.mode = fields.letter(12, "mode", kModeIndicators);
    rmc.navigational_status = fields.letter(13, "navigational status", "SCUV");
    return rmc;
}

SentenceData decode_vtg(FieldReader& fields) {
    VtgData vtg;
    vtg.course_true_deg = fields.number(1, "course true", 0.0, 360.0);
    fields.unit(2, "course true reference", 'T');
    vtg.course_magnetic_deg = fields.number(3, "course magnetic", 0.0, 360.0);
    fields.unit(4, "course magnetic reference", 'M');
    vtg.speed_knots = fields.number(5, "speed knots", 0.0, kUnbounded);
    fields.unit(6, "speed knots unit", 'N');
    vtg.speed_km_h = fields.number(7, "speed km/h", 0.0, kUnbounded);
    fields.unit(8, "speed km/h unit", 'K');
    constexpr double kMetresPerSecondPerKmH = 1000.0 / 3600.0;
    if (vtg.speed_knots) {
        vtg.speed_m_s = *vtg.speed_knots * kMetresPerSecondPerKnot;
    } else if (vtg.speed_km_h) {
        vtg.speed_m_s = *vtg.speed_km_h * kMetresPerSecondPerKmH;
    }
    vtg.mode = fields.letter(9, "mode", kModeIndicators);
    return vtg;
}

SentenceData decode_gll(FieldReader& fields) {
    GllData gll;
    gll.position = fields.position(1);
    gll.utc_time = fields.utc_time(5);
    gll.status = to_status(fields.letter(6, "status", kStatusLetters));
    gll.mode = fields.letter(7, "mode", kModeIndicators);
    return gll;
}

SentenceData decode_zda(FieldReader& fields) {
    ZdaData zda;
    zda.utc_time = fields.utc_time(1);
    zda.date = fields.split_date(2);
    zda.local_zone_hours = fields.integer(5, "local zone hours", -13, 13);
    zda.local_zone_minutes = fields.integer(6, "local zone minutes", 0, 59);
    return zda;
}

SentenceData decode_hdt(FieldReader& fields) {
    HdtData hdt;
    hdt.heading_true_deg = fields.number(1, "heading true", 0.0, 360.0);
    fields.unit(2, "heading reference", 'T');
    return hdt;
}

// Field counts exclude the address.  min_fields is the layout of the oldest NMEA
// version that has the fields we decode; max_fields the newest version plus the
// vendor extensions seen in real logs.  Fewer fields means a truncated sentence;
// far more means corrupted or merged data, so both are errors.
struct SentenceLayout {
    std::string_view type;
    std::size_t min_fields;
    std::size_t max_fields;
    SentenceData (*decode)(FieldReader&);
};

constexpr std::array<SentenceLayout, 6> kDecodedLayouts{{
    // 14 standard; SiRF TriG (beidou-bd.log) appends a 15th field (its VDOP).
    {"GGA", 14, 15, decode_gga},
    // NMEA 2.0: 11; 2.3 adds the mode indicator; 4.1 the navigational status.
    {"RMC", 11, 13, decode_rmc},
    // NMEA 2.0: 8; 2.3 adds the mode indicator.
    {"VTG", 8, 9, decode_vtg},
    // NMEA 2.0: 6; 2.3 adds the mode indicator.
    {"GLL", 6, 7, decode_gll},
    {"ZDA", 6, 6, decode_zda},
    {"HDT", 2, 2, decode_hdt},
}};

// Standard sentences we know but the controller has no use for (satellites in
// view, DOPs, error statistics, waypoints, text).  Reported as UndecodedData.
constexpr std::array<std::string_view, 14> kRecognisedNotDecoded{
    "ALM", "DTM", "GBS", "GNS", "GRS", "GSA", "GST", "GSV", "HDG", "HDM", "RMB", "ROT", "THS", "TXT",
};

struct Talker {
    std::string_view id;
    std::string_view system;
};

constexpr std::array<Talker, 7> kAcceptedTalkers{{
    {"GP", "GPS"},
    {"GN", "combined GNSS"},
    {"BD", "BeiDou (Chinese TSCPB talker id)"},
    {"GB", "BeiDou (NMEA 4.11 talker id)"},
    {"GL", "GLONASS"},
    {"GA", "Galileo"},
    {"GQ", "QZSS"},
}};

const SentenceLayout* find_layout(std::string_view type) {
    for (const SentenceLayout& layout : kDecodedLayouts) {
        if (layout.type == type) return &layout;
    }
    return nullptr;
}

bool is_recognised_not_decoded(std::string_view type) {
    for (std::string_view known : kRecognisedNotDecoded) {
        if (known == type) return true;
    }
    return false;
}

bool is_accepted_talker(std::string_view talker) {
    for (const Talker& accepted : kAcceptedTalkers) {
        if (accepted.id == talker) return true;
    }
    return false;
}

std::string accepted_talker_list() {
    std::string list;
    for (const Talker& accepted : kAcceptedTalkers) {
        if (!list.empty()) list += ' ';
        list += accepted.id;
    }
    return list;
}

std::vector<std::string_view> split_fields(std::string_view body) {
    std::vector<std::string_view> fields;
    std::size_t begin = 0;
    while (true) {
        const std::size_t comma = body.find(',', begin);
        if (comma == std::string_view::npos) {
            fields.push_back(body.substr(begin));
            return fields;
        }
        fields.push_back(body.substr(begin, comma - begin));
        begin = comma + 1;
    }
}

UndecodedData undecoded(const std::vector<std::string_view>& fields) {
    UndecodedData data;
    data.fields.reserve(fields.size() - 1);
    for (std::size_t i = 1; i < fields.size(); ++i) data.fields.emplace_back(fields[i]);
    return data;
}

ParseResult failure(ParseError error) { return ParseResult{std::nullopt, std::move(error)}; }
ParseResult failure(ParseErrorCode code, std::string message) { return failure(make_error(code, std::move(message))); }
ParseResult success(Sentence sentence) { return ParseResult{std::move(sentence), std::nullopt}; }

bool is_upper_alphanumeric(std::string_view text) {
    for (char c : text) {
        if (!is_upper(c) && !is_digit(c)) return false;
    }
    return true;
}

// "$P" + a three-character manufacturer id + the manufacturer's own sentence.
constexpr std::size_t kMinProprietaryAddressLength = 4;
constexpr std::size_t kTalkerLength = 2;
constexpr std::size_t kStandardAddressLength = 5;

ParseResult decode_fields(const std::vector<std::string_view>& fields) {
    const std::string_view address = fields.front();
    if (!address.empty() && address.front() == 'P') {
        if (address.size() < kMinProprietaryAddressLength || !is_upper_alphanumeric(address)) {
            return failure(ParseErrorCode::malformed_address,
                           "proprietary address " + quoted(address) +
                               " must be 'P' and a manufacturer id of 3 or more letters/digits");
        }
        return success(Sentence{"P", std::string(address.substr(1)), undecoded(fields)});
    }
    const bool standard_shape = address.size() == kStandardAddressLength && is_upper(address[0]) &&
                                is_upper(address[1]) && is_upper(address[2]) && is_upper(address[3]) &&
                                is_upper(address[4]);
    if (!standard_shape) {
        return failure(ParseErrorCode::malformed_address,
                       "address " + quoted(address) + " must be a 2-letter talker and a 3-letter sentence type");
    }
    const std::string_view talker = address.substr(0, kTalkerLength);
    const std::string_view type = address.substr(kTalkerLength);
    if (!is_accepted_talker(talker)) {
        return failure(ParseErrorCode::unknown_talker,
                       "talker " + quoted(talker) + " is not accepted (accepted: " + accepted_talker_list() + ")");
    }
    if (const SentenceLayout* layout = find_layout(type)) {
        const std::size_t field_count = fields.size() - 1;
        if (field_count < layout->min_fields) {
            return failure(ParseErrorCode::too_few_fields, std::string(type) + " has " + std::to_string(field_count) +
                                                               " fields, needs at least " +
                                                               std::to_string(layout->min_fields));
        }
        if (field_count > layout->max_fields) {
            return failure(ParseErrorCode::too_many_fields, std::string(type) + " has " + std::to_string(field_count) +
                                                                " fields, at most " +
                                                                std::to_string(layout->max_fields) + " expected");
        }
        FieldReader reader(type, fields);
        SentenceData data = layout->decode(reader);
        if (reader.error()) return failure(*reader.error());
        return success(Sentence{std::string(talker), std::string(type), std::move(data)});
    }
    if (is_recognised_not_decoded(type)) {
        return success(Sentence{std::string(talker), std::string(type), undecoded(fields)});
    }
    return failure(ParseErrorCode::unknown_sentence_type, "sentence type " + quoted(type) + " is unknown");
}

}  // namespace

std::string_view to_string(ParseErrorCode code) {
    switch (code) {
        case ParseErrorCode::empty_line: return "empty_line";
        case ParseErrorCode::line_too_long: return "line_too_long";
        case ParseErrorCode::missing_start_delimiter: return "missing_start_delimiter";
        case ParseErrorCode::non_printable_character: return "non_printable_character";
        case ParseErrorCode::embedded_start_delimiter: return "embedded_start_delimiter";
        case ParseErrorCode::missing_checksum: return "missing_checksum";
        case ParseErrorCode::malformed_checksum: return "malformed_checksum";
        case ParseErrorCode::checksum_mismatch: return "checksum_mismatch";
        case ParseErrorCode::malformed_address: return "malformed_address";
        case ParseErrorCode::unknown_talker: return "unknown_talker";
        case ParseErrorCode::unknown_sentence_type: return "unknown_sentence_type";
        case ParseErrorCode::too_few_fields: return "too_few_fields";
        case ParseErrorCode::too_many_fields: return "too_many_fields";
        case ParseErrorCode::bad_field_syntax: return "bad_field_syntax";
        case ParseErrorCode::field_out_of_range: return "field_out_of_range";
    }
    return "unknown_error_code";
}

std::uint8_t nmea_checksum(std::string_view body) {
    unsigned checksum = 0;
    for (char c : body) checksum ^= static_cast<unsigned char>(c);
    return static_cast<std::uint8_t>(checksum);
}

ParseResult parse_sentence(std::string_view line, const ParseOptions& options) {
    const RawLine raw = strip_line(line);
    for (FramingCheck check : kFramingChecks) {
        if (std::optional<ParseError> error = check(raw, options)) return failure(std::move(*error));
    }
    const std::size_t star = raw.text.find('*');
    return decode_fields(split_fields(raw.text.substr(1, star - 1)));
}

}  // namespace rig::nmea
