#pragma once
// Strict reading of YAML configuration on top of yaml-cpp: every value is read
// through a YamlSection, which knows the file and key path, so every mistake
// (syntax, type, range, enum, missing key, unknown key, duplicate key, wrong
// kind of node) becomes a ConfigError at `file:line:col: key.path: message`.
//
// Typical use (one function per section keeps adding a section a local change):
//
//   YamlSection root = YamlSection::load_file("cases/bp.yaml");
//   YamlSection vehicle = root.section("vehicle");
//   double speed_km_h = vehicle.required_in_range<double>("speed_km_h", Bounds::open_closed(0, 30));
//   double accel_m_s2 = vehicle.optional_in_range<double>("accel_m_s2", 0.5, Bounds::open_closed(0, 5));
//   root.finish();   // unknown keys, then missing required keys, anywhere below root
//
// Why missing required keys are only reported by finish(): a missing key is most
// often a misspelt one, and only once every accessor has run is the full set of
// known keys available to say "unknown key 'speed_kmh'; did you mean 'speed_km_h'?"
// at the typo's own line instead of "speed_km_h missing" at the parent's. Until
// finish() has returned, a missing required value reads as T{} and must not be
// used for cross-field checks.
//
// Values present but wrong (type, range, enum, node kind) throw at once.
#include <yaml-cpp/yaml.h>

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "rig/config/config_error.h"

namespace rig {

// Configuration files are a few kilobytes (the largest case in cases/ is
// 2.3 KB); a megabyte is far beyond any, and bounds what parsing a wrong file
// (a log, a core dump) given by mistake can cost.
inline constexpr std::uint64_t kMaxConfigFileBytes = 1u << 20;

// An allowed interval for a number, each end open, closed or unbounded.
class Bounds {
public:
    static Bounds greater_than(double low);                  // (low, +inf)
    static Bounds at_least(double low);                      // [low, +inf)
    static Bounds less_than(double high);                    // (-inf, high)
    static Bounds at_most(double high);                      // (-inf, high]
    static Bounds open(double low, double high);             // (low, high)
    static Bounds closed(double low, double high);           // [low, high]
    static Bounds open_closed(double low, double high);      // (low, high]
    static Bounds closed_open(double low, double high);      // [low, high)

    bool contains(double value) const { return !violation(value).has_value(); }
    // Empty when the value is allowed; otherwise the violated side alone, e.g.
    // "must be > 0" or "must be <= 20", so the message says what to change.
    std::optional<std::string> violation(double value) const;
    // Interval notation, e.g. "(0, 30]".
    std::string describe() const;

private:
    std::optional<double> low_;
    std::optional<double> high_;
    bool low_inclusive_ = true;
    bool high_inclusive_ = true;
};

// The scalar types a config value can be read as. Integers are read exactly
// (no "1.0" for an integer, no "-1" for an unsigned one); numbers must be plain,
// finite decimals (quoted numbers are refused: `"6"` is a string in YAML);
// booleans are true/false.
template <class T>
concept ConfigScalar = std::same_as<T, double> || std::same_as<T, bool> || std::same_as<T, std::string> ||
                       std::same_as<T, int> || std::same_as<T, std::int64_t> || std::same_as<T, std::uint32_t> ||
                       std::same_as<T, std::uint64_t>;

// One spelling of an enumerated setting and the C++ value it stands for.
template <class E>
struct EnumChoice {
    std::string_view name;
    E value;
};

// A sub-tree kept as written, for a consumer that validates its own keys (the
// controller under test). `location` is where it starts in the file (or, when
// absent, where its parent mapping is), so that consumer can report
// `file:line:col` too, e.g. by wrapping `node` in a YamlSection.
struct RawYaml {
    YAML::Node node;  // a null node when absent: check `present`
    SourceLocation location;
    bool present = false;

    RawYaml() = default;
    RawYaml(YAML::Node node_, SourceLocation location_, bool present_)
        : node(std::move(node_)), location(std::move(location_)), present(present_) {}
    RawYaml(const RawYaml&) = default;
    RawYaml(RawYaml&&) = default;
    RawYaml& operator=(RawYaml&& other) { return *this = static_cast<const RawYaml&>(other); }
    // Assignment takes the other's node, as a value would. yaml-cpp's own
    // Node::operator= writes the right side into the node the left one refers
    // to, which every copy of it shares: moving cases about in a vector then
    // gave one case the controller section of its neighbour.
    RawYaml& operator=(const RawYaml& other) {
        node.reset(other.node);
        location = other.location;
        present = other.present;
        return *this;
    }
};

class YamlSection {
public:
    // Reads and parses a whole file. Unreadable file, YAML syntax error, empty
    // file, several documents, or a top level that is not a mapping: ConfigError.
    // Errors name the file as `path.string()`.
    static YamlSection load_file(const std::filesystem::path& path);
    // Same from text already in memory; `file_name` is what errors call it.
    static YamlSection load_string(std::string_view yaml_text, const std::string& file_name);

    // Wraps an already parsed mapping (e.g. a RawYaml handed to a consumer).
    // Checks the whole tree for duplicate keys, non-scalar keys and alias cycles.
    // An undefined or null node is an empty section.
    YamlSection(const YAML::Node& node, std::string file_name, std::string key_path = {});
    // Wraps a kept sub-tree; errors about an absent or empty one point where it was.
    explicit YamlSection(const RawYaml& raw);

