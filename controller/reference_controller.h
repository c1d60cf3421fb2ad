#pragma once
// The reference controller under test as a rig node on DDS: what an STM32 board
// running the paper's firmware does, with DDS topics as its wires. It reads only
// device topics, hands them to the firmware logic (controller/spray_controller.h),
// and publishes the actuator commands, its breakpoint events and its status. It
// never sees truth.
//
// Subscriptions: device/gnss/nmea, device/wheel_encoder/count,
//                device/main_flow_meter/count, device/pump_flow_sensor/voltage,
//                device/boom_height_sensor/voltage, device/breakpoint_button/level,
//                device/spray_switch/level
// Publications:  actuator/ball_valve/relays, actuator/section_valves/open,
//                actuator/unloading_valve/open, controller/status,
//                controller/breakpoint_event
#include <filesystem>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>

#include "controller/controller_config.h"
#include "controller/spray_controller.h"
#include "rig/runtime/actuator_topics.h"
#include "rig/runtime/board_input_topics.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/node.h"

namespace rig::controller {

class ReferenceController final : public Node {
public:
    // `log`: where its notices go (stderr when null; a plugin's log file in process).
    ReferenceController(std::string node_name, ControllerConfig config, const std::filesystem::path& state_dir,
                        std::ostream* log = nullptr);
    ~ReferenceController() override;
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    void activate(TimeNs now_ns) override;
    TimeNs step(TimeNs now_ns) override;
    bool has_unread_input() const override;

private:
    // --- subscriptions
    std::unique_ptr<Reader<msg::NmeaSentence>> nmea_reader_;
    std::unique_ptr<BoardInputReaders> device_inputs_;  // encoder, flow meter, sensors, button, switch
    // --- publications
    std::unique_ptr<ActuatorTopicsWriter> actuators_writer_;  // the three actuator topics
    std::unique_ptr<Writer<msg::ControllerStatus>> status_writer_;
    std::unique_ptr<Writer<msg::BreakpointEvent>> event_writer_;
    std::unique_ptr<Writer<msg::NmeaSentence>> diagnostics_writer_;  // config.diagnostics_topic: text lines
    std::optional<msg::SprayPhase> last_phase_;
    // --- TEST-ONLY faults (ControllerFaults): a topic read behind the hello's
    // back, forged truth written.
    dds::DataReader* undeclared_reader_ = nullptr;
    DdsContext* dds_ = nullptr;
    std::unique_ptr<Writer<msg::VehicleTruth>> forged_vehicle_writer_;
    std::unique_ptr<Writer<msg::HydraulicsTruth>> forged_hydraulics_writer_;

    std::ostream* log_;
    std::string name_;
    ControllerConfig config_;
    SprayController firmware_;
    TimeNs status_period_ns_;
    TimeNs next_status_ns_ = 0;
};

}  // namespace rig::controller
