#include "rig/nmea/nmea_encoder.h"

#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace rig::nmea {
namespace {

constexpr double kKnotsPerMetrePerSecond = 3600.0 / 1852.0;
constexpr std::int64_t kCentisecondsPerSecond = 100;
constexpr std::int64_t kCentisecondsPerMinute = 60 * kCentisecondsPerSecond;
constexpr std::int64_t kCentisecondsPerHour = 60 * kCentisecondsPerMinute;
constexpr std::int64_t kCentisecondsPerDay = 24 * kCentisecondsPerHour;
// Beyond this a double no longer holds every integer exactly; any field that
// large is garbage, not a measurement.
constexpr double kLargestScaledValue = 9.0e15;

void append_integer(std::string& out, std::int64_t value, int min_digits) {
    std::array<char, 24> digits{};
    const auto [end, ec] = std::to_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec != std::errc{}) return;
    const auto length = static_cast<int>(end - digits.data());
    if (length < min_digits) out.append(static_cast<std::size_t>(min_digits - length), '0');
    out.append(digits.data(), end);
}

std::int64_t power_of_ten(int exponent) {
    std::int64_t result = 1;
    for (int i = 0; i < exponent; ++i) result *= 10;
    return result;
}

// A decimal number given as an integer count of 10^-decimals units, so that the
// digits and the sign are exact (no "-0.000").
void append_scaled(std::string& out, std::int64_t units, int decimals) {
    const std::int64_t unit = power_of_ten(decimals);
    if (units < 0) out += '-';
    const std::int64_t magnitude = units < 0 ? -units : units;
    append_integer(out, magnitude / unit, 1);
    if (decimals > 0) {
        out += '.';
        append_integer(out, magnitude % unit, decimals);
    }
}

// value rounded to `decimals` places.  Not finite or absurdly large: nothing is
// written (an empty field).
void append_fixed(std::string& out, double value, int decimals) {
    const double scaled = value * static_cast<double>(power_of_ten(decimals));
    if (!std::isfinite(scaled) || std::fabs(scaled) > kLargestScaledValue) return;
    append_scaled(out, std::llround(scaled), decimals);
}

// Time of day in whole centiseconds, rounded once so that 59.996 s becomes the
// next minute rather than "60.00", plus the days that rounding (or an input
// outside 0..86400 s) carried over.
struct WireTime {
    std::int64_t centiseconds_of_day = 0;
    int day_carry = 0;
};

std::optional<WireTime> to_wire_time(double seconds_of_day) {
    const double centiseconds = seconds_of_day * static_cast<double>(kCentisecondsPerSecond);
    if (!std::isfinite(centiseconds) || std::fabs(centiseconds) > kLargestScaledValue) {
        return std::nullopt;
    }
    const std::int64_t total = std::llround(centiseconds);
    std::int64_t days = total / kCentisecondsPerDay;
    std::int64_t remainder = total % kCentisecondsPerDay;
    if (remainder < 0) {
        remainder += kCentisecondsPerDay;
        --days;
    }
    return WireTime{remainder, static_cast<int>(days)};
}

void append_time(std::string& out, const std::optional<WireTime>& time) {
    if (!time) return;
    const std::int64_t cs = time->centiseconds_of_day;
    append_integer(out, cs / kCentisecondsPerHour, 2);
    append_integer(out, cs % kCentisecondsPerHour / kCentisecondsPerMinute, 2);
    append_integer(out, cs % kCentisecondsPerMinute / kCentisecondsPerSecond, 2);
    out += '.';
    append_integer(out, cs % kCentisecondsPerSecond, 2);
}

// A day past the end of the month rolls over into the next month (C++20's
// sys_days conversion counts on from the 1st), so a caller may add whole days
// to GnssFix::day.  An impossible date leaves the field empty.
void append_date_ddmmyy(std::string& out, const GnssFix& fix, int day_carry) {
    using namespace std::chrono;
    constexpr int kMaxDayOfMonthField = 255;  // what std::chrono::day can hold
    if (fix.month < 1 || fix.month > 12 || fix.day < 1 || fix.day > kMaxDayOfMonthField) return;
    const year_month_day date{year{fix.year} / month{static_cast<unsigned>(fix.month)} /
                              day{static_cast<unsigned>(fix.day)}};
    if (!date.year().ok()) return;
    const year_month_day carried{sys_days{date} + days{day_carry}};
    append_integer(out, static_cast<unsigned>(carried.day()), 2);
    append_integer(out, static_cast<unsigned>(carried.month()), 2);
    append_integer(out, (static_cast<int>(carried.year()) % 100 + 100) % 100, 2);
}

// Four fields "ddmm.mmmmmmmm,N,dddmm.mmmmmmmm,E".  The angle is rounded once, in
// whole 1e-8 minutes, and split into degrees and minutes afterwards, so minutes
// that round up to 60 carry into the degrees instead of printing "60.00000000".
void append_angle(std::string& out, double angle_deg, int degree_digits, char positive, char negative) {
    const std::int64_t minute_unit = power_of_ten(kMinuteDecimals);
    const std::int64_t units_per_degree = 60 * minute_unit;
    const std::int64_t units = std::llround(std::fabs(angle_deg) * 60.0 * static_cast<double>(minute_unit));
    append_integer(out, units / units_per_degree, degree_digits);
    append_integer(out, units % units_per_degree / minute_unit, 2);
    out += '.';
    append_integer(out, units % minute_unit, kMinuteDecimals);
    out += ',';
    // The hemisphere of what is printed: a value that rounds to zero is N / E.
    out += (angle_deg < 0.0 && units != 0) ? negative : positive;
}

