#pragma once
// A value of a case file given on the command line (`rig run --set
// vehicle.speed_km_h=9`, `rig falsify --vary ...`): a key by its path in the
// file, and the value that replaces the one the file writes there.
//
// The setting is applied to the file's text before the loader reads it, in
// the place the file writes the value: the loader then checks the key's range
// and its relations to the rest of the case exactly as for the file's own
// value, its errors point at the file's line, and the text kept in the trace
// (meta `case_yaml`) is the case that ran, comments and all. So a point of a
// search written back into the file (worst.yaml) is the same case.
//
// Only a value the file writes can be set: a key the file leaves at its
// default has no place in the text, and a path that names nothing is the
// same mistake as a typo; both are an error naming the path and the nearest
// key the file does write.
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rig/config/config_error.h"

namespace rig::harness {

struct KeySetting {
    // Dotted path with list indices, as errors print keys: `gnss.dropouts[0].at_s`.
    std::string key;
    // A plain YAML scalar: a number, true/false, or a word (a choice key's value).
    std::string value;
};

// `KEY=VALUE` as --set takes it. Throws std::invalid_argument saying what is
// wrong with it (no '=', an empty or malformed key, a value that is not a
// plain scalar: quotes, spaces, YAML punctuation).
KeySetting parse_key_setting(std::string_view text);

// `key` is a well-formed path (names of [A-Za-z0-9_] joined by '.', each
// followed by any number of [N]); empty when it is, else why not.
std::string key_path_problem(std::string_view key);

// Where the file writes a key's value, and as what.
struct WrittenValue {
    std::string text;  // the scalar as written ("6.0", "fusion")
    SourceLocation where;
    std::size_t offset = 0;  // of its first character in the file's text
};

// The scalar value `key` has in the file's text. Throws rig::ConfigError (at
// the file, naming the key) when the path names no value the file writes, or
// names a mapping, a sequence or a quoted or multi-line scalar.
WrittenValue written_value(std::string_view yaml_text, const std::string& file_name, std::string_view key);

// The file's text with each setting's value in place of the one written
// (lines and columns of everything else unchanged). Throws rig::ConfigError
// as written_value does, and for a key set twice.
std::string apply_key_settings(std::string_view yaml_text, const std::string& file_name,
                               std::span<const KeySetting> settings);

// "--set vehicle.speed_km_h=9 --set gnss.latency_s=0.2", for errors and reports.
std::string settings_text(std::span<const KeySetting> settings);

}  // namespace rig::harness
