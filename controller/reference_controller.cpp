#include "controller/reference_controller.h"

#include <cstdlib>
#include <iostream>

#include "idl/topics.h"

namespace rig::controller {

ReferenceController::ReferenceController(std::string node_name, ControllerConfig config,
                                         const std::filesystem::path& state_dir, std::ostream* log)
    : log_(log != nullptr ? log : &std::cerr),
      name_(std::move(node_name)),
      config_(config),
      firmware_(std::move(config), state_dir),
      status_period_ns_(seconds_to_ns(1.0 / config_.status_rate_hz)) {}

ReferenceController::~ReferenceController() {
    if (undeclared_reader_ != nullptr) dds_->subscriber().delete_datareader(undeclared_reader_);
}

void ReferenceController::configure(DdsContext& dds) {
    nmea_reader_ = std::make_unique<Reader<msg::NmeaSentence>>(dds, topics::kGnssNmea);
    device_inputs_ = std::make_unique<BoardInputReaders>(dds);
    actuators_writer_ = std::make_unique<ActuatorTopicsWriter>(dds);
    status_writer_ = std::make_unique<Writer<msg::ControllerStatus>>(dds, topics::kControllerStatus);
    event_writer_ = std::make_unique<Writer<msg::BreakpointEvent>>(dds, topics::kBreakpointEvent);
    if (!config_.diagnostics_topic.empty()) {
        diagnostics_writer_ = std::make_unique<Writer<msg::NmeaSentence>>(dds, config_.diagnostics_topic);
    }

    // TEST-ONLY faults. A reader made straight on the DDS subscriber, outside the
    // context's registry: the hello does not list it, as a controller that hides
    // what it reads would not. The rig must find it from discovery.
    dds_ = &dds;
    const ControllerFaults& faults = config_.faults;
    // Data sharing off, as on every endpoint of the project's profile: its
    // segments (fast_datasharing_*) have no owner lock, so a killed controller's
    // could never be told from a live one's and would stay in /dev/shm for good.
    auto undeclared_qos = dds.subscriber().get_default_datareader_qos();
    undeclared_qos.data_sharing().off();
    if (faults.read_topic == topics::kVehicleTruth) {
        undeclared_reader_ =
            dds.subscriber().create_datareader(dds.topic<msg::VehicleTruth>(topics::kVehicleTruth), undeclared_qos);
    } else if (faults.read_topic == topics::kHydraulicsTruth) {
        undeclared_reader_ =
            dds.subscriber().create_datareader(dds.topic<msg::HydraulicsTruth>(topics::kHydraulicsTruth), undeclared_qos);
    }
    if (!faults.read_topic.empty() && undeclared_reader_ == nullptr) {
        throw std::runtime_error("fault read_topic: cannot create a reader on " + faults.read_topic);
    }
    if (faults.write_topic == topics::kVehicleTruth) {
        forged_vehicle_writer_ = std::make_unique<Writer<msg::VehicleTruth>>(dds, topics::kVehicleTruth);
    } else if (faults.write_topic == topics::kHydraulicsTruth) {
        forged_hydraulics_writer_ = std::make_unique<Writer<msg::HydraulicsTruth>>(dds, topics::kHydraulicsTruth);
    }
}

void ReferenceController::activate(TimeNs now_ns) {
    firmware_.start(now_ns);
    next_status_ns_ = now_ns;
}

bool ReferenceController::has_unread_input() const {
    return nmea_reader_->has_unread() || device_inputs_->has_unread();
}

TimeNs ReferenceController::step(TimeNs now_ns) {
    // TEST-ONLY fault: a firmware that dies mid-case.
    if (config_.faults.crash_at_s >= 0.0 && now_ns >= seconds_to_ns(config_.faults.crash_at_s)) {
        *log_ << name_ << ": crashing at t=" << ns_to_seconds(now_ns) << " s as the fault crash_at_s asks" << std::endl;
        std::abort();
    }
    // Fixed order (encoder, meters, sensors, GNSS, panel) keeps runs identical
    // whatever the arrival order across topics.
    for (const auto& sample : device_inputs_->wheel_encoder.take_all()) {
        firmware_.on_encoder_count(sample.count_pulses(), sample.last_edge_capture_us(), now_ns);
    }
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
    for (const std::string& notice : firmware_.take_notices()) *log_ << name_ << ": " << notice << "\n";
    if (diagnostics_writer_ && firmware_.phase() != last_phase_) {
        last_phase_ = firmware_.phase();
        msg::NmeaSentence line;
        line.sentence(std::string("phase ") + std::to_string(static_cast<int>(*last_phase_)));
        diagnostics_writer_->publish(line);
    }
    if (now_ns >= next_status_ns_) {
        status_writer_->publish(firmware_.status(now_ns));
        next_status_ns_ = next_period_boundary(now_ns, status_period_ns_);
        // TEST-ONLY faults: read what it must not, write what it must not.
        if (undeclared_reader_ != nullptr) {
            msg::VehicleTruth vehicle;
            msg::HydraulicsTruth hydraulics;
            dds::SampleInfo info;
            void* sample = config_.faults.read_topic == topics::kVehicleTruth ? static_cast<void*>(&vehicle)
                                                                              : static_cast<void*>(&hydraulics);
            while (undeclared_reader_->take_next_sample(sample, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
            }
        }
        if (forged_vehicle_writer_) {
            msg::VehicleTruth forged;
            forged.time_ns(now_ns);
            forged.nozzle_line_along_m(-1000.0);  // a sprayer far from where it is
            forged_vehicle_writer_->publish(forged);
        }
        if (forged_hydraulics_writer_) {
            msg::HydraulicsTruth forged;
            forged.time_ns(now_ns);
            forged.main_flow_l_min(config_.target_flow_l_min);  // "the flow is on target"
            forged_hydraulics_writer_->publish(forged);
        }
    }
    return std::min(next_wake, next_status_ns_);
}

}  // namespace rig::controller
