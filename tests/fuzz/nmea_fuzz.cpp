// libFuzzer harness: the controller's NMEA parser (rig/nmea/nmea_parser.h)
// and `rig nmea decode`'s stream decoder, on any bytes.
// Oracles beyond the sanitizers: exactly one of sentence and error is set; a
// decoded sentence holds only values its fields can mean (a latitude within
// +-90, a time of day, a month 1-12, finite numbers).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string_view>
#include <variant>

#include "harness/bench/nmea_decode_tool.h"
#include "rig/nmea/nmea_parser.h"

namespace {

using namespace rig::nmea;

void require(bool condition) {
    if (!condition) std::abort();  // a finding: libFuzzer keeps the input
}

void check_finite(const std::optional<double>& value) { require(!value || std::isfinite(*value)); }

void check(const std::optional<Position>& position) {
    if (!position) return;
    require(std::isfinite(position->lat_deg) && std::abs(position->lat_deg) <= 90.0);
    require(std::isfinite(position->lon_deg) && std::abs(position->lon_deg) <= 180.0);
}

void check(const std::optional<UtcTime>& time) {
    if (!time) return;
    require(time->hour >= 0 && time->hour <= 23 && time->minute >= 0 && time->minute <= 59);
    require(time->second >= 0.0 && time->second < 61.0);
}

void check(const std::optional<Date>& date) {
    if (!date) return;
    require(date->month >= 1 && date->month <= 12 && date->day >= 1 && date->day <= 31);
}

void check(const GgaData& gga) {
    check(gga.utc_time);
    check(gga.position);
    check_finite(gga.hdop);
    check_finite(gga.altitude_msl_m);
    check_finite(gga.geoid_separation_m);
    check_finite(gga.differential_age_s);
}
void check(const RmcData& rmc) {
    check(rmc.utc_time);
    check(rmc.position);
    check(rmc.date);
    check_finite(rmc.speed_knots);
    check_finite(rmc.speed_m_s);
    check_finite(rmc.course_true_deg);
    check_finite(rmc.magnetic_variation_deg);
}
void check(const VtgData& vtg) {
    check_finite(vtg.course_true_deg);
    check_finite(vtg.speed_knots);
    check_finite(vtg.speed_km_h);
    check_finite(vtg.speed_m_s);
}
void check(const GllData& gll) {
    check(gll.position);
    check(gll.utc_time);
}
void check(const ZdaData& zda) {
    check(zda.utc_time);
    check(zda.date);
}
void check(const HdtData& hdt) { check_finite(hdt.heading_true_deg); }
void check(const UndecodedData&) {}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    // One sentence, as the controller parses each line it receives.
    const ParseResult result = parse_sentence(bytes);
    require(result.sentence.has_value() != result.error.has_value());
    if (result.ok()) {
        require(!result.sentence->talker.empty());
        std::visit([](const auto& decoded) { check(decoded); }, result.sentence->data);
    } else {
        require(!result.error->message.empty());
    }
    // The whole input as a capture, line by line (`rig nmea decode`).
    std::istringstream in{std::string(bytes)};
    std::ostringstream out;
    const int status = decode_stream(in, out);
    require(status == 0 || status == 1);
    return 0;
}
