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

// `A,B,...` after a choice key's `=`: two or more, none empty, none twice.
std::vector<std::string> parse_choices(std::string_view list, const std::string& whole) {
    std::vector<std::string> choices;
    for (std::size_t start = 0; start <= list.size();) {
        const std::size_t comma = std::min(list.find(',', start), list.size());
        std::string choice(list.substr(start, comma - start));
        if (choice.empty() || choice.find_first_of(" \t\"'#{}[]") != std::string::npos) {
            throw std::invalid_argument("'" + whole + "': choice '" + choice +
                                        "' is not a plain word or number (choices are A,B,...: gnss,fusion)");
        }
        if (std::find(choices.begin(), choices.end(), choice) != choices.end()) {
            throw std::invalid_argument("'" + whole + "': choice '" + choice + "' is given twice");
        }
        choices.push_back(std::move(choice));
        start = comma + 1;
    }
    if (choices.size() < 2) {
        throw std::invalid_argument("'" + whole + "' is neither KEY=LO:HI nor KEY=A,B,... (two choices or more)");
    }
    return choices;
}

}  // namespace

VaryRange parse_vary(std::string_view text) {
    const std::string whole(text);
    const std::size_t equals = text.find('=');
    const std::size_t colon = text.rfind(':');
    if (equals == std::string_view::npos) {
        throw std::invalid_argument("'" + whole + "' is not KEY=LO:HI (e.g. vehicle.speed_km_h=3:12) or KEY=A,B,... "
                                    "(e.g. controller.positioning=gnss,fusion)");
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
    if (colon == std::string_view::npos || colon < equals) {
        range.choices = parse_choices(text.substr(equals + 1), whole);
        range.low = 0.0;
        range.high = static_cast<double>(range.choices.size());
        return range;
    }
    range.low = finite_number(text.substr(equals + 1, colon - equals - 1), "'" + whole + "': LO");
    range.high = finite_number(text.substr(colon + 1), "'" + whole + "': HI");
    if (!(range.low < range.high)) {
        throw std::invalid_argument("'" + whole + "': LO must be below HI (" + shortest_text(range.low) +
                                    " >= " + shortest_text(range.high) + ")");
    }
    return range;
}

std::string range_text(const VaryRange& range) {
    if (!range.is_choice()) return range.key + "=" + shortest_text(range.low) + ":" + shortest_text(range.high);
    std::string text = range.key + "=";
    for (std::size_t index = 0; index < range.choices.size(); ++index) {
        text += (index == 0 ? "" : ",") + range.choices[index];
    }
    return text;
}

double snapped(const VaryRange& range, double value) {
    const double inside = std::clamp(value, range.low, range.high);
    if (range.is_choice()) return std::min(std::floor(inside), static_cast<double>(range.choices.size() - 1));
    if (!range.integer) return inside;
    return std::clamp(std::round(inside), std::ceil(range.low), std::floor(range.high));
}

double unit_of(const VaryRange& range, double value) {
    const double coordinate = range.is_choice() ? snapped(range, value) + 0.5 : value;
    return (coordinate - range.low) / (range.high - range.low);
}

std::string value_text(const VaryRange& range, double value) {
    const double snapped_value = snapped(range, value);
    if (range.is_choice()) return range.choices[static_cast<std::size_t>(snapped_value)];
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
