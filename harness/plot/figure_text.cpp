#include "harness/plot/figure_text.h"

#include <cmath>

#include "harness/output/xml_text.h"
#include "rig/text/number_text.h"

namespace rig::harness {

std::string exact_number(double value) {
    if (std::isnan(value)) return "NaN";
    return shortest_text(value);
}

std::string shown_number(double value, int significant_digits) {
    if (!std::isfinite(value)) return std::isnan(value) ? "\u2013" : (value > 0 ? "inf" : "-inf");
    return significant_text(value, significant_digits);
}

std::string fixed_number(double value, int decimals) {
    if (!std::isfinite(value)) return shown_number(value);
    return fixed_text(value, decimals);
}

std::string shown_against(double value, double limit) {
    if (!std::isfinite(value) || !std::isfinite(limit)) return shown_number(value);
    return significant_text_against(value, limit, 4);
}

std::string html(std::string_view text) { return xml_escape(text, false); }

std::string gnuplot_string(std::string_view text) {
    std::string quoted = "'";
    for (const char c : valid_utf8(text)) {
        const auto byte = static_cast<unsigned char>(c);
        if (byte < 0x20 || byte == 0x7F) {
            quoted += ' ';
        } else if (c == '\'') {
            quoted += "''";
        } else {
            quoted += c;
        }
    }
    return quoted + "'";
}

std::string shortened(std::string_view text, std::size_t max_code_points) {
    const std::string valid = valid_utf8(text);
    std::size_t count = 0;
    for (std::size_t i = 0; i < valid.size(); ++i) {
        if ((static_cast<unsigned char>(valid[i]) & 0xC0) == 0x80) continue;
        if (count == max_code_points) return valid.substr(0, i) + "\u2026";
        ++count;
    }
    return valid;
}

}  // namespace rig::harness
