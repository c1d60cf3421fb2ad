#include "harness/trace_recorder.h"

#include <algorithm>
#include <map>
#include <stdexcept>

#include "harness/trace_json.h"
#include "idl/topics.h"

namespace rig::harness {

namespace {

bool starts_with(const std::string& text, const char* prefix) { return text.rfind(prefix, 0) == 0; }

}  // namespace

bool rig_only_topic(const std::string& topic) { return starts_with(topic, "truth/") || starts_with(topic, "device/"); }

bool controller_output_topic(const std::string& topic) {
    return starts_with(topic, "actuator/") || starts_with(topic, "controller/");
}

template <class Msg>
void TraceRecorder::add_channel(DdsContext& dds, const char* topic) {
    auto reader = std::make_shared<Reader<Msg>>(dds, topic);
    readers_.push_back(reader);
    channels_.push_back(Channel{topic, [reader](std::vector<std::pair<std::string, std::string>>& out) {
                                    for (auto& [sample, writer] : reader->take_all_with_writer()) {
                                        out.emplace_back(to_json_text(sample), std::move(writer));
                                    }
                                }});
}

TraceRecorder::TraceRecorder(DdsContext& dds, const std::filesystem::path& file) : dds_(dds), file_(file) {
    // Fixed channel order: part of what makes the trace reproducible.
    add_channel<msg::VehicleTruth>(dds, topics::kVehicleTruth);
    add_channel<msg::NmeaSentence>(dds, topics::kGnssNmea);
    add_channel<msg::EncoderCount>(dds, topics::kWheelEncoder);
    add_channel<msg::HydraulicsTruth>(dds, topics::kHydraulicsTruth);
    add_channel<msg::FlowMeterCount>(dds, topics::kMainFlowMeter);
    add_channel<msg::AnalogInput>(dds, topics::kPumpFlowSensor);
    add_channel<msg::AnalogInput>(dds, topics::kBoomHeightSensor);
    add_channel<msg::SwitchLevel>(dds, topics::kBreakpointButton);
    add_channel<msg::SwitchLevel>(dds, topics::kSpraySwitch);
    add_channel<msg::BallValveRelays>(dds, topics::kBallValveRelays);
    add_channel<msg::SectionValves>(dds, topics::kSectionValves);
    add_channel<msg::UnloadingValve>(dds, topics::kUnloadingValve);
    add_channel<msg::ControllerStatus>(dds, topics::kControllerStatus);
    add_channel<msg::BreakpointEvent>(dds, topics::kBreakpointEvent);
}

void TraceRecorder::record_boundary_topics() {
    add_channel<msg::SerialLine>(dds_, topics::kLaserHeightSerial);
    add_channel<msg::NozzlePwm>(dds_, topics::kNozzlePwm);
    add_channel<msg::Vehicle2dTruth>(dds_, topics::kVehicle2dTruth);
    add_channel<msg::NozzlesTruth>(dds_, topics::kNozzlesTruth);
}

void TraceRecorder::record_vision_topics() {
    add_channel<msg::VisionReport>(dds_, topics::kVisionReport);
    add_channel<msg::CameraViewTruth>(dds_, topics::kCameraViewTruth);
}

bool TraceRecorder::records(const std::string& topic) const {
    return std::any_of(channels_.begin(), channels_.end(), [&](const Channel& channel) { return channel.topic == topic; });
}

void TraceRecorder::record_raw(const std::string& topic, const std::string& type_name) {
    if (records(topic)) return;
    // A type the rig knows (a controller reusing, say, NmeaSentence for text):
    // read and recorded as such. A participant holds one type per name, so
    // these could not be read as raw bytes anyway.
    using Adder = void (*)(TraceRecorder&, DdsContext&, const char*);
    static const std::map<std::string, Adder> known = {
        {"rig::msg::NmeaSentence", [](TraceRecorder& r, DdsContext& d, const char* t) { r.add_channel<msg::NmeaSentence>(d, t); }},
        {"rig::msg::EncoderCount", [](TraceRecorder& r, DdsContext& d, const char* t) { r.add_channel<msg::EncoderCount>(d, t); }},
        {"rig::msg::FlowMeterCount", [](TraceRecorder& r, DdsContext& d, const char* t) { r.add_channel<msg::FlowMeterCount>(d, t); }},
        {"rig::msg::AnalogInput", [](TraceRecorder& r, DdsContext& d, const char* t) { r.add_channel<msg::AnalogInput>(d, t); }},
        {"rig::msg::SwitchLevel", [](TraceRecorder& r, DdsContext& d, const char* t) { r.add_channel<msg::SwitchLevel>(d, t); }},
        {"rig::msg::BallValveRelays", [](TraceRecorder& r, DdsContext& d, const char* t) { r.add_channel<msg::BallValveRelays>(d, t); }},
        {"rig::msg::SectionValves", [](TraceRecorder& r, DdsContext& d, const char* t) { r.add_channel<msg::SectionValves>(d, t); }},
        {"rig::msg::UnloadingValve", [](TraceRecorder& r, DdsContext& d, const char* t) { r.add_channel<msg::UnloadingValve>(d, t); }},
        {"rig::msg::ControllerStatus", [](TraceRecorder& r, DdsContext& d, const char* t) { r.add_channel<msg::ControllerStatus>(d, t); }},
        {"rig::msg::BreakpointEvent", [](TraceRecorder& r, DdsContext& d, const char* t) { r.add_channel<msg::BreakpointEvent>(d, t); }},
    };
    file_.set_meta("own_topic:" + topic, type_name);
    if (const auto it = known.find(type_name); it != known.end()) {
        it->second(*this, dds_, topic.c_str());
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
            if (channel.topic == topics::kVehicleTruth) last_vehicle_truth_ns_ = t;
            controller_output |= controller_output_topic(channel.topic);
        }
    }
    // The plant at the instant the controller acted: the judge then needs no
    // interpolation (and no plant) to say where the sprayer was.
    if (controller_output && probe_ && last_vehicle_truth_ns_ != t) {
        file_.append_text(t, round, topics::kVehicleTruth, to_json_text(probe_(t)));
        last_vehicle_truth_ns_ = t;
    }
}

}  // namespace rig::harness
