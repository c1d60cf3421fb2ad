#include "harness/spec/case_settings.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <optional>
#include <stdexcept>
#include <utility>

#include "rig/config/yaml_fields.h"

namespace rig::harness {

namespace {

bool is_name_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; }

// Characters a plain scalar from the command line may hold: enough for any
// number (1e-05, -3.5) and any choice word, and nothing that YAML reads as
// structure (':', '#', ',', brackets, quotes, spaces) when written into a file.
bool is_plain_value_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '.' || c == '-' || c == '+';
}

// One step of a key path: a mapping key, then the list indices after it.
struct PathStep {
    std::string name;
    std::vector<std::size_t> indices;
};

// The steps of a well-formed path (key_path_problem() empty).
std::vector<PathStep> path_steps(std::string_view key) {
    std::vector<PathStep> steps;
    std::size_t at = 0;
    while (at < key.size()) {
        PathStep step;
        while (at < key.size() && is_name_char(key[at])) step.name += key[at++];
        while (at < key.size() && key[at] == '[') {
            const std::size_t close = key.find(']', at);
            step.indices.push_back(static_cast<std::size_t>(std::stoull(std::string(key.substr(at + 1, close - at - 1)))));
            at = close + 1;
        }
        steps.push_back(std::move(step));
        if (at < key.size()) ++at;  // the '.'
    }
    return steps;
}

// Every scalar the file writes, by its path (for "did you mean").
void collect_scalar_paths(const YAML::Node& node, const std::string& path, std::vector<std::string>& paths) {
    if (node.IsScalar()) {
        paths.push_back(path);
    } else if (node.IsMap()) {
        for (const auto& entry : node) {
            if (!entry.first.IsScalar()) continue;
            collect_scalar_paths(entry.second, path.empty() ? entry.first.Scalar() : path + "." + entry.first.Scalar(),
                                 paths);
        }
    } else if (node.IsSequence()) {
        for (std::size_t index = 0; index < node.size(); ++index) {
            collect_scalar_paths(node[index], path + "[" + std::to_string(index) + "]", paths);
        }
    }
}

[[noreturn]] void fail_unwritten(const YAML::Node& root, const std::string& file_name, std::string_view key,
                                 const std::string& why) {
    std::vector<std::string> written;
    collect_scalar_paths(root, "", written);
    std::string message = why + "; a setting replaces a value the case file writes";
    if (const auto nearest = closest_spelling(key, written)) message += " (did you mean '" + *nearest + "'?)";
    throw ConfigError(SourceLocation{file_name, 0, 0, std::string(key)}, message);
}

}  // namespace

std::string key_path_problem(std::string_view key) {
    if (key.empty()) return "the key is empty";
    std::size_t at = 0;
    while (true) {
        const std::size_t name_start = at;
        while (at < key.size() && is_name_char(key[at])) ++at;
        if (at == name_start) return "a key name is missing at character " + std::to_string(at + 1);
        while (at < key.size() && key[at] == '[') {
            const std::size_t digits_start = ++at;
            while (at < key.size() && std::isdigit(static_cast<unsigned char>(key[at])) != 0) ++at;
            if (at == digits_start || at >= key.size() || key[at] != ']' || at - digits_start > 6) {
                return "a list index must be [N] with N a number of at most 6 digits";
            }
            ++at;
        }
        if (at == key.size()) return "";
        if (key[at] != '.') return std::string("unexpected '") + key[at] + "' at character " + std::to_string(at + 1);
        ++at;
    }
}

KeySetting parse_key_setting(std::string_view text) {
    const std::size_t equals = text.find('=');
    if (equals == std::string_view::npos) {
        throw std::invalid_argument("'" + std::string(text) + "' is not KEY=VALUE (e.g. vehicle.speed_km_h=9)");
    }
    KeySetting setting{std::string(text.substr(0, equals)), std::string(text.substr(equals + 1))};
    if (const std::string problem = key_path_problem(setting.key); !problem.empty()) {
        throw std::invalid_argument("'" + std::string(text) + "': key '" + setting.key + "': " + problem);
    }
    if (setting.value.empty()) throw std::invalid_argument("'" + std::string(text) + "': the value is empty");
    if (setting.value.size() > 64 || !std::all_of(setting.value.begin(), setting.value.end(), is_plain_value_char)) {
        throw std::invalid_argument("'" + std::string(text) +
                                    "': the value must be a number or a word (letters, digits, _ . + -; at most 64)");
    }
    return setting;
}

