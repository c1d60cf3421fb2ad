#include "rig/config/yaml_fields.h"

#include "rig/config/file_access.h"
#include "rig/text/number_text.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace rig {

namespace {

// Guards for documents built with aliases: a cycle (`a: &x [ *x ]`) or an
// exponential alias fan-out would otherwise make a tree walk never end.
constexpr std::size_t kMaxNodesPerDocument = 200'000;
constexpr std::size_t kMaxNestingDepth = 100;
// Scalars longer than this are cut in messages so an error stays one line.
constexpr std::size_t kMaxQuotedScalarChars = 40;

struct Document {
    std::string file;
    std::uint64_t next_sequence = 0;
};

struct Entry {
    std::string key;
    YAML::Node key_node;
    YAML::Node value;
};

// A required key or section that was asked for and not found; kept until
// finish() so an unknown-key typo can be reported first (see the header).
struct PendingMissing {
    ConfigError error;
    std::uint64_t sequence;
};

SourceLocation location_at(const std::string& file, const YAML::Mark& mark, std::string key_path) {
    SourceLocation where{file, 0, 0, std::move(key_path)};
    if (!mark.is_null() && mark.line >= 0) {
        where.line = mark.line + 1;
        where.column = mark.column + 1;
    }
    return where;
}

// A key as messages show it: one line, at most kMaxQuotedKeyChars (a key can
// be a multi-line scalar of any length; an error must stay one short line).
constexpr std::size_t kMaxQuotedKeyChars = 64;
std::string shown_key(std::string_view key) {
    std::string text(key.substr(0, kMaxQuotedKeyChars));
    for (char& c : text) {
        if (c == '\n' || c == '\r' || c == '\t') c = ' ';
    }
    if (key.size() > kMaxQuotedKeyChars) text += "...";
    return text;
}

std::string child_path(const std::string& parent, std::string_view key) {
    if (parent.empty()) return shown_key(key);
    std::string path = parent;
    path += '.';
    path += shown_key(key);
    return path;
}

std::string item_path(const std::string& parent, std::size_t index) {
    return parent + '[' + std::to_string(index) + ']';
}

// Shortest text that reads back as the same double ("0.16", not "0.160000").
std::string number_text(double value) { return shortest_text(value); }

bool is_quoted(const YAML::Node& scalar) {
    // yaml-cpp tags plain scalars "?" and quoted ones "!".
    return scalar.Tag() == "!";
}

std::string lowercase(std::string_view text) {
    std::string lowered(text);
    for (char& c : lowered) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return lowered;
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
    std::vector<std::size_t> previous(b.size() + 1);
    std::vector<std::size_t> current(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) previous[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        current[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t substitution = previous[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
            current[j] = std::min({previous[j] + 1, current[j - 1] + 1, substitution});
        }
        std::swap(previous, current);
    }
    return previous[b.size()];
}

std::string join(const std::vector<std::string>& words, std::string_view separator) {
    std::string text;
    for (std::size_t i = 0; i < words.size(); ++i) {
        if (i > 0) text += separator;
        text += words[i];
    }
    return text;
}

// Rejects what a strict reader cannot give a precise answer for: keys that are
// not plain names, duplicate keys (yaml-cpp keeps both and lookups would
// silently take one), and alias cycles or bombs.
class TreeChecker {
public:
    explicit TreeChecker(const std::string& file) : file_(file) {}

    void check(const YAML::Node& node, const std::string& path) {
        if (!node.IsDefined()) return;
        if (++visited_ > kMaxNodesPerDocument) {
            throw ConfigError(location_at(file_, node.Mark(), path),
                              "document too large (more than " + std::to_string(kMaxNodesPerDocument) +
                                  " nodes; aliases expanding?)");
        }
        for (const YAML::Node& ancestor : ancestors_) {
            if (ancestor.is(node)) {
                throw ConfigError(location_at(file_, node.Mark(), path), "an alias refers to its own ancestor");
            }
        }
        if (ancestors_.size() >= kMaxNestingDepth) {
            throw ConfigError(location_at(file_, node.Mark(), path),
                              "nested deeper than " + std::to_string(kMaxNestingDepth) + " levels");
        }
        if (node.IsMap()) {
            ancestors_.push_back(node);
            check_mapping(node, path);
            ancestors_.pop_back();
        } else if (node.IsSequence()) {
            ancestors_.push_back(node);
            std::size_t index = 0;
            for (const YAML::Node& item : node) check(item, item_path(path, index++));
            ancestors_.pop_back();
        }
    }

private:
    void check_mapping(const YAML::Node& mapping, const std::string& path) {
        // Hashed: a mapping of n keys is checked in O(n), not O(n^2) (a 10 MB
        // file of keys took 82 s to reject with a list).
        std::unordered_map<std::string, YAML::Mark> seen;
        for (auto it = mapping.begin(); it != mapping.end(); ++it) {
            // Copies: yaml-cpp's iterator `->` points into a temporary proxy.
            const YAML::Node key = it->first;
            const YAML::Node value = it->second;
            if (!key.IsScalar() || key.Scalar().empty()) {
                throw ConfigError(location_at(file_, key.Mark(), path),
                                  "keys must be plain names, got " + describe_node(key));
            }
            const std::string& name = key.Scalar();
            const std::string key_path = child_path(path, name);
            const auto [earlier, inserted] = seen.emplace(name, key.Mark());
            if (!inserted) {
                const YAML::Mark& earlier_mark = earlier->second;
                throw ConfigError(location_at(file_, key.Mark(), key_path),
                                  "duplicate key '" + shown_key(name) + "' (first at line " + std::to_string(earlier_mark.line + 1) +
                                      ", column " + std::to_string(earlier_mark.column + 1) + ")");
            }
            check(value, key_path);
        }
    }

    const std::string& file_;
    std::vector<YAML::Node> ancestors_;
    std::size_t visited_ = 0;
};

// Counts a text's documents without building them, for at most two.
//
// Not YAML::LoadAll: in yaml-cpp 0.7 (Debian 12) a ',' outside [ ] or { } at
// the top level (",", "[1]\n,") makes each HandleNextDocument() return an
// empty document without consuming the ','; LoadAll then loops forever,
// allocating (found by tests/fuzz/case_file_fuzz). A document that starts
// where the previous one did is that: reported as a syntax error there.
class DocumentCounter : public YAML::EventHandler {
public:
    void OnDocumentStart(const YAML::Mark& mark) override { start = mark; }
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
    void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
    void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
    void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
    void OnSequenceEnd() override {}
    void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
    void OnMapEnd() override {}
    YAML::Mark start = YAML::Mark::null_mark();
};

struct DocumentCount {
    int documents = 0;
    YAML::Mark second_start = YAML::Mark::null_mark();
};

DocumentCount count_documents(const std::string& text, const std::string& file_name) {
    std::istringstream in(text);
    DocumentCount count;
    try {
        YAML::Parser parser(in);
        DocumentCounter counter;
        YAML::Mark previous = YAML::Mark::null_mark();
        // Up to three, so a stuck ',' after a first document is told from a real second one.
        while (count.documents < 3 && parser.HandleNextDocument(counter)) {
            if (count.documents >= 1) {
                if (counter.start.pos == previous.pos) {
                    throw ConfigError(location_at(file_name, counter.start, ""),
                                      "YAML syntax error: a ',' outside [ ] or { } (or another token that "
                                      "starts no value)");
                }
                if (count.documents == 1) count.second_start = counter.start;
            }
            previous = counter.start;
            ++count.documents;
        }
    } catch (const YAML::Exception& error) {
        throw ConfigError(location_at(file_name, error.mark, ""), "YAML syntax error: " + error.msg);
    }
    return count;
}

template <class T>
constexpr std::string_view expected_kind() {
    if constexpr (std::same_as<T, double>) {
        return "a number";
    } else if constexpr (std::same_as<T, bool>) {
        return "true or false";
    } else if constexpr (std::same_as<T, std::string>) {
        return "a string";
    } else if constexpr (std::is_unsigned_v<T>) {
        return "a non-negative integer";
    } else {
        return "an integer";
    }
}

}  // namespace

// ---------------------------------------------------------------- Bounds

Bounds Bounds::greater_than(double low) {
    Bounds b;
    b.low_ = low;
    b.low_inclusive_ = false;
    return b;
}
Bounds Bounds::at_least(double low) {
    Bounds b;
    b.low_ = low;
    return b;
}
Bounds Bounds::less_than(double high) {
    Bounds b;
    b.high_ = high;
    b.high_inclusive_ = false;
    return b;
}
Bounds Bounds::at_most(double high) {
    Bounds b;
    b.high_ = high;
    return b;
}
Bounds Bounds::open(double low, double high) {
    Bounds b = greater_than(low);
    b.high_ = high;
    b.high_inclusive_ = false;
    return b;
}
Bounds Bounds::closed(double low, double high) {
    Bounds b = at_least(low);
    b.high_ = high;
    return b;
}
Bounds Bounds::open_closed(double low, double high) {
    Bounds b = greater_than(low);
    b.high_ = high;
    return b;
}
Bounds Bounds::closed_open(double low, double high) {
    Bounds b = at_least(low);
    b.high_ = high;
    b.high_inclusive_ = false;
    return b;
}

std::optional<std::string> Bounds::violation(double value) const {
    if (low_) {
        const bool below = low_inclusive_ ? value < *low_ : value <= *low_;
        if (below) return std::string(low_inclusive_ ? "must be >= " : "must be > ") + number_text(*low_);
    }
    if (high_) {
        const bool above = high_inclusive_ ? value > *high_ : value >= *high_;
        if (above) return std::string(high_inclusive_ ? "must be <= " : "must be < ") + number_text(*high_);
    }
    return std::nullopt;
}

std::string Bounds::describe() const {
    std::string text = low_ ? (low_inclusive_ ? "[" : "(") + number_text(*low_) : std::string("(-inf");
    text += ", ";
    text += high_ ? number_text(*high_) + (high_inclusive_ ? "]" : ")") : std::string("+inf)");
    return text;
}

// ---------------------------------------------------------------- free helpers

std::optional<std::string> closest_spelling(std::string_view word, std::span<const std::string> candidates) {
    const std::string lowered_word = lowercase(word);
    // Keys carry their unit (`speed_km_h`); writing the bare quantity (`speed`)
    // is the most likely slip, and too far by edit distance to be caught below.
    for (const std::string& candidate : candidates) {
        const std::string lowered = lowercase(candidate);
        if (lowered.size() > lowered_word.size() + 1 && lowered.starts_with(lowered_word) &&
            lowered[lowered_word.size()] == '_') {
            return candidate;
        }
    }
    // An enum value given without its qualifier (`float` for `rtk_float`).
    std::optional<std::string> qualified;
    int qualified_matches = 0;
    for (const std::string& candidate : candidates) {
        const std::string lowered = lowercase(candidate);
        if (lowered.size() > lowered_word.size() + 1 && lowered.ends_with(lowered_word) &&
            lowered[lowered.size() - lowered_word.size() - 1] == '_') {
            qualified = candidate;
            ++qualified_matches;
        }
    }
    if (qualified_matches == 1) return qualified;
    const std::size_t max_distance = word.size() <= 3 ? 1 : std::max<std::size_t>(2, (word.size() + 2) / 3);
    std::optional<std::string> best;
    std::size_t best_distance = max_distance + 1;
    for (const std::string& candidate : candidates) {
        const std::size_t distance = edit_distance(lowered_word, lowercase(candidate));
        if (distance < best_distance && distance < std::max(word.size(), candidate.size())) {
            best_distance = distance;
            best = candidate;
        }
    }
    return best;
}

std::string describe_node(const YAML::Node& node) {
    if (!node.IsDefined()) return "nothing";
    switch (node.Type()) {
        case YAML::NodeType::Null:
            return "an empty value";
        case YAML::NodeType::Map:
            return "a mapping";
        case YAML::NodeType::Sequence:
            return "a sequence";
        case YAML::NodeType::Scalar: {
            std::string text = node.Scalar();
            if (text.size() > kMaxQuotedScalarChars) text = text.substr(0, kMaxQuotedScalarChars) + "...";
            for (char& c : text) {
                if (c == '\n' || c == '\r' || c == '\t') c = ' ';
            }
            return (is_quoted(node) ? "the quoted string '" : "'") + text + "'";
        }
        case YAML::NodeType::Undefined:
            break;
    }
    return "nothing";
}

// ---------------------------------------------------------------- State

struct YamlSection::State {
    std::shared_ptr<Document> document;
    std::string path;
    SourceLocation location;
    bool present = false;
    std::vector<Entry> entries;
    // entries by key (keys are unique: the tree checker refuses duplicates).
    // Lookups are hashed so a section whose keys are data (limits) reads in
    // linear time however many it has.
    std::unordered_map<std::string, std::size_t> entry_index;
    std::vector<std::string> known_keys;  // in the order asked, for suggestions
    std::unordered_set<std::string> known_key_set;
    std::vector<std::pair<std::string, std::shared_ptr<State>>> sections;
    std::vector<std::pair<std::string, std::vector<std::shared_ptr<State>>>> lists;
    std::vector<PendingMissing> missing;

