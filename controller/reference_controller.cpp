#include "controller/reference_controller.h"

#include <iostream>

#include "idl/topics.h"

namespace rig::controller {

ReferenceController::ReferenceController(std::string node_name, ControllerConfig config,
                                         const std::filesystem::path& state_dir)
    : name_(std::move(node_name)),
      config_(config),
      firmware_(std::move(config), state_dir),
      status_period_ns_(seconds_to_ns(1.0 / config_.status_rate_hz)) {}

void ReferenceController::configure(DdsContext& dds) {
    nmea_reader_ = std::make_unique<Reader<msg::NmeaSentence>>(dds, topics::kGnssNmea);
    device_inputs_ = std::make_unique<BoardInputReaders>(dds);
    actuators_writer_ = std::make_unique<ActuatorTopicsWriter>(dds);
    status_writer_ = std::make_unique<Writer<msg::ControllerStatus>>(dds, topics::kControllerStatus);
    event_writer_ = std::make_unique<Writer<msg::BreakpointEvent>>(dds, topics::kBreakpointEvent);
}

void ReferenceController::activate(TimeNs now_ns) {
    firmware_.start(now_ns);
    next_status_ns_ = now_ns;
}

bool ReferenceController::has_unread_input() const {
    return nmea_reader_->has_unread() || device_inputs_->has_unread();
}

TimeNs ReferenceController::step(TimeNs now_ns) {
    // Fixed order (encoder, meters, sensors, GNSS, panel) keeps runs identical
    // whatever the arrival order across topics.
    for (const auto& sample : device_inputs_->wheel_encoder.take_all()) firmware_.on_encoder_count(sample.count_pulses(), now_ns);
    for (const auto& sample : device_inputs_->main_flow_meter.take_all()) {
        firmware_.on_flow_meter_count(sample.count_pulses(), sample.last_edge_capture_us(), now_ns);
    }
    for (const auto& sample : device_inputs_->pump_flow_sensor.take_all()) firmware_.on_pump_sensor_voltage(sample.voltage_v(), now_ns);
    for (const auto& sample : device_inputs_->boom_height_sensor.take_all()) firmware_.on_boom_height_voltage(sample.voltage_v(), now_ns);
    for (const auto& sample : nmea_reader_->take_all()) firmware_.on_nmea_sentence(sample.sentence().to_string(), now_ns);
    for (const auto& sample : device_inputs_->breakpoint_button.take_all()) firmware_.on_breakpoint_button(sample.closed(), now_ns);
    for (const auto& sample : device_inputs_->spray_switch.take_all()) firmware_.on_spray_switch(sample.closed(), now_ns);

    TimeNs next_wake = firmware_.update(now_ns);
    actuators_writer_->publish_changes(firmware_.actuators());
    for (const msg::BreakpointEvent& event : firmware_.take_events()) event_writer_->publish(event);
    for (const std::string& notice : firmware_.take_notices()) std::cerr << name_ << ": " << notice << "\n";
    if (now_ns >= next_status_ns_) {
        status_writer_->publish(firmware_.status(now_ns));
        next_status_ns_ = next_period_boundary(now_ns, status_period_ns_);
    }
    return std::min(next_wake, next_status_ns_);
}

}  // namespace rig::controller
