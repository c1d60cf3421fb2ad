#include "harness/bench/nmea_decode_tool.h"

#include <CLI/CLI.hpp>

#include <iostream>

#include <array>
#include <cmath>
#include <cstdio>
#include <istream>
#include <optional>
#include <ostream>
#include <string>
#include <variant>

#include <nlohmann/json.hpp>

#include "rig/nmea/nmea_parser.h"
#include "rig/config/file_access.h"

#include <fcntl.h>

#include <cstring>
#include <limits>

namespace rig::nmea {
namespace {

using Json = nlohmann::ordered_json;  // keys in the order written: talker, type, ...

// A line is kept up to this many bytes; anything longer is far beyond any
// sentence limit, so the rest is only counted, never stored.
constexpr std::size_t kMaxKeptLineBytes = 4096;

struct InputLine {
    std::string text;        // at most kMaxKeptLineBytes, without the '\n'
    std::size_t length = 0;  // true length in bytes
    bool truncated() const { return length > text.size(); }
};

// Reads up to and including the next '\n'.  False at end of input with nothing read.
bool read_line(std::streambuf& input, InputLine& line) {
    line.text.clear();
    line.length = 0;
    using Traits = std::streambuf::traits_type;
    for (Traits::int_type c = input.sbumpc(); !Traits::eq_int_type(c, Traits::eof()); c = input.sbumpc()) {
        const char byte = Traits::to_char_type(c);
        if (byte == '\n') return true;
        if (line.length < kMaxKeptLineBytes) line.text += byte;
        ++line.length;
    }
    return line.length > 0;
}

bool is_skipped(std::string_view text) {
    const std::size_t first = text.find_first_not_of(" \t\r");
    return first == std::string_view::npos || text[first] == '#';
}

// "hh:mm:ss.sss".  Milliseconds are truncated, not rounded, so that 59.9996 s
// never prints as 60.000; the 1e-6 absorbs binary representation error
// (0.123 is stored as 0.12299999...).
std::string format_time(const UtcTime& time) {
    constexpr double kRepresentationSlack = 1e-6;
    const auto milliseconds = static_cast<long>(std::floor(time.second * 1000.0 + kRepresentationSlack));
    std::array<char, 32> text{};
    std::snprintf(text.data(), text.size(), "%02d:%02d:%02ld.%03ld", time.hour, time.minute, milliseconds / 1000,
                  milliseconds % 1000);
    return text.data();
}

std::string format_date(const Date& date) {
    std::array<char, 32> text{};
    std::snprintf(text.data(), text.size(), "%04d-%02d-%02d", date.year, date.month, date.day);
    return text.data();
}

template <class T>
void put(Json& json, const char* key, const std::optional<T>& value) {
    if (value) json[key] = *value;
}
void put(Json& json, const char* key, const std::optional<char>& value) {
    if (value) json[key] = std::string(1, *value);
}
void put(Json& json, const char* key, const std::optional<DataStatus>& value) {
    if (value) json[key] = std::string(1, static_cast<char>(*value));
}
void put(Json& json, const char* key, const std::optional<UtcTime>& value) {
    if (value) json[key] = format_time(*value);
}
void put(Json& json, const char* key, const std::optional<Date>& value) {
    if (value) json[key] = format_date(*value);
}
void put_position(Json& json, const std::optional<Position>& value) {
    if (!value) return;
    json["lat_deg"] = value->lat_deg;
    json["lon_deg"] = value->lon_deg;
}

void add_fields(Json& json, const GgaData& gga) {
    put(json, "utc_time", gga.utc_time);
    put_position(json, gga.position);
    put(json, "fix_quality", gga.fix_quality);
    put(json, "satellites", gga.satellites_used);
    put(json, "hdop", gga.hdop);
    put(json, "altitude_msl_m", gga.altitude_msl_m);
    put(json, "geoid_separation_m", gga.geoid_separation_m);
    put(json, "differential_age_s", gga.differential_age_s);
    put(json, "station_id", gga.differential_station_id);
}

void add_fields(Json& json, const RmcData& rmc) {
    put(json, "utc_time", rmc.utc_time);
    put(json, "date", rmc.date);
    put(json, "status", rmc.status);
    put_position(json, rmc.position);
    put(json, "speed_knots", rmc.speed_knots);
    put(json, "speed_m_s", rmc.speed_m_s);
    put(json, "course_deg", rmc.course_true_deg);
    put(json, "magnetic_variation_deg", rmc.magnetic_variation_deg);
    put(json, "mode", rmc.mode);
    put(json, "navigational_status", rmc.navigational_status);
}

void add_fields(Json& json, const VtgData& vtg) {
    put(json, "course_deg", vtg.course_true_deg);
    put(json, "course_magnetic_deg", vtg.course_magnetic_deg);
    put(json, "speed_knots", vtg.speed_knots);
    put(json, "speed_km_h", vtg.speed_km_h);
    put(json, "speed_m_s", vtg.speed_m_s);
    put(json, "mode", vtg.mode);
}

void add_fields(Json& json, const GllData& gll) {
    put(json, "utc_time", gll.utc_time);
    put(json, "status", gll.status);
    put_position(json, gll.position);
    put(json, "mode", gll.mode);
}

void add_fields(Json& json, const ZdaData& zda) {
    put(json, "utc_time", zda.utc_time);
    put(json, "date", zda.date);
    put(json, "local_zone_hours", zda.local_zone_hours);
    put(json, "local_zone_minutes", zda.local_zone_minutes);
}

void add_fields(Json& json, const HdtData& hdt) { put(json, "heading_deg", hdt.heading_true_deg); }

void add_fields(Json& json, const UndecodedData& undecoded) { json["fields"] = undecoded.fields; }

Json to_json(const Sentence& sentence) {
    Json json;
    json["talker"] = sentence.talker;
    json["type"] = sentence.type;
    json["decoded"] = sentence.is_decoded();
    std::visit([&json](const auto& data) { add_fields(json, data); }, sentence.data);
    return json;
}

Json error_json(std::string_view message, ParseErrorCode code, std::size_t line_number) {
    Json json;
    json["error"] = message;
    json["code"] = to_string(code);
    json["line"] = line_number;
    return json;
}

void write(std::ostream& out, const Json& json) {
    // Messages and fields are ASCII by construction; `replace` is a second guard
    // so that no input byte can make dump() throw.
    out << json.dump(-1, ' ', false, Json::error_handler_t::replace) << '\n';
}

}  // namespace

int decode_stream(std::istream& in, std::ostream& out) {
    std::streambuf* input = in.rdbuf();
    if (input == nullptr) return 1;
    bool all_decoded = true;
    std::size_t line_number = 0;
    InputLine line;
    while (read_line(*input, line)) {
        ++line_number;
        if (is_skipped(line.text)) continue;
        if (line.truncated()) {
            all_decoded = false;
            write(out, error_json("line is " + std::to_string(line.length) +
                                      " bytes long, far beyond any sentence; not parsed",
                                  ParseErrorCode::line_too_long, line_number));
            continue;
        }
        const ParseResult result = parse_sentence(line.text);
        if (result.ok()) {
            write(out, to_json(*result.sentence));
        } else {
            all_decoded = false;
            write(out, error_json(result.error->message, result.error->code, line_number));
        }
    }
    return all_decoded ? 0 : 1;
}

int decode_file(const std::filesystem::path& file, std::ostream& out, std::ostream& err) {
    // Streamed line by line, so any size is fine.
    const OpenOptions options{.no_follow = false, .max_bytes = std::numeric_limits<std::uint64_t>::max(),
                              .what = "NMEA capture"};
    try {
        const FileDescriptor fd = open_regular_file(AT_FDCWD, file, options, file);
        FdInputBuffer buffer(fd.get());
        std::istream in(&buffer);
        const int status = decode_stream(in, out);
        if (buffer.read_error() != 0) {
            err << "rig nmea decode: " << file.string() << ": read error: " << std::strerror(buffer.read_error())
                << "\n";
            return 2;
        }
        return status;
    } catch (const FileAccessError& error) {
        err << "rig nmea decode: " << error.what() << "\n";
        return 2;
    }
}

}  // namespace rig::nmea

namespace rig::harness {

NmeaCommand::NmeaCommand(CLI::App& app) {
    auto* nmea = app.add_subcommand("nmea", "NMEA tools");
    nmea->require_subcommand(1);
    decode_ = nmea->add_subcommand("decode", "decode NMEA lines with the controller's parser, one JSON per line");
    decode_->add_option("input", input_, "file, or - for standard input")->required();
}

bool NmeaCommand::parsed() const { return decode_->parsed(); }

int NmeaCommand::run() {
    if (input_ == "-") return nmea::decode_stream(std::cin, std::cout);
    return nmea::decode_file(input_, std::cout, std::cerr);
}

}  // namespace rig::harness