    const std::string& file() const { return document->file; }

    bool is_known(const std::string& key) const { return known_key_set.contains(key); }

    const Entry* find(std::string_view key) const {
        const auto it = entry_index.find(std::string(key));
        return it == entry_index.end() ? nullptr : &entries[it->second];
    }

    // Finds `key` and marks it as known.
    const Entry* lookup(std::string_view key) {
        std::string name(key);
        if (known_key_set.insert(name).second) known_keys.push_back(std::move(name));
        return find(key);
    }

    SourceLocation key_location(const Entry& entry) const {
        return location_at(file(), entry.key_node.Mark(), child_path(path, entry.key));
    }

    // yaml-cpp marks an empty value at the next token (often the next line), so
    // an empty value is reported at its key.
    SourceLocation value_location(const Entry& entry) const {
        if (entry.value.IsNull() || entry.value.Mark().is_null()) return key_location(entry);
        return location_at(file(), entry.value.Mark(), child_path(path, entry.key));
    }

    SourceLocation absent_location(std::string_view key) const {
        SourceLocation where = location;
        where.key_path = child_path(path, key);
        return where;
    }

    [[noreturn]] void fail_at(const Entry& entry, const std::string& message) const {
        throw ConfigError(value_location(entry), message);
    }

    void record_missing(std::string_view key, const std::string& message) {
        missing.push_back({ConfigError(absent_location(key), message), document->next_sequence++});
    }