    const std::string& file() const;
    const std::string& key_path() const;
    // False when the section is absent from the file (then it is empty, and
    // optional values take their defaults).
    bool present() const;
    // Where the section is: its mapping, or for an absent one its parent's.
    SourceLocation location() const;
    // Where `key`'s value is; its key when the value is empty; the section itself
    // when the key is absent. key_path is always the child path.
    SourceLocation location(std::string_view key) const;
    SourceLocation key_location(std::string_view key) const;
    // Item `index` of the sequence under `key` (e.g. `expect.fail[1]`).
    SourceLocation item_location(std::string_view key, std::size_t index) const;

    // Whether `key` is in the file. Marks the key as known.
    bool has(std::string_view key) const;
    // Marks a key as known without reading it (one the caller handles otherwise).
    void allow(std::string_view key) const;
    // Every key in the mapping, in file order (for mappings whose keys are data,
    // e.g. limits: name -> value). Does not mark anything as known.
    std::vector<std::string> keys() const;

    template <ConfigScalar T>
    T required(std::string_view key) const;
    template <ConfigScalar T>
    T optional(std::string_view key, T fallback) const;
    // Absent -> nullopt; present -> the value (type-checked).
    template <ConfigScalar T>
    std::optional<T> maybe(std::string_view key) const;

    template <ConfigScalar T>
        requires(!std::same_as<T, std::string> && !std::same_as<T, bool>)
    T required_in_range(std::string_view key, const Bounds& bounds) const;
    template <ConfigScalar T>
        requires(!std::same_as<T, std::string> && !std::same_as<T, bool>)
    T optional_in_range(std::string_view key, T fallback, const Bounds& bounds) const;

    // String-valued enumerations: "must be one of lockstep, realtime; got 'lockstp' (did you mean 'lockstep'?)".
    std::string required_enum(std::string_view key, std::span<const std::string_view> choices) const;
    std::string optional_enum(std::string_view key, std::initializer_list<std::string_view> choices,
                              std::string_view fallback) const;
    std::string optional_enum(std::string_view key, std::span<const std::string_view> choices,
                              std::string_view fallback) const;
    // Enumerations mapped straight to a C++ enum.
    template <class E>
    E required_enum(std::string_view key, std::span<const EnumChoice<E>> choices) const;
    template <class E>
    E optional_enum(std::string_view key, std::span<const EnumChoice<std::type_identity_t<E>>> choices,
                    E fallback) const;

    // A child mapping. Absent or empty (`gnss:`) -> an empty section, so its
    // optional values take their defaults; not a mapping -> ConfigError.
    // Asking twice for the same key gives the same section.
    YamlSection section(std::string_view key) const;
    // Same, but absence is an error (reported by finish()).
    YamlSection required_section(std::string_view key) const;
    // A sequence of mappings (`dropouts: [ { at_s: 1, for_s: 2 } ]`); absent or
    // empty -> no items. Items are sections with paths `key[i]`.
    std::vector<YamlSection> list(std::string_view key) const;
    // A sequence of non-empty scalars; absent or empty -> no items.
    std::vector<std::string> string_list(std::string_view key) const;
    // A sub-tree kept verbatim; its keys are not checked here.
    RawYaml raw(std::string_view key) const;

    // Throws at `location(key)` / at the section itself.
    [[noreturn]] void fail(std::string_view key, const std::string& message) const;
    [[noreturn]] void fail(const std::string& message) const;

    // Checks this section and every section obtained from it: first any key that
    // no accessor asked about (the earliest in the file, with the closest known
    // key as a suggestion), then the first missing required key or section.
    // Call once after reading; values are trustworthy only after it returns.
    void finish() const;

    struct State;  // shared between copies; public only for the implementation

private:
    explicit YamlSection(std::shared_ptr<State> state);
    std::optional<std::size_t> choice_index(std::string_view key, std::span<const std::string_view> choices,
                                            bool required) const;
    std::shared_ptr<State> state_;
};

// Closest candidate to `word` by edit distance, if close enough to be a likely
// typo (used for unknown keys and enum values).
std::optional<std::string> closest_spelling(std::string_view word, std::span<const std::string> candidates);

// "a mapping", "a sequence", "an empty value" or the scalar quoted: `'fast'`.
std::string describe_node(const YAML::Node& node);

template <class E>
E YamlSection::required_enum(std::string_view key, std::span<const EnumChoice<E>> choices) const {
    std::vector<std::string_view> names;
    for (const EnumChoice<E>& choice : choices) names.push_back(choice.name);
    const std::optional<std::size_t> index = choice_index(key, names, /*required=*/true);
    return index ? choices[*index].value : choices.front().value;  // placeholder until finish() reports the miss
}

template <class E>
E YamlSection::optional_enum(std::string_view key, std::span<const EnumChoice<std::type_identity_t<E>>> choices,
                             E fallback) const {
    std::vector<std::string_view> names;
    for (const EnumChoice<E>& choice : choices) names.push_back(choice.name);
    const std::optional<std::size_t> index = choice_index(key, names, /*required=*/false);
    return index ? choices[*index].value : fallback;
}

}  // namespace rig
