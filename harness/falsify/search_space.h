#pragma once
// What `rig falsify` varies: keys of the case file by their path
// (harness/spec/case_settings.h), each over a range [low, high] that the
// key's own bounds allow, as the loader checks them.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "harness/spec/case_settings.h"

namespace rig::harness {

struct VaryRange {
    // As given: one key path, or several joined by a comma that always take
    // the same value (a route's speed written at its start and in each segment).
    std::string key;
    std::vector<std::string> keys;  // `key` split at the commas
    double low = 0.0;
    double high = 0.0;
    // The file writes the key as a whole number (`pulses_per_rev: 1000`): it
    // is varied over whole numbers only.
    bool integer = false;
    double base = 0.0;  // the value the base case has (file and --set)
};

// `KEY=LO:HI` or `KEY1,KEY2=LO:HI` as --vary takes it; throws
// std::invalid_argument saying what is wrong.
VaryRange parse_vary(std::string_view text);

// The value a search's coordinate stands for: rounded to a whole number for
// an integer key, and never outside [low, high].
double snapped(const VaryRange& range, double value);
// The value as it is written into the case file: the shortest text that
// reads back as the same double (a whole number for an integer key).
std::string value_text(const VaryRange& range, double value);

// One point's settings: the base case's own (--set), then each range's keys at
// its coordinate.
std::vector<KeySetting> point_settings(const std::vector<KeySetting>& base, const std::vector<VaryRange>& ranges,
                                       const std::vector<double>& point);

}  // namespace rig::harness