    std::string missing_message(std::string_view what) const {
        std::string message = std::string("required ") + std::string(what) + " missing";
        if (!present && !path.empty()) message += " (the whole '" + path + "' section is absent)";
        return message;
    }
};

namespace {

using StatePtr = std::shared_ptr<YamlSection::State>;

StatePtr make_state(std::shared_ptr<Document> document, std::string path, const YAML::Node& node,
                    SourceLocation location, bool present) {
    auto state = std::make_shared<YamlSection::State>();
    state->document = std::move(document);
    state->path = std::move(path);
    state->location = std::move(location);
    state->present = present;
    if (node.IsDefined() && node.IsMap()) {
        for (auto it = node.begin(); it != node.end(); ++it) {
            state->entry_index.emplace(it->first.Scalar(), state->entries.size());
            state->entries.push_back(Entry{it->first.Scalar(), it->first, it->second});
        }
    }
    return state;
}

template <class T>
T convert_scalar(const YamlSection::State& state, const Entry& entry, bool has_default) {
    const YAML::Node& value = entry.value;
    const std::string_view kind = expected_kind<T>();
    if (value.IsNull()) {
        std::string message = "empty value, expected " + std::string(kind);
        if (has_default) message += "; remove the key to use the default";
        state.fail_at(entry, message);
    }
    if (!value.IsScalar()) state.fail_at(entry, "expected " + std::string(kind) + ", got " + describe_node(value));
    const std::string& text = value.Scalar();
    if constexpr (std::same_as<T, std::string>) {
        return text;
    } else {
        if (is_quoted(value)) {
            state.fail_at(entry, "expected " + std::string(kind) + ", got " + describe_node(value) +
                                     " (write it without quotes)");
        }
        if constexpr (std::same_as<T, bool>) {
            if (text == "true" || text == "True" || text == "TRUE") return true;
            if (text == "false" || text == "False" || text == "FALSE") return false;
            state.fail_at(entry, "expected true or false, got " + describe_node(value));
        } else {
            // from_chars takes no leading '+', which YAML numbers may have.
            std::string_view digits = text;
            if (digits.size() > 1 && digits.front() == '+' && digits[1] != '-' && digits[1] != '+') {
                digits.remove_prefix(1);
            }
            const char* const begin = digits.data();
            const char* const end = begin + digits.size();
            T parsed{};
            std::from_chars_result result{};
            if constexpr (std::same_as<T, double>) {
                result = std::from_chars(begin, end, parsed, std::chars_format::general);
            } else {
                result = std::from_chars(begin, end, parsed, 10);
            }
            const bool whole = result.ptr == end && !digits.empty();
            if (result.ec == std::errc::result_out_of_range && whole) {
                if constexpr (std::same_as<T, double>) {
                    state.fail_at(entry, "number out of range, got " + describe_node(value));
                } else {
                    state.fail_at(entry, "must be between " + std::to_string(std::numeric_limits<T>::min()) +
                                             " and " + std::to_string(std::numeric_limits<T>::max()) + ", got " +
                                             describe_node(value));
                }
            }
            if (result.ec != std::errc{} || !whole) {
                state.fail_at(entry, "expected " + std::string(kind) + ", got " + describe_node(value));
            }
            if constexpr (std::same_as<T, double>) {
                if (!std::isfinite(parsed)) {
                    state.fail_at(entry, "expected a finite number, got " + describe_node(value));
                }
            }
            return parsed;
        }
    }
}

struct UnknownKey {
    const YamlSection::State* state;
    const Entry* entry;
    SourceLocation where;
};

// Every key no accessor asked about; the message is made later for the one
// reported (a suggestion costs an edit distance per known key, too much to
// spend on each of thousands of unknown keys).
void collect_unknown_keys(const YamlSection::State& state, std::vector<UnknownKey>& unknown) {
    for (const Entry& entry : state.entries) {
        if (!state.is_known(entry.key)) unknown.push_back({&state, &entry, state.key_location(entry)});
    }
    for (const auto& [key, child] : state.sections) collect_unknown_keys(*child, unknown);
    for (const auto& [key, items] : state.lists) {
        for (const StatePtr& item : items) collect_unknown_keys(*item, unknown);
    }
}

ConfigError unknown_key_error(const UnknownKey& unknown) {
    const YamlSection::State& state = *unknown.state;
    const std::string& key = unknown.entry->key;
    std::string message = "unknown key '" + shown_key(key) + "'";
    if (state.known_keys.empty()) {
        message += "; nothing is allowed here";
    } else if (const auto suggestion = closest_spelling(key, state.known_keys)) {
        message += "; did you mean '" + *suggestion + "'?";
    } else {
        std::vector<std::string> sorted = state.known_keys;
        std::sort(sorted.begin(), sorted.end());
        message += "; known keys here: " + join(sorted, ", ");
    }
    return ConfigError(unknown.where, message);
}

void collect_missing(const YamlSection::State& state, std::vector<const PendingMissing*>& missing) {
    for (const PendingMissing& pending : state.missing) missing.push_back(&pending);
    for (const auto& [key, child] : state.sections) collect_missing(*child, missing);
    for (const auto& [key, items] : state.lists) {
        for (const StatePtr& item : items) collect_missing(*item, missing);
    }
}

}  // namespace

// ---------------------------------------------------------------- YamlSection

YamlSection::YamlSection(std::shared_ptr<State> state) : state_(std::move(state)) {}

YamlSection::YamlSection(const YAML::Node& node, std::string file_name, std::string key_path) {
    auto document = std::make_shared<Document>();
    document->file = std::move(file_name);
    TreeChecker(document->file).check(node, key_path);
    const bool present = node.IsDefined();
    SourceLocation where = location_at(document->file, present ? node.Mark() : YAML::Mark::null_mark(), key_path);
    if (present && !node.IsNull() && !node.IsMap()) {
        throw ConfigError(where, "expected a mapping (key: value lines), got " + describe_node(node));
    }
    state_ = make_state(std::move(document), std::move(key_path), node, std::move(where), present);
}

YamlSection::YamlSection(const RawYaml& raw) : YamlSection(raw.node, raw.location.file, raw.location.key_path) {
    state_->present = raw.present;
    // An empty or absent sub-tree has no useful mark of its own (see value_location).
    if (!raw.present || raw.node.IsNull() || state_->location.line == 0) state_->location = raw.location;
}

YamlSection YamlSection::load_string(std::string_view yaml_text, const std::string& file_name) {
    const std::string text(yaml_text);
    const DocumentCount count = count_documents(text, file_name);
    if (count.documents == 0) {
        throw ConfigError(SourceLocation{file_name, 1, 1, ""},
                          "the file is empty; expected a mapping of settings (key: value lines)");
    }
    if (count.documents > 1) {
        throw ConfigError(location_at(file_name, count.second_start, ""),
                          "a second YAML document ('---') in the file; one file holds one document");
    }
    YAML::Node root;
    try {
        root = YAML::Load(text);  // the first document only: never LoadAll's loop
    } catch (const YAML::Exception& error) {
        throw ConfigError(location_at(file_name, error.mark, ""), "YAML syntax error: " + error.msg);
    }
    if (!root.IsMap()) {
        throw ConfigError(location_at(file_name, root.IsNull() ? YAML::Mark{} : root.Mark(), ""),
                          "expected a mapping of settings (key: value lines) at the top level, got " +
                              describe_node(root));
    }
    return YamlSection(root, file_name);
}

YamlSection YamlSection::load_file(const std::filesystem::path& path) {
    const std::string file_name = path.string();
    const SourceLocation whole_file{file_name, 0, 0, "(file)"};
    std::string text;
    try {
        // Regular files only (a FIFO would block, a device never end) and of a
        // bounded size (see kMaxConfigFileBytes).
        text = read_regular_file(path, OpenOptions{.no_follow = false, .max_bytes = kMaxConfigFileBytes,
                                                   .what = "YAML file"});
    } catch (const FileAccessError& error) {
        throw ConfigError(whole_file, error.problem());
    }
    return load_string(text, file_name);
}

const std::string& YamlSection::file() const { return state_->file(); }
const std::string& YamlSection::key_path() const { return state_->path; }
bool YamlSection::present() const { return state_->present; }
SourceLocation YamlSection::location() const { return state_->location; }

SourceLocation YamlSection::location(std::string_view key) const {
    if (const Entry* entry = state_->find(key)) return state_->value_location(*entry);
    return state_->absent_location(key);
}

SourceLocation YamlSection::key_location(std::string_view key) const {
    if (const Entry* entry = state_->find(key)) return state_->key_location(*entry);
    return state_->absent_location(key);
}

SourceLocation YamlSection::item_location(std::string_view key, std::size_t index) const {
    const Entry* entry = state_->find(key);
    if (entry != nullptr && entry->value.IsSequence() && index < entry->value.size()) {
        const YAML::Node item = entry->value[index];
        const YAML::Mark mark = item.IsNull() ? entry->value.Mark() : item.Mark();
        return location_at(file(), mark, item_path(child_path(state_->path, key), index));
    }
    return location(key);
}

bool YamlSection::has(std::string_view key) const { return state_->lookup(key) != nullptr; }

void YamlSection::allow(std::string_view key) const { state_->lookup(key); }

std::vector<std::string> YamlSection::keys() const {
    std::vector<std::string> names;
    for (const Entry& entry : state_->entries) names.push_back(entry.key);
    return names;
}

template <ConfigScalar T>
std::optional<T> YamlSection::maybe(std::string_view key) const {
    const Entry* entry = state_->lookup(key);
    if (entry == nullptr) return std::nullopt;
    return convert_scalar<T>(*state_, *entry, /*has_default=*/false);
}

template <ConfigScalar T>
T YamlSection::required(std::string_view key) const {
    const Entry* entry = state_->lookup(key);
    if (entry == nullptr) {
        state_->record_missing(key, state_->missing_message("key"));
        return T{};
    }
    return convert_scalar<T>(*state_, *entry, /*has_default=*/false);
}

template <ConfigScalar T>
T YamlSection::optional(std::string_view key, T fallback) const {
    const Entry* entry = state_->lookup(key);
    if (entry == nullptr) return fallback;
    return convert_scalar<T>(*state_, *entry, /*has_default=*/true);
}

template <ConfigScalar T>
    requires(!std::same_as<T, std::string> && !std::same_as<T, bool>)
T YamlSection::required_in_range(std::string_view key, const Bounds& bounds) const {
    const Entry* entry = state_->lookup(key);
    if (entry == nullptr) {
        state_->record_missing(key, state_->missing_message("key") + ", allowed " + bounds.describe());
        return T{};
    }
    const T value = convert_scalar<T>(*state_, *entry, /*has_default=*/false);
    if (const auto violation = bounds.violation(static_cast<double>(value))) {
        state_->fail_at(*entry, *violation + ", got " + entry->value.Scalar());
    }
    return value;
}

template <ConfigScalar T>
    requires(!std::same_as<T, std::string> && !std::same_as<T, bool>)
T YamlSection::optional_in_range(std::string_view key, T fallback, const Bounds& bounds) const {
    const Entry* entry = state_->lookup(key);
    if (entry == nullptr) return fallback;
    const T value = convert_scalar<T>(*state_, *entry, /*has_default=*/true);
    if (const auto violation = bounds.violation(static_cast<double>(value))) {
        state_->fail_at(*entry, *violation + ", got " + entry->value.Scalar());
    }
    return value;
}

#define RIG_INSTANTIATE_SCALAR(T)                                            \
    template T YamlSection::required<T>(std::string_view) const;             \
    template T YamlSection::optional<T>(std::string_view, T) const;          \
    template std::optional<T> YamlSection::maybe<T>(std::string_view) const;
#define RIG_INSTANTIATE_NUMBER(T)                                                           \
    template T YamlSection::required_in_range<T>(std::string_view, const Bounds&) const;    \
    template T YamlSection::optional_in_range<T>(std::string_view, T, const Bounds&) const;

RIG_INSTANTIATE_SCALAR(double)
RIG_INSTANTIATE_SCALAR(bool)
RIG_INSTANTIATE_SCALAR(std::string)
RIG_INSTANTIATE_SCALAR(int)
RIG_INSTANTIATE_SCALAR(std::int64_t)
RIG_INSTANTIATE_SCALAR(std::uint32_t)
RIG_INSTANTIATE_SCALAR(std::uint64_t)
RIG_INSTANTIATE_NUMBER(double)
RIG_INSTANTIATE_NUMBER(int)
RIG_INSTANTIATE_NUMBER(std::int64_t)
RIG_INSTANTIATE_NUMBER(std::uint32_t)
RIG_INSTANTIATE_NUMBER(std::uint64_t)
#undef RIG_INSTANTIATE_SCALAR
#undef RIG_INSTANTIATE_NUMBER

std::optional<std::size_t> YamlSection::choice_index(std::string_view key, std::span<const std::string_view> choices,
                                                     bool required) const {
    std::vector<std::string> names(choices.begin(), choices.end());
    const std::string allowed = join(names, ", ");
    const Entry* entry = state_->lookup(key);
    if (entry == nullptr) {
        if (required) state_->record_missing(key, state_->missing_message("key") + ", one of " + allowed);
        return std::nullopt;
    }
    if (!entry->value.IsScalar()) {
        state_->fail_at(*entry, "expected one of " + allowed + ", got " + describe_node(entry->value));
    }
    const std::string& text = entry->value.Scalar();
    for (std::size_t i = 0; i < choices.size(); ++i) {
        if (choices[i] == text) return i;
    }
    std::string message = "must be one of " + allowed + "; got " + describe_node(entry->value);
    if (const auto suggestion = closest_spelling(text, names)) message += " (did you mean '" + *suggestion + "'?)";
    state_->fail_at(*entry, message);
}

std::string YamlSection::required_enum(std::string_view key, std::span<const std::string_view> choices) const {
    const auto index = choice_index(key, choices, /*required=*/true);
    return index ? std::string(choices[*index]) : std::string();
}

std::string YamlSection::optional_enum(std::string_view key, std::initializer_list<std::string_view> choices,
                                       std::string_view fallback) const {
    return optional_enum(key, std::span<const std::string_view>(choices.begin(), choices.size()), fallback);
}

std::string YamlSection::optional_enum(std::string_view key, std::span<const std::string_view> choices,
                                       std::string_view fallback) const {
    const auto index = choice_index(key, choices, /*required=*/false);
    return std::string(index ? choices[*index] : fallback);
}

YamlSection YamlSection::section(std::string_view key) const {
    for (const auto& [name, child] : state_->sections) {
        if (name == key) return YamlSection(child);
    }
    const Entry* entry = state_->lookup(key);
    const std::string path = child_path(state_->path, key);
    StatePtr child;
    if (entry == nullptr) {
        child = make_state(state_->document, path, YAML::Node(), state_->absent_location(key), /*present=*/false);
    } else if (entry->value.IsNull()) {
        child = make_state(state_->document, path, entry->value, state_->key_location(*entry), /*present=*/true);
    } else if (entry->value.IsMap()) {
        child = make_state(state_->document, path, entry->value, state_->value_location(*entry), /*present=*/true);
    } else {
        state_->fail_at(*entry, "expected a mapping (key: value), got " + describe_node(entry->value));
    }
    state_->sections.emplace_back(std::string(key), child);
    return YamlSection(child);
}

YamlSection YamlSection::required_section(std::string_view key) const {
    const bool was_present = state_->lookup(key) != nullptr;
    YamlSection child = section(key);
    if (!was_present) state_->record_missing(key, state_->missing_message("section"));
    return child;
}

std::vector<YamlSection> YamlSection::list(std::string_view key) const {
    auto as_sections = [](const std::vector<StatePtr>& items) {
        std::vector<YamlSection> sections;
        for (const StatePtr& item : items) sections.push_back(YamlSection(item));
        return sections;
    };
    for (const auto& [name, items] : state_->lists) {
        if (name == key) return as_sections(items);
    }
    const Entry* entry = state_->lookup(key);
    std::vector<StatePtr> items;
    if (entry != nullptr && !entry->value.IsNull()) {
        if (!entry->value.IsSequence()) {
            state_->fail_at(*entry, "expected a sequence ('- ' items or [ ... ]), got " + describe_node(entry->value));
        }
        const std::string path = child_path(state_->path, key);
        for (std::size_t index = 0; index < entry->value.size(); ++index) {
            const YAML::Node item = entry->value[index];
            const SourceLocation where = item_location(key, index);
            if (!item.IsMap()) throw ConfigError(where, "expected a mapping (key: value), got " + describe_node(item));
            items.push_back(make_state(state_->document, item_path(path, index), item, where, /*present=*/true));
        }
    }
    state_->lists.emplace_back(std::string(key), items);
    return as_sections(items);
}

std::vector<std::string> YamlSection::string_list(std::string_view key) const {
    const Entry* entry = state_->lookup(key);
    std::vector<std::string> strings;
    if (entry == nullptr || entry->value.IsNull()) return strings;
    if (!entry->value.IsSequence()) {
        std::string message = "expected a sequence of strings, got " + describe_node(entry->value);
        if (entry->value.IsScalar()) message += "; write [ " + entry->value.Scalar() + " ]";
        state_->fail_at(*entry, message);
    }
    for (std::size_t index = 0; index < entry->value.size(); ++index) {
        const YAML::Node item = entry->value[index];
        if (!item.IsScalar() || item.Scalar().empty()) {
            throw ConfigError(item_location(key, index), "expected a non-empty string, got " + describe_node(item));
        }
        strings.push_back(item.Scalar());
    }
    return strings;
}

RawYaml YamlSection::raw(std::string_view key) const {
    const Entry* entry = state_->lookup(key);
    if (entry == nullptr) return RawYaml{YAML::Node(), state_->absent_location(key), false};
    return RawYaml{entry->value, state_->value_location(*entry), true};
}

void YamlSection::fail(std::string_view key, const std::string& message) const {
    throw ConfigError(location(key), message);
}

void YamlSection::fail(const std::string& message) const { throw ConfigError(state_->location, message); }

void YamlSection::finish() const {
    std::vector<UnknownKey> unknown;
    collect_unknown_keys(*state_, unknown);
    if (!unknown.empty()) {
        const auto earliest = std::min_element(unknown.begin(), unknown.end(), [](const auto& a, const auto& b) {
            return std::tie(a.where.line, a.where.column) < std::tie(b.where.line, b.where.column);
        });
        throw unknown_key_error(*earliest);
    }
    std::vector<const PendingMissing*> missing;
    collect_missing(*state_, missing);
    if (!missing.empty()) {
        const auto first = std::min_element(missing.begin(), missing.end(),
                                            [](const auto* a, const auto* b) { return a->sequence < b->sequence; });
        throw (*first)->error;
    }
}

}  // namespace rig
