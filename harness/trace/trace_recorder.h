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

#include "harness/trace/topic_roles.h"
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
    // Records every sample of `topic`: its CDR bytes, and its type's JSON
    // (harness/trace/trace_json.h) rendered from them off the loop (trace_file.h).
    template <class Msg>
    void record(const char* topic);
    // After a round in which the controller wrote (actuator/*, controller/*),
    // `topic` also gets the sample `truth_at(t)` unless one arrived at that
    // instant: the plant's state where the controller acted, so the judge
    // needs no plant and no interpolation there (seed 000's truth/vehicle).
    template <class Msg>
    void record_truth_at_controller_outputs(const char* topic, std::function<Msg(TimeNs)> truth_at);
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
        std::uint32_t slot = 0;  // the topic's in the file
        bool rig_only = false;   // truth/* or device/*: another participant's sample is forged
        bool controller_output = false;  // actuator/*, controller/*
        // Records every sample taken at (t, round); returns how many went into samples.
        std::function<std::size_t(TimeNs t, int round)> drain;
    };
    // Whether a sample `writer` wrote on the channel goes into samples; if not
    // (forged), records it as foreign, `json_text()` its text.
    template <class JsonText>
    bool admit(const Channel& channel, const std::string& writer, TimeNs t, int round, const JsonText& json_text);
    void record_foreign(const Channel& channel, const std::string& writer, TimeNs t, int round,
                        const std::string& json_text);

    DdsContext& dds_;
    TraceFile file_;
    std::vector<Channel> channels_;  // drained in this fixed order
    std::vector<std::shared_ptr<void>> readers_;
    std::string truth_topic_;
    std::function<void(TimeNs, int)> append_truth_at_;
    TimeNs last_truth_ns_ = -1;
    std::vector<ForeignSample> foreign_;
};

template <class JsonText>
bool TraceRecorder::admit(const Channel& channel, const std::string& writer, TimeNs t, int round,
                          const JsonText& json_text) {
    if (!channel.rig_only || dds_.is_rig_participant(writer)) return true;
    record_foreign(channel, writer, t, round, json_text());
    return false;
}

template <class Msg>
void TraceRecorder::record(const char* topic) {
    auto reader = std::make_shared<Reader<Msg>>(dds_, topic);
    readers_.push_back(reader);
    Channel channel{topic, file_.topic_slot(topic, &sample_codec<Msg>()), rig_only_topic(topic),
                    controller_output_topic(topic), {}};
    channel.drain = [this, reader, index = channels_.size()](TimeNs t, int round) {
        const Channel& self = channels_[index];
        std::size_t recorded = 0;
        for (auto& [sample, writer] : reader->take_all_with_writer()) {
            if (!admit(self, writer, t, round, [&sample = sample] { return to_json_text(sample); })) continue;
            file_.append_sample(t, round, self.slot, sample);
            ++recorded;
        }
        return recorded;
    };
    channels_.push_back(std::move(channel));
}

template <class Msg>
void TraceRecorder::record_truth_at_controller_outputs(const char* topic, std::function<Msg(TimeNs)> truth_at) {
    truth_topic_ = topic;
    const std::uint32_t slot = file_.topic_slot(topic, &sample_codec<Msg>());
    append_truth_at_ = [this, slot, truth_at = std::move(truth_at)](TimeNs t, int round) {
        file_.append_sample(t, round, slot, truth_at(t));
    };
}

}  // namespace rig::harness
