#pragma once
// Records every topic of a run into its trace file (harness/trace_file.h), in
// the exact order the lockstep rounds delivered them. Besides what arrives:
//   - truth/vehicle also gets the plant's state at every instant a controller
//     output (actuator/*, controller/*) arrived, so each thing the controller did
//     has its exact truth beside it and the judge needs no plant;
//   - a sample on a truth/* or device/* topic written by a participant other
//     than the rig is forged: it goes to foreign_samples, never into samples.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "harness/trace_file.h"
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
    TraceRecorder(DdsContext& dds, const std::filesystem::path& file);
    TraceRecorder(const TraceRecorder&) = delete;
    TraceRecorder& operator=(const TraceRecorder&) = delete;

    TraceFile& file() { return file_; }
    // The plant's vehicle truth at any instant (a pure function of t).
    void set_vehicle_truth_probe(std::function<msg::VehicleTruth(TimeNs)> probe) { probe_ = std::move(probe); }
    // Takes every sample that arrived and records it at (t, round).
    void drain(TimeNs t, int round);
    // Samples other participants wrote on rig-only topics, so far.
    const std::vector<ForeignSample>& foreign_samples() const { return foreign_; }
    // Whether the recorder has a channel for the topic.
    bool records(const std::string& topic) const;
    // Records a topic of the controller's own (its diagnostics): decoded when the
    // type is one of the rig's, else each sample as its serialized bytes,
    // {"cdr_hex": "..."}; meta `own_topic:TOPIC` says the type. Channels added
    // this way are drained after the known ones, in the order added.
    void record_raw(const std::string& topic, const std::string& type_name);
    // Seed 001's topics (boundary cases): the AD300's and L4's lines, the PWM
    // duties, the 2-D plant's truth. Drained after the fixed ones, in this order.
    void record_boundary_topics();
    // Seed 001's vision: the controller's reports and the crop truth per frame
    // (not the frames: megabytes each, and a pure function of case and seed).
    void record_vision_topics();

private:
    struct Channel {
        std::string topic;
        // Appends (JSON text, writer's GUID prefix) of every sample taken.
        std::function<void(std::vector<std::pair<std::string, std::string>>&)> take;
    };
public:
    // (Public for record_raw's table of known types.)
    template <class Msg>
    void add_channel(DdsContext& dds, const char* topic);

private:

    DdsContext& dds_;
    TraceFile file_;
    std::vector<Channel> channels_;  // drained in this fixed order
    std::vector<std::shared_ptr<void>> readers_;
    std::function<msg::VehicleTruth(TimeNs)> probe_;
    TimeNs last_vehicle_truth_ns_ = -1;
    std::vector<ForeignSample> foreign_;
};

// Topics only the rig may write (truth and device data). A sample on one of
// them from another participant is forged.
bool rig_only_topic(const std::string& topic);
// Topics the controller under test writes (actuator commands, its own reports).
bool controller_output_topic(const std::string& topic);

}  // namespace rig::harness
