#include "harness/trace/trace_recorder.h"

#include <algorithm>
#include <map>
#include <stdexcept>

#include "harness/trace/topic_roles.h"
#include "harness/trace/trace_json.h"
#include "idl/topics.h"

namespace rig::harness {

TraceRecorder::TraceRecorder(DdsContext& dds, const std::filesystem::path& file) : dds_(dds), file_(file) {}

void TraceRecorder::record_truth_at_controller_outputs(const char* topic, std::function<std::string(TimeNs)> json_at) {
    truth_topic_ = topic;
    truth_at_ = std::move(json_at);
}

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
    channels_.push_back(Channel{topic, [reader](std::vector<std::pair<std::string, std::string>>& out) {
                                    for (auto& [sample, writer] : reader->take_all_with_writer()) {
                                        out.emplace_back(cdr_hex_json_text(sample.bytes), std::move(writer));
                                    }
                                }});
}

void TraceRecorder::drain(TimeNs t, int round) {
    bool controller_output = false;
    std::vector<std::pair<std::string, std::string>> taken;
    for (const Channel& channel : channels_) {
        taken.clear();
        channel.take(taken);
        const bool rig_only = rig_only_topic(channel.topic);
        for (auto& [text, writer] : taken) {
            if (rig_only && !dds_.is_rig_participant(writer)) {
                const std::string participant = dds_.participant_name(writer);
                file_.append_foreign(t, round, channel.topic, participant, writer, text);
                foreign_.push_back(ForeignSample{t, channel.topic, participant, writer});
                continue;
            }
            file_.append_text(t, round, channel.topic, std::move(text));
            if (channel.topic == truth_topic_) last_truth_ns_ = t;
            controller_output |= controller_output_topic(channel.topic);
        }
    }
    // The plant at the instant the controller acted: the judge then needs no
    // interpolation (and no plant) to say where the sprayer was.
    if (controller_output && truth_at_ && last_truth_ns_ != t) {
        file_.append_text(t, round, truth_topic_, truth_at_(t));
        last_truth_ns_ = t;
    }
}

}  // namespace rig::harness