WrittenValue written_value(std::string_view yaml_text, const std::string& file_name, std::string_view key) {
    // The loader's own checks first (syntax, one document, a mapping at the top).
    (void)YamlSection::load_string(yaml_text, file_name);
    const YAML::Node root = YAML::Load(std::string(yaml_text));
    if (const std::string problem = key_path_problem(key); !problem.empty()) {
        throw ConfigError(SourceLocation{file_name, 0, 0, std::string(key)}, "not a key path: " + problem);
    }
    // reset(), not operator=: yaml-cpp's assignment writes into the node the
    // left side refers to, which would overwrite the file's tree as it walks.
    YAML::Node node;
    node.reset(root);
    std::string walked;
    for (const PathStep& step : path_steps(key)) {
        walked += (walked.empty() ? "" : ".") + step.name;
        // Looked up through a const node: a non-const lookup adds the key.
        const YAML::Node child = node.IsMap() ? std::as_const(node)[step.name] : YAML::Node(YAML::NodeType::Undefined);
        if (!child.IsDefined()) fail_unwritten(root, file_name, key, "the file writes no '" + walked + "'");
        node.reset(child);
        for (const std::size_t index : step.indices) {
            walked += "[" + std::to_string(index) + "]";
            if (!node.IsSequence()) fail_unwritten(root, file_name, key, "'" + walked + "': the file's value there is not a list");
            if (index >= node.size()) {
                fail_unwritten(root, file_name, key,
                               "'" + walked + "': the list has " + std::to_string(node.size()) + " item(s)");
            }
            const YAML::Node item = std::as_const(node)[index];
            node.reset(item);
        }
    }
    const YAML::Mark mark = node.Mark();
    const SourceLocation where{file_name, mark.line + 1, mark.column + 1, std::string(key)};
    if (!node.IsScalar()) {
        throw ConfigError(where, "is " + describe_node(node) + ", not a single value a setting can replace");
    }
    const std::string& scalar = node.Scalar();
    const auto offset = static_cast<std::size_t>(mark.pos);
    // Only a plain one-line scalar is its own text in the file; a quoted or
    // folded one is not a number the loader would take anyway.
    if (node.Tag() == "!" || offset >= yaml_text.size() || yaml_text.substr(offset, scalar.size()) != scalar ||
        scalar.find('\n') != std::string::npos) {
        throw ConfigError(where, "is written as a quoted or multi-line value, which a setting cannot replace");
    }
    return WrittenValue{scalar, where, offset};
}

std::string apply_key_settings(std::string_view yaml_text, const std::string& file_name,
                               std::span<const KeySetting> settings) {
    // Replaced from the end of the file, so that earlier offsets still hold.
    std::map<std::size_t, std::pair<std::size_t, std::string>, std::greater<>> replacements;
    std::map<std::string, std::string> seen;
    for (const KeySetting& setting : settings) {
        if (const auto [earlier, inserted] = seen.emplace(setting.key, setting.value); !inserted) {
            throw ConfigError(SourceLocation{file_name, 0, 0, setting.key},
                              "set twice (" + earlier->second + " and " + setting.value + ")");
        }
        const WrittenValue written = written_value(yaml_text, file_name, setting.key);
        replacements[written.offset] = {written.text.size(), setting.value};
    }
    std::string text(yaml_text);
    for (const auto& [offset, replacement] : replacements) text.replace(offset, replacement.first, replacement.second);
    return text;
}

std::string settings_text(std::span<const KeySetting> settings) {
    std::string text;
    for (const KeySetting& setting : settings) text += (text.empty() ? "" : " ") + std::string("--set ") + setting.key + "=" + setting.value;
    return text;
}

}  // namespace rig::harness
