#include "harness/trace/trace_recorder.h"

#include <algorithm>
#include <map>
#include <stdexcept>

#include "harness/trace/trace_json.h"
#include "idl/topics.h"

namespace rig::harness {

TraceRecorder::TraceRecorder(DdsContext& dds, const std::filesystem::path& file) : dds_(dds), file_(file) {}

bool TraceRecorder::records(const std::string& topic) const {
    return std::any_of(channels_.begin(), channels_.end(), [&](const Channel& channel) { return channel.topic == topic; });
}

void TraceRecorder::record_raw(const std::string& topic, const std::string& type_name) {
    if (records(topic)) return;
    // A type the rig knows (a controller reusing, say, NmeaSentence for text):
    // read and recorded as such. A participant holds one type per name, so
    // these could not be read as raw bytes anyway.
    using Adder = void (*)(TraceRecorder&, const char*);
    static const std::map<std::string, Adder> known = {
        {"rig::msg::NmeaSentence", [](TraceRecorder& r, const char* t) { r.record<msg::NmeaSentence>(t); }},
        {"rig::msg::EncoderCount", [](TraceRecorder& r, const char* t) { r.record<msg::EncoderCount>(t); }},
        {"rig::msg::FlowMeterCount", [](TraceRecorder& r, const char* t) { r.record<msg::FlowMeterCount>(t); }},
        {"rig::msg::AnalogInput", [](TraceRecorder& r, const char* t) { r.record<msg::AnalogInput>(t); }},
        {"rig::msg::SwitchLevel", [](TraceRecorder& r, const char* t) { r.record<msg::SwitchLevel>(t); }},
        {"rig::msg::BallValveRelays", [](TraceRecorder& r, const char* t) { r.record<msg::BallValveRelays>(t); }},
        {"rig::msg::SectionValves", [](TraceRecorder& r, const char* t) { r.record<msg::SectionValves>(t); }},
        {"rig::msg::UnloadingValve", [](TraceRecorder& r, const char* t) { r.record<msg::UnloadingValve>(t); }},
        {"rig::msg::ControllerStatus", [](TraceRecorder& r, const char* t) { r.record<msg::ControllerStatus>(t); }},
        {"rig::msg::BreakpointEvent", [](TraceRecorder& r, const char* t) { r.record<msg::BreakpointEvent>(t); }},
    };
    file_.set_meta("own_topic:" + topic, type_name);
    if (const auto it = known.find(type_name); it != known.end()) {
        it->second(*this, topic.c_str());
        return;
    }
    if (!dds_.participant().find_type(type_name).empty()) {
        throw std::runtime_error("topic " + topic + " has type " + type_name +
                                 ", a type the rig uses but cannot record for another topic");
    }
    auto reader = std::make_shared<RawReader>(dds_, topic, type_name);
    readers_.push_back(reader);
    // Bytes of a type the rig cannot decode: stored as JSON text only ({"cdr_hex": ...}).
    Channel channel{topic, file_.topic_slot(topic), rig_only_topic(topic), controller_output_topic(topic), {}};
    channel.drain = [this, reader, index = channels_.size()](TimeNs t, int round) {
        const Channel& self = channels_[index];
        std::size_t recorded = 0;
        for (auto& [sample, writer] : reader->take_all_with_writer()) {
            std::string text = cdr_hex_json_text(sample.bytes);
            if (!admit(self, writer, t, round, [&text] { return text; })) continue;
            file_.append_text(t, round, self.topic, std::move(text));
            ++recorded;
        }
        return recorded;
    };
    channels_.push_back(std::move(channel));
}

void TraceRecorder::record_foreign(const Channel& channel, const std::string& writer, TimeNs t, int round,
                                   const std::string& json_text) {
    const std::string participant = dds_.participant_name(writer);
    file_.append_foreign(t, round, channel.topic, participant, writer, json_text);
    foreign_.push_back(ForeignSample{t, channel.topic, participant, writer});
}

void TraceRecorder::drain(TimeNs t, int round) {
    bool controller_output = false;
    for (const Channel& channel : channels_) {
        if (channel.drain(t, round) == 0) continue;
        if (channel.topic == truth_topic_) last_truth_ns_ = t;
        controller_output |= channel.controller_output;
    }
    // The plant at the instant the controller acted: the judge then needs no
    // interpolation (and no plant) to say where the sprayer was.
    if (controller_output && append_truth_at_ && last_truth_ns_ != t) {
        append_truth_at_(t, round);
        last_truth_ns_ = t;
    }
}

}  // namespace rig::harness
