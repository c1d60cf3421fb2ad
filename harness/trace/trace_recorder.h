#pragma once
// Records the topics of a run into its trace file (harness/trace/trace_file.h),
// in the exact order the lockstep rounds delivered them. Which topics is the
// system's to say (harness/systems/system.h SystemRun::record). Besides what
// arrives:
//   - a truth topic may also get the plant's state at every instant a
//     controller output (actuator/*, controller/*) arrived, so each thing the
//     controller did has its exact truth beside it;
//   - a sample on a truth/* or device/* topic written by a participant other
//     than the rig is forged: it goes to foreign_samples, never into samples.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "harness/trace/trace_file.h"
#include "harness/trace/trace_json.h"
#include "rig/runtime/dds_context.h"

namespace rig::harness {

// A sample on a truth or device topic that another participant wrote.
struct ForeignSample {
    TimeNs t_ns = 0;
    std::string topic;
    std::string participant;
    std::string guid_prefix;
};

class TraceRecorder {
public:
    // Records nothing yet: each system names its topics (record()), in the
    // order they are drained, which is part of what makes a trace reproducible.
    TraceRecorder(DdsContext& dds, const std::filesystem::path& file);
    TraceRecorder(const TraceRecorder&) = delete;
    TraceRecorder& operator=(const TraceRecorder&) = delete;

    TraceFile& file() { return file_; }
    // Records every sample of `topic`, as its type's JSON (harness/trace/trace_json.h).
    template <class Msg>
    void record(const char* topic);
    // After a round in which the controller wrote (actuator/*, controller/*),
    // `topic` also gets a sample of `json_at(t)` unless one arrived at that
    // instant: the plant's state where the controller acted, so the judge
    // needs no plant and no interpolation there (seed 000's truth/vehicle).
    void record_truth_at_controller_outputs(const char* topic, std::function<std::string(TimeNs)> json_at);
    // Takes every sample that arrived and records it at (t, round).
    void drain(TimeNs t, int round);
    // Samples other participants wrote on rig-only topics, so far.
    const std::vector<ForeignSample>& foreign_samples() const { return foreign_; }
    // Whether the recorder has a channel for the topic.
    bool records(const std::string& topic) const;
    // Records a topic of the controller's own (its diagnostics): decoded when the
    // type is one of the rig's, else each sample as its serialized bytes,
    // {"cdr_hex": "..."}; meta `own_topic:TOPIC` says the type. Channels added
    // this way are drained after the ones before, in the order added.
    void record_raw(const std::string& topic, const std::string& type_name);

private:
    struct Channel {
        std::string topic;
        // Appends (JSON text, writer's GUID prefix) of every sample taken.
        std::function<void(std::vector<std::pair<std::string, std::string>>&)> take;
    };

    DdsContext& dds_;
    TraceFile file_;
    std::vector<Channel> channels_;  // drained in this fixed order
    std::vector<std::shared_ptr<void>> readers_;
    std::string truth_topic_;
    std::function<std::string(TimeNs)> truth_at_;
    TimeNs last_truth_ns_ = -1;
    std::vector<ForeignSample> foreign_;
};

template <class Msg>
void TraceRecorder::record(const char* topic) {
    auto reader = std::make_shared<Reader<Msg>>(dds_, topic);
    readers_.push_back(reader);
    channels_.push_back(Channel{topic, [reader](std::vector<std::pair<std::string, std::string>>& out) {
                                    for (auto& [sample, writer] : reader->take_all_with_writer()) {
                                        out.emplace_back(to_json_text(sample), std::move(writer));
                                    }
                                }});
}

}  // namespace rig::harness
