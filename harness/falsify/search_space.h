#pragma once
// What `rig falsify` varies: keys of the case file by their path
// (harness/spec/case_settings.h), each over a range [low, high] that the
// key's own bounds allow, as the loader checks them, or over a list of
// choices (`controller.positioning=gnss,fusion`), each one the loader accepts.
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
    double base = 0.0;  // the value the base case has (file and --set); a choice key's: its index, if listed
    // A choice key (`KEY=A,B,C`): the values as written into the file, in the
    // order given. Its value in a point is the choice's index; as a
    // coordinate, low 0 and high the number of choices, [i, i + 1) standing
    // for choice i (the search itself fixes it per cell: falsify_search.h).
    std::vector<std::string> choices;
    std::string base_text;  // the base case's value as the file writes it

    bool is_choice() const { return !choices.empty(); }
};

// `KEY=LO:HI`, `KEY1,KEY2=LO:HI` or `KEY=A,B,...` (two or more distinct
// choices) as --vary takes it; throws std::invalid_argument saying what is wrong.
VaryRange parse_vary(std::string_view text);

// The range as --vary writes it: `KEY=LO:HI` or `KEY=A,B`.
std::string range_text(const VaryRange& range);

// The value a search's coordinate stands for: rounded to a whole number for
// an integer key, the choice's index for a choice key, and never outside
// [low, high] (a choice key: below the number of choices).
double snapped(const VaryRange& range, double value);
// Where a value lies on the search's unit interval of its range (a choice:
// the middle of its share), so that mapping it back gives the same value.
double unit_of(const VaryRange& range, double value);
// The value as it is written into the case file: the shortest text that
// reads back as the same double (a whole number for an integer key; the
// choice itself for a choice key).
std::string value_text(const VaryRange& range, double value);

// One point's settings: the base case's own (--set), then each range's keys at
// its coordinate.
std::vector<KeySetting> point_settings(const std::vector<KeySetting>& base, const std::vector<VaryRange>& ranges,
                                       const std::vector<double>& point);

}  // namespace rig::harness