void append_position(std::string& out, const GnssFix& fix, bool has_solution) {
    const bool printable = has_solution && std::isfinite(fix.lat_deg) && std::isfinite(fix.lon_deg) &&
                           std::fabs(fix.lat_deg) <= 90.0 && std::fabs(fix.lon_deg) <= 180.0;
    if (!printable) {
        out += ",,,";
        return;
    }
    constexpr int kLatitudeDegreeDigits = 2;
    constexpr int kLongitudeDegreeDigits = 3;
    append_angle(out, fix.lat_deg, kLatitudeDegreeDigits, 'N', 'S');
    out += ',';
    append_angle(out, fix.lon_deg, kLongitudeDegreeDigits, 'E', 'W');
}

// Age of corrections and reference station only mean something for a solution
// that uses corrections: DGPS, RTK fixed, RTK float.
bool is_differential(int fix_quality) { return fix_quality == 2 || fix_quality == 4 || fix_quality == 5; }

// NMEA 2.3 mode indicator for each GGA fix quality 0..8.
char rmc_mode(int fix_quality) {
    constexpr std::string_view kModeByQuality = "NADPRFEMS";
    if (fix_quality < 0 || fix_quality >= static_cast<int>(kModeByQuality.size())) return 'N';
    return kModeByQuality[static_cast<std::size_t>(fix_quality)];
}

std::uint8_t checksum_of(std::string_view body) {
    unsigned checksum = 0;
    for (char c : body) checksum ^= static_cast<unsigned char>(c);
    return static_cast<std::uint8_t>(checksum);
}

}  // namespace

std::string with_checksum(std::string_view body) {
    constexpr std::string_view kHexDigits = "0123456789ABCDEF";
    const std::uint8_t checksum = checksum_of(body);
    std::string sentence;
    sentence.reserve(body.size() + 6);
    sentence += '$';
    sentence += body;
    sentence += '*';
    sentence += kHexDigits[checksum >> 4];
    sentence += kHexDigits[checksum & 0x0F];
    sentence += "\r\n";
    return sentence;
}

std::string encode_gga(std::string_view talker, const GnssFix& fix) {
    constexpr int kHdopDecimals = 1;
    constexpr int kHeightDecimals = 3;  // millimetres: RTK resolution
    constexpr int kAgeDecimals = 1;
    constexpr int kStationIdDigits = 4;
    constexpr int kMaxStationId = 1023;
    const bool has_solution = fix.fix_quality != 0;
    std::string body(talker);
    body += "GGA,";
    append_time(body, to_wire_time(fix.utc_seconds_of_day));
    body += ',';
    append_position(body, fix, has_solution);
    body += ',';
    append_integer(body, fix.fix_quality, 1);
    body += ',';
    append_integer(body, fix.satellites, 2);
    body += ',';
    append_fixed(body, fix.hdop, kHdopDecimals);
    body += ',';
    if (has_solution) append_fixed(body, fix.altitude_msl_m, kHeightDecimals);
    body += ",M,";
    if (has_solution) append_fixed(body, fix.geoid_separation_m, kHeightDecimals);
    body += ",M,";
    if (is_differential(fix.fix_quality)) {
        if (fix.differential_age_s >= 0.0) append_fixed(body, fix.differential_age_s, kAgeDecimals);
        body += ',';
        if (fix.station_id >= 0 && fix.station_id <= kMaxStationId) {
            append_integer(body, fix.station_id, kStationIdDigits);
        }
    } else {
        body += ',';
    }
    return with_checksum(body);
}

std::string encode_rmc(std::string_view talker, const GnssFix& fix) {
    constexpr int kSpeedDecimals = 3;
    constexpr int kCourseDecimals = 3;
    const bool has_solution = fix.fix_quality != 0;
    const std::optional<WireTime> time = to_wire_time(fix.utc_seconds_of_day);
    std::string body(talker);
    body += "RMC,";
    append_time(body, time);
    body += has_solution ? ",A," : ",V,";
    append_position(body, fix, has_solution);
    body += ',';
    if (has_solution) append_fixed(body, fix.speed_m_s * kKnotsPerMetrePerSecond, kSpeedDecimals);
    body += ',';
    if (has_solution && std::isfinite(fix.course_deg)) {
        // Course in [0, 360): 359.9996 rounds to 360.000, which is printed as 0.000.
        const std::int64_t unit = power_of_ten(kCourseDecimals);
        const std::int64_t full_circle = 360 * unit;
        const std::int64_t units = std::llround(std::fmod(fix.course_deg, 360.0) * static_cast<double>(unit));
        append_scaled(body, (units % full_circle + full_circle) % full_circle, kCourseDecimals);
    }
    body += ',';
    if (time) append_date_ddmmyy(body, fix, time->day_carry);
    body += ",,,";  // magnetic variation and its direction: not known to a GNSS-only receiver
    body += has_solution ? rmc_mode(fix.fix_quality) : 'N';
    return with_checksum(body);
}

}  // namespace rig::nmea
