#include "harness/falsify/search_space.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

double finite_number(std::string_view text, const std::string& what) {
    double value = 0.0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || error != std::errc{} || end != text.data() + text.size() || !std::isfinite(value)) {
        throw std::invalid_argument(what + " '" + std::string(text) + "' is not a finite number");
    }
    return value;
}

}  // namespace

VaryRange parse_vary(std::string_view text) {
    const std::string whole(text);
    const std::size_t equals = text.find('=');
    const std::size_t colon = text.rfind(':');
    if (equals == std::string_view::npos || colon == std::string_view::npos || colon < equals) {
        throw std::invalid_argument("'" + whole + "' is not KEY=LO:HI (e.g. vehicle.speed_km_h=3:12)");
    }
    VaryRange range;
    range.key = std::string(text.substr(0, equals));
    for (std::size_t start = 0; start <= range.key.size();) {
        const std::size_t comma = std::min(range.key.find(',', start), range.key.size());
        range.keys.push_back(range.key.substr(start, comma - start));
        start = comma + 1;
    }
    for (const std::string& key : range.keys) {
        if (const std::string problem = key_path_problem(key); !problem.empty()) {
            throw std::invalid_argument("'" + whole + "': key '" + key + "': " + problem);
        }
    }
    range.low = finite_number(text.substr(equals + 1, colon - equals - 1), "'" + whole + "': LO");
    range.high = finite_number(text.substr(colon + 1), "'" + whole + "': HI");
    if (!(range.low < range.high)) {
        throw std::invalid_argument("'" + whole + "': LO must be below HI (" + shortest_text(range.low) +
                                    " >= " + shortest_text(range.high) + ")");
    }
    return range;
}

double snapped(const VaryRange& range, double value) {
    const double inside = std::clamp(value, range.low, range.high);
    if (!range.integer) return inside;
    return std::clamp(std::round(inside), std::ceil(range.low), std::floor(range.high));
}

std::string value_text(const VaryRange& range, double value) {
    const double snapped_value = snapped(range, value);
    if (range.integer) return std::to_string(static_cast<long long>(snapped_value));
    return shortest_text(snapped_value);
}

std::vector<KeySetting> point_settings(const std::vector<KeySetting>& base, const std::vector<VaryRange>& ranges,
                                       const std::vector<double>& point) {
    std::vector<KeySetting> settings = base;
    for (std::size_t index = 0; index < ranges.size(); ++index) {
        for (const std::string& key : ranges[index].keys) {
            const KeySetting setting{key, value_text(ranges[index], point[index])};
            // A varied key the base also sets: the point's value replaces it.
            const auto same = std::find_if(settings.begin(), settings.end(),
                                           [&](const KeySetting& given) { return given.key == setting.key; });
            if (same != settings.end()) {
                *same = setting;
            } else {
                settings.push_back(setting);
            }
        }
    }
    return settings;
}

}  // namespace rig::harness
