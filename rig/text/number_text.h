#pragma once
// Numbers as text, the one home for every way the rig prints a double. All
// are locale-independent (std::to_chars, whose general and fixed forms are
// specified as printf's %.*g and %.*f in the "C" locale), and none throws.
// What a caller shows for a value that is not a number (NaN: "-", "–",
// "not measured") is the caller's: these print nan and inf as printf does.
#include <charconv>
#include <string>

namespace rig {

// The shortest text that reads back as the same double: "0.16", "-60", "1e-05"
// (file:line errors quoting a value, gnuplot data, a store written to disk).
inline std::string shortest_text(double value) {
    char buffer[64];
    const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
    return error == std::errc{} ? std::string(buffer, end) : std::string("?");
}

// `digits` significant digits, as printf's %.{digits}g: "3.3", "1.716", "1e+06".
inline std::string significant_text(double value, int digits = 6) {
    char buffer[64];
    const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, digits);
    return error == std::errc{} ? std::string(buffer, end) : std::string("?");
}

// `decimals` digits after the point, as printf's %.{decimals}f: "1.70", "12.3".
inline std::string fixed_text(double value, int decimals) {
    char buffer[400];  // %f of the largest double has 309 digits before the point
    const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed, decimals);
    return error == std::errc{} ? std::string(buffer, end) : std::string("?");
}

// `value` with at least `min_digits` significant digits, and more when needed
// so that it does not print the same as a different `reference`: a value of
// 3.3000001 against a limit of 3.3 must not read "3.3 > 3.3".
inline std::string significant_text_against(double value, double reference, int min_digits = 4) {
    for (int digits = min_digits; digits < 17; ++digits) {
        const std::string text = significant_text(value, digits);
        if (value == reference || text != significant_text(reference, digits)) return text;
    }
    return significant_text(value, 17);
}

}  // namespace rig
