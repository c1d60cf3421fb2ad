#include "harness/trace/trace_diff.h"

#include <algorithm>
#include <set>
#include <sstream>
#include <tuple>

namespace rig::harness {

namespace {

const std::vector<TraceRow> kNoRows;

const std::vector<TraceRow>& rows_of(const TopicRows& rows, const std::string& topic) {
    const auto it = rows.find(topic);
    return it == rows.end() ? kNoRows : it->second;
}

bool same_sample(const TraceRow& a, const TraceRow& b) { return a.t_ns == b.t_ns && a.json_text == b.json_text; }

// The delivery order of a sample within its trace: time, round, then its row
// (rows of one round are stored in the order they were taken).
std::tuple<TimeNs, int, std::int64_t> delivery_key(const TraceRow& row) { return {row.t_ns, row.round, row.rowid}; }

std::vector<FieldDifference> field_differences(const TraceRow& a, const TraceRow& b, std::size_t* more) {
    if (a.json_text == b.json_text) return {};
    const nlohmann::json a_json = nlohmann::json::parse(a.json_text, nullptr, /*allow_exceptions=*/false);
    const nlohmann::json b_json = nlohmann::json::parse(b.json_text, nullptr, /*allow_exceptions=*/false);
    if (a_json.is_discarded() || b_json.is_discarded()) return {};
    return differing_fields(a_json, b_json, kMaxDifferingFields, more);
}

TopicParting parting_of(const std::string& topic, TopicRole role, const std::vector<TraceRow>& a,
                        const std::vector<TraceRow>& b, std::size_t index) {
    TopicParting parting;
    parting.topic = topic;
    parting.role = role;
    parting.index = index;
    parting.a_samples = a.size();
    parting.b_samples = b.size();
    if (index < a.size()) parting.a = a[index];
    if (index < b.size()) parting.b = b[index];
    // One of the two is there: the topic parts where one run has a sample the other has not.
    const TraceRow& earlier = !parting.b                                                        ? *parting.a
                              : !parting.a                                                      ? *parting.b
                              : delivery_key(*parting.b) < delivery_key(*parting.a) ? *parting.b
                                                                                                : *parting.a;
    parting.t_ns = earlier.t_ns;
    parting.round = earlier.round;
    if (parting.a && parting.b) {
        parting.differing_fields = field_differences(*parting.a, *parting.b, &parting.more_differing_fields);
    }
    return parting;
}

// The row of the parting sample that sets its place in the order (A's when both are at one instant and round).
std::int64_t ordering_row(const TopicParting& parting) {
    if (parting.a && parting.a->t_ns == parting.t_ns && parting.a->round == parting.round) return parting.a->rowid;
    return parting.b ? parting.b->rowid : 0;
}

void collect_differences(const nlohmann::json& a, const nlohmann::json& b, const std::string& path, std::size_t max_fields,
                         std::vector<FieldDifference>& found, std::size_t& more) {
    auto differ = [&](const std::string& where, const nlohmann::json* a_value, const nlohmann::json* b_value) {
        if (found.size() < max_fields) {
            found.push_back({where, a_value != nullptr ? a_value->dump() : "", b_value != nullptr ? b_value->dump() : ""});
        } else {
            ++more;
        }
    };
    if (a.is_object() && b.is_object()) {
        std::set<std::string> keys;
        for (const auto& item : a.items()) keys.insert(item.key());
        for (const auto& item : b.items()) keys.insert(item.key());
        for (const std::string& key : keys) {
            const std::string where = path.empty() ? key : path + "." + key;
            const auto in_a = a.find(key);
            const auto in_b = b.find(key);
            if (in_a == a.end() || in_b == b.end()) {
                differ(where, in_a == a.end() ? nullptr : &*in_a, in_b == b.end() ? nullptr : &*in_b);
            } else {
                collect_differences(*in_a, *in_b, where, max_fields, found, more);
            }
        }
        return;
    }
    if (a.is_array() && b.is_array()) {
        for (std::size_t i = 0; i < std::max(a.size(), b.size()); ++i) {
            const std::string where = path + "[" + std::to_string(i) + "]";
            if (i >= a.size() || i >= b.size()) {
                differ(where, i < a.size() ? &a[i] : nullptr, i < b.size() ? &b[i] : nullptr);
            } else {
                collect_differences(a[i], b[i], where, max_fields, found, more);
            }
        }
        return;
    }
    if (a != b) differ(path, &a, &b);
}

// `text` cut to at most `max_chars` bytes without splitting a UTF-8 character.
std::string cut_utf8(const std::string& text, std::size_t max_chars) {
    if (text.size() <= max_chars) return text;
    std::size_t end = max_chars;
    while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
    return text.substr(0, end);
}

// The top-level key a YAML line starts ("controller" of "controller:"), or "".
std::string top_level_key(const std::string& line) {
    if (line.empty() || line.front() == ' ' || line.front() == '#' || line.front() == '-') return "";
    const std::size_t colon = line.find(':');
    return colon == std::string::npos ? "" : line.substr(0, colon);
}

}  // namespace

const TopicParting* TraceDiff::first() const { return partings.empty() ? nullptr : &partings.front(); }

const TopicParting* TraceDiff::first_with_role(TopicRole role) const {
    for (const TopicParting& parting : partings) {
        if (parting.role == role) return &parting;
    }
    return nullptr;
}

TraceDiff diff_samples(const TopicRows& a, const TopicRows& b, const std::function<TopicRole(const std::string&)>& role_of) {
    std::set<std::string> topics;
    for (const auto& [topic, rows] : a) topics.insert(topic);
    for (const auto& [topic, rows] : b) topics.insert(topic);
    TraceDiff diff;
    for (const std::string& topic : topics) {
        const std::vector<TraceRow>& a_rows = rows_of(a, topic);
        const std::vector<TraceRow>& b_rows = rows_of(b, topic);
        const std::size_t common = std::min(a_rows.size(), b_rows.size());
        std::size_t index = 0;
        while (index < common && same_sample(a_rows[index], b_rows[index])) ++index;
        diff.agreeing_samples += index;
        if (index == common && a_rows.size() == b_rows.size()) {
            diff.same_topics.push_back(topic);
        } else {
            diff.partings.push_back(parting_of(topic, role_of(topic), a_rows, b_rows, index));
        }
    }
    std::stable_sort(diff.partings.begin(), diff.partings.end(), [](const TopicParting& x, const TopicParting& y) {
        return std::make_tuple(x.t_ns, x.round, ordering_row(x)) < std::make_tuple(y.t_ns, y.round, ordering_row(y));
    });
    return diff;
}

TraceDiff diff_traces(const RecordedTrace& a, const RecordedTrace& b) {
    // The controller's own topics are declared in its hello and kept in meta
    // (docs/trace-format.md): whatever their names, they are its outputs.
    auto declared_own = [](const RecordedTrace& trace, const std::string& topic) {
        return trace.meta.count("own_topic:" + topic) > 0;
    };
    TraceDiff diff = diff_samples(a.rows, b.rows, [&](const std::string& topic) {
        const TopicRole role = topic_role(topic);
        if (role == TopicRole::other && (declared_own(a, topic) || declared_own(b, topic))) return TopicRole::controller;
        return role;
    });
    auto same_cell = [](const RecordedDepositionCell& x, const RecordedDepositionCell& y) {
        return x.pass == y.pass && x.row == y.row && x.nozzle == y.nozzle && x.dose_ul_cm2 == y.dose_ul_cm2;
    };
    auto same_edge = [](const RecordedLandingEdge& x, const RecordedLandingEdge& y) {
        return x.t_ns == y.t_ns && x.landing == y.landing;
    };
    diff.deposition_differs = !std::equal(a.deposition.begin(), a.deposition.end(), b.deposition.begin(),
                                          b.deposition.end(), same_cell);
    diff.landing_edges_differ = !std::equal(a.landing_edges.begin(), a.landing_edges.end(), b.landing_edges.begin(),
                                            b.landing_edges.end(), same_edge);
    return diff;
}

PartingCause parting_cause(const TraceDiff& diff) {
    const TopicParting* first = diff.first();
    if (first == nullptr) return diff.same() ? PartingCause::none : PartingCause::case_or_rig;
    switch (first->role) {
        case TopicRole::actuator:
        case TopicRole::controller: return PartingCause::controller;
        case TopicRole::device:
        case TopicRole::truth: return PartingCause::case_or_rig;
        case TopicRole::clock:
        case TopicRole::other: break;
    }
    return PartingCause::unknown;
}

std::vector<FieldDifference> differing_fields(const nlohmann::json& a, const nlohmann::json& b, std::size_t max_fields,
                                              std::size_t* more) {
    std::vector<FieldDifference> found;
    std::size_t beyond = 0;
    collect_differences(a, b, "", max_fields, found, beyond);
    if (more != nullptr) *more = beyond;
    return found;
}

ShownSample shown_sample(const std::string& json_text, const std::vector<FieldDifference>& fields, Run run,
                         std::size_t max_chars) {
    if (json_text.size() <= max_chars) return {json_text, ""};
    const std::string whole = "the sample is " + std::to_string(json_text.size()) + " characters";
    std::string listed;
    for (const FieldDifference& field : fields) {
        const std::string& value = run == Run::a ? field.a : field.b;
        listed += (listed.empty() ? "" : ", ") + (field.path.empty() ? "" : field.path + "=") + (value.empty() ? "(none)" : value);
    }
    if (!fields.empty() && listed.size() <= max_chars) return {listed, "only the fields that differ; " + whole};
    return {cut_utf8(json_text, max_chars) + "\u2026", "cut; " + whole};
}

std::optional<CaseFileDifference> first_case_file_difference(const std::string& a_yaml, const std::string& b_yaml) {
    if (a_yaml == b_yaml) return std::nullopt;
    std::istringstream a_lines(a_yaml);
    std::istringstream b_lines(b_yaml);
    std::string section;
    for (std::size_t number = 1;; ++number) {
        std::string a_line;
        std::string b_line;
        const bool a_more = static_cast<bool>(std::getline(a_lines, a_line));
        const bool b_more = static_cast<bool>(std::getline(b_lines, b_line));
        if (!a_more && !b_more) {
            // Lines alike, texts not: they differ in a final line break.
            return CaseFileDifference{number, section, "", ""};
        }
        const std::string key = top_level_key(a_more ? a_line : b_line);
        if (!key.empty()) section = key;
        if (a_line != b_line || a_more != b_more) return CaseFileDifference{number, section, a_line, b_line};
    }
}

}  // namespace rig::harness
