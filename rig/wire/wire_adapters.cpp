#include "rig/wire/wire_adapters.h"

#include <cmath>
#include <iostream>
#include <limits>
#include <stdexcept>

#include "idl/topics.h"

namespace rig {

// ------------------------------------------------------------------ Modbus slave wire

modbus::ModbusSlaveCallbacks ModbusSlaveWire::callbacks() {
    modbus::ModbusSlaveCallbacks callbacks;
    callbacks.on_master_write = [signal = signal_](const modbus::MasterWrite&) {
        std::lock_guard lock(signal->mutex);
        if (signal->wake) signal->wake();
    };
    callbacks.on_problem = [](const std::string& problem) { std::cerr << "rig: modbus: " << problem << "\n"; };
    return callbacks;
}

ModbusSlaveWire::ModbusSlaveWire(const modbus::TcpSlaveOptions& options)
    : slave_(std::make_unique<modbus::ModbusSlave>(options, callbacks())) {}

ModbusSlaveWire::ModbusSlaveWire(const modbus::RtuSlaveOptions& options)
    : slave_(std::make_unique<modbus::ModbusSlave>(options, callbacks())) {}

void ModbusSlaveWire::set_wake(std::function<void()> wake) {
    std::lock_guard lock(signal_->mutex);
    signal_->wake = std::move(wake);
}

std::string ModbusSlaveWire::description() const { return "Modbus slave " + slave_->endpoint(); }

void ModbusSlaveWire::put_inputs(const io::DeviceSignals& signals, TimeNs /*spread_ns*/) {
    slave_->set_device_signals(signals);
    if (const auto failure = slave_->server_failure()) {
        throw std::runtime_error("Modbus slave " + slave_->endpoint() + " stopped: " + *failure);
    }
}

io::ActuatorCommands ModbusSlaveWire::outputs() { return slave_->actuator_commands(); }

io::ControllerIndicators ModbusSlaveWire::indicators() { return slave_->indicators(); }

bool ModbusSlaveWire::changed() {
    const std::uint64_t writes = slave_->master_write_count();
    const bool changed = writes != writes_seen_;
    writes_seen_ = writes;
    return changed;
}

// ------------------------------------------------------------------ HID board wire

HidBoardWire::HidBoardWire(std::unique_ptr<HidBoard> board, std::string description)
    : board_(std::move(board)), description_(std::move(description)) {}

void HidBoardWire::put_inputs(const io::DeviceSignals& signals, TimeNs spread_ns) {
    board_->apply(signals, spread_ns);
    latest_ = board_->read_actuators();
}

io::ActuatorCommands HidBoardWire::outputs() { return latest_; }

io::ControllerIndicators HidBoardWire::indicators() { return board_->indicators(); }

// ------------------------------------------------------------------ board I/O adapter

BoardIoAdapter::BoardIoAdapter(BoardIoWire& wire, double update_rate_hz)
    : wire_(wire), period_ns_(seconds_to_ns(1.0 / update_rate_hz)) {}

void BoardIoAdapter::configure(DdsContext& dds) {
    device_inputs_ = std::make_unique<BoardInputReaders>(dds);
    actuators_writer_ = std::make_unique<ActuatorTopicsWriter>(dds);
    event_writer_ = std::make_unique<Writer<msg::BreakpointEvent>>(dds, topics::kBreakpointEvent);
}

bool BoardIoAdapter::has_unread_input() const {
    // Device topics are taken at the update rate; the board's own writes come in at once.
    return wire_.changed();
}

void BoardIoAdapter::take_device_topics() {
    for (const auto& sample : device_inputs_->wheel_encoder.take_all()) {
        signals_.wheel_encoder_count = sample.count_pulses();
        signals_.wheel_encoder_last_edge_us = sample.last_edge_capture_us();
    }
    for (const auto& sample : device_inputs_->main_flow_meter.take_all()) {
        signals_.main_flow_pulses = sample.count_pulses();
        signals_.main_flow_last_edge_us = sample.last_edge_capture_us();
    }
    for (const auto& sample : device_inputs_->pump_flow_sensor.take_all()) {
        signals_.pump_flow_adc = io::adc_counts_from_voltage(sample.voltage_v());
    }
    for (const auto& sample : device_inputs_->boom_height_sensor.take_all()) {
        signals_.boom_height_adc = io::adc_counts_from_voltage(sample.voltage_v());
    }
    for (const auto& sample : device_inputs_->breakpoint_button.take_all()) signals_.breakpoint_button = sample.closed();
    for (const auto& sample : device_inputs_->spray_switch.take_all()) signals_.spray_switch = sample.closed();
}

void BoardIoAdapter::publish_outputs(TimeNs now_ns) {
    actuators_writer_->publish_changes(wire_.outputs());

    // The board's breakpoint counters become events (its claims; position unknown on this wire).
    const io::ControllerIndicators indicators = wire_.indicators();
    auto emit = [&](std::uint16_t now_count, std::uint16_t& seen, msg::BreakpointEventKind kind) {
        while (seen != now_count) {
            ++seen;
            msg::BreakpointEvent event;
            event.time_ns(now_ns);
            event.breakpoint_id(seen);
            event.kind(kind);
            event.lat_deg(std::numeric_limits<double>::quiet_NaN());
            event.lon_deg(std::numeric_limits<double>::quiet_NaN());
            event_writer_->publish(event);
        }
    };
    emit(indicators.breakpoints_stored, seen_indicators_.breakpoints_stored, msg::BREAKPOINT_STORED);
    emit(indicators.breakpoints_reached, seen_indicators_.breakpoints_reached, msg::BREAKPOINT_REACHED);
}

TimeNs BoardIoAdapter::step(TimeNs now_ns) {
    if (now_ns >= next_update_ns_) {
        take_device_topics();
        next_update_ns_ = next_period_boundary(now_ns, period_ns_);
        wire_.put_inputs(signals_, next_update_ns_ - now_ns);
    }
    publish_outputs(now_ns);
    return next_update_ns_;
}

// ------------------------------------------------------------------ seed 001: PWM capture

NozzlePwmCaptureAdapter::NozzlePwmCaptureAdapter(HidBoard& board, int nozzles, double poll_rate_hz,
                                                 PwmCaptureParams params)
    : board_(board), nozzles_(nozzles), period_ns_(0), params_(params) {
    if (nozzles < 1 || nozzles > hid::kPwmCaptureInputs) {
        throw std::invalid_argument("nozzle PWM capture: " + std::to_string(nozzles) + " nozzles, the board captures 1.." +
                                    std::to_string(hid::kPwmCaptureInputs));
    }
    if (!(poll_rate_hz > 0.0 && poll_rate_hz <= 1000.0)) {
        throw std::invalid_argument("nozzle PWM capture: poll rate " + std::to_string(poll_rate_hz) +
                                    " Hz outside (0, 1000]");
    }
    period_ns_ = seconds_to_ns(1.0 / poll_rate_hz);
}

void NozzlePwmCaptureAdapter::configure(DdsContext& dds) {
    writer_ = std::make_unique<Writer<msg::NozzlePwm>>(dds, topics::kNozzlePwm);
}

TimeNs NozzlePwmCaptureAdapter::step(TimeNs now_ns) {
    if (!started_) {
        board_.enable_pwm_capture(static_cast<std::uint8_t>((1u << nozzles_) - 1u), params_);
        board_.rebase(io::DeviceSignals{});
        started_ = true;
    }
    board_.read_actuators();  // takes the edge reports too
    const msg::NozzlePwm pwm = board_.pwm_capture()->nozzle_pwm(nozzles_);
    if (!last_published_ || pwm.duty_pct() != last_published_->duty_pct() ||
        pwm.frequency_hz() != last_published_->frequency_hz()) {
        writer_->publish(pwm);
        last_published_ = pwm;
        ++published_;
    }
    return next_period_boundary(now_ns, period_ns_);
}

}  // namespace rig
