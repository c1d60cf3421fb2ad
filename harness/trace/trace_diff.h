#pragma once
// Two traces of one case, sample against sample (`rig diff`, docs/diff.md):
// where they part. A lockstep run is a pure function of its case, seed, rig
// and controller, so two runs that differ in the controller alone agree on
// every sample until the controller does something else, and the topic that
// parts first says who changed: an actuator or controller topic, the
// controller; a device or truth topic before any of those, the case or the
// rig (the devices and the plant part before the controller could have acted).
//
// Each topic is compared in delivery order: its i-th sample in A against its
// i-th in B, the simulated time and the JSON as stored. Nothing here knows a
// system; the roles come from the topic names (topic_roles.h).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/trace/topic_roles.h"
#include "harness/trace/trace_reader.h"
#include "rig/runtime/clock.h"

namespace rig::harness {

// Every topic's samples in delivery order, as the trace stores them.
using TopicRows = std::map<std::string, std::vector<TraceRow>>;

// One place two samples' values differ: its path from the sample's top
// ("duty_pct[3]", "nozzles[2].flow_l_min"; "" for the whole value) and each
// run's value there as compact JSON ("" where that run has none).
struct FieldDifference {
    std::string path;
    std::string a;
    std::string b;
};

// Where one topic parts: its first sample whose time or value differs.
struct TopicParting {
    std::string topic;
    TopicRole role = TopicRole::other;
    std::size_t index = 0;     // of that sample in the topic, from 0
    std::optional<TraceRow> a;  // A's sample there; none: A has no more samples of the topic
    std::optional<TraceRow> b;
    // The instant it parts: the earlier of the two samples (the one there is,
    // when a run has no more). Among topics that part at one instant, the one
    // its round delivered first comes first.
    TimeNs t_ns = 0;
    int round = 0;
    std::size_t a_samples = 0;  // the topic's samples in each run
    std::size_t b_samples = 0;
    // Where the two values differ, at most kMaxDifferingFields of them; empty
    // when a sample is missing, the times alone differ, or a value is not JSON.
    std::vector<FieldDifference> differing_fields;
    std::size_t more_differing_fields = 0;  // found beyond those listed
};
inline constexpr std::size_t kMaxDifferingFields = 8;

// Who changed, from the first topic to part.
enum class PartingCause {
    none,         // nothing parts
    controller,   // an actuator command or a controller report parts first
    case_or_rig,  // a device or truth topic parts first (or only the plant's ground record differs)
    unknown,      // a topic of another role (the clock, a topic the rig does not name) parts first
};

struct TraceDiff {
    std::vector<TopicParting> partings;  // every topic that parts, the earliest first
    std::vector<std::string> same_topics;  // topics whose samples all agree, by name
    std::size_t agreeing_samples = 0;      // sample pairs found the same (before each topic parts)
    // The rest of what the digest covers (docs/trace-format.md): the spray on
    // the ground and its landing edges; compared when every sample agrees or not.
    bool deposition_differs = false;
    bool landing_edges_differ = false;

    bool same() const { return partings.empty() && !deposition_differs && !landing_edges_differ; }
    // The first topic to part, or the first of that role; nullptr when none does.
    const TopicParting* first() const;
    const TopicParting* first_with_role(TopicRole role) const;
};

// Compares two runs' samples topic by topic. `role_of` names each topic's
// role (a controller's own topics, declared in its hello, are its outputs).
TraceDiff diff_samples(const TopicRows& a, const TopicRows& b,
                       const std::function<TopicRole(const std::string&)>& role_of = topic_role);
// Two recorded traces: their samples (a topic the controller declared as its
// own in either counts as a controller topic), deposition and landing edges.
TraceDiff diff_traces(const RecordedTrace& a, const RecordedTrace& b);

PartingCause parting_cause(const TraceDiff& diff);

// Where two JSON values differ, depth first in key order, at most
// `max_fields` of them; `more` (if given) counts the rest.
std::vector<FieldDifference> differing_fields(const nlohmann::json& a, const nlohmann::json& b, std::size_t max_fields,
                                              std::size_t* more = nullptr);

// Which run's sample to show.
enum class Run { a, b };

// A sample's JSON for one line of text: as stored when at most `max_chars`
// long; longer, that run's side of the fields that differ ("duty_pct[3]=40"),
// or, when there are none or they are long too, the sample cut with an
// ellipsis. `note` then says which, and how long the whole sample is.
struct ShownSample {
    std::string text;
    std::string note;  // empty: the whole sample
};
ShownSample shown_sample(const std::string& json_text, const std::vector<FieldDifference>& fields, Run run,
                         std::size_t max_chars);

// Where two case files first differ, line by line: the line number (from 1),
// the top-level section it is in ("controller"; empty before any), both lines
// ("" past a file's end). nullopt when they are the same text.
struct CaseFileDifference {
    std::size_t line = 0;
    std::string section;
    std::string a_line;
    std::string b_line;
};
std::optional<CaseFileDifference> first_case_file_difference(const std::string& a_yaml, const std::string& b_yaml);

}  // namespace rig::harness
