#include "controller/boundary/l4_laser_parser.h"

#include <cctype>
#include <string>

namespace rig::controller::boundary {
namespace {

constexpr std::size_t kMaxLineLength = 32;

L4Reading fail(std::string message, std::size_t column) {
    L4Reading r;
    r.error = message + " at column " + std::to_string(column + 1);
    return r;
}

bool is_digit(char c) { return c >= '0' && c <= '9'; }

}  // namespace

L4Reading parse_l4_line(std::string_view line) {
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
    if (line.empty()) return fail("empty line", 0);
    if (line.size() > kMaxLineLength) return fail("line longer than " + std::to_string(kMaxLineLength) + " characters", kMaxLineLength);
    for (std::size_t i = 0; i < line.size(); ++i) {
        const auto c = static_cast<unsigned char>(line[i]);
        if (c < 0x20 || c > 0x7E) return fail("non-printable byte", i);
    }
    if (line.size() < 3 || line[1] != '=') return fail("expected 'D=' or 'E='", 0);
    if (line[0] == 'E') {
        if (line.size() > 2 + 5) return fail("error code too long", 2);
        int code = 0;
        for (std::size_t i = 2; i < line.size(); ++i) {
            if (!is_digit(line[i])) return fail("error code must be digits", i);
            code = code * 10 + (line[i] - '0');
        }
        L4Reading r;
        r.device_error = code;
        return r;
    }
    if (line[0] != 'D') return fail("expected 'D=' or 'E='", 0);
    // D=<digits>.<digits>m
    std::size_t i = 2;
    const std::size_t int_start = i;
    while (i < line.size() && is_digit(line[i])) ++i;
    if (i == int_start) return fail("distance must start with a digit", i);
    if (i - int_start > 6) return fail("distance too large", int_start);
    if (i >= line.size() || line[i] != '.') return fail("expected '.' in the distance", i);
    ++i;
    const std::size_t frac_start = i;
    while (i < line.size() && is_digit(line[i])) ++i;
    if (i == frac_start) return fail("expected digits after '.'", i);
    if (i - frac_start > 6) return fail("too many decimals", frac_start);
    if (i >= line.size() || line[i] != 'm') return fail("expected unit 'm'", i);
    if (i + 1 != line.size()) return fail("unexpected text after the unit", i + 1);
    // Exact decimal digits to a double (at most 12 digits: fits in an int64).
    long long whole = 0;
    for (std::size_t k = int_start; k < frac_start - 1; ++k) whole = whole * 10 + (line[k] - '0');
    long long fraction = 0;
    double scale = 1.0;
    for (std::size_t k = frac_start; k < i; ++k) {
        fraction = fraction * 10 + (line[k] - '0');
        scale *= 10.0;
    }
    L4Reading r;
    r.distance_m = static_cast<double>(whole) + static_cast<double>(fraction) / scale;
    return r;
}

}  // namespace rig::controller::boundary
