#include "controller/wired_board_controller.h"

#include <algorithm>
#include <iostream>

namespace rig::controller {

std::vector<std::string> take_nmea_lines(std::string& buffer) {
    std::vector<std::string> lines;
    std::size_t start = 0;
    for (;;) {
        const std::size_t line_end = buffer.find('\n', start);
        if (line_end == std::string::npos) break;
        // NMEA 0183: '$' (or '!') starts a sentence. One inside the line means
        // the sentence before it was cut off (a receiver that stopped writing
        // mid-sentence): that fragment is a line of its own (the parser
        // rejects and counts it), so the whole sentence after it is not lost with it.
        std::size_t next = buffer.find_first_of("$!", start + 1);
        while (next != std::string::npos && next < line_end) {
            lines.push_back(buffer.substr(start, next - start));
            start = next;
            next = buffer.find_first_of("$!", start + 1);
        }
        lines.push_back(buffer.substr(start, line_end + 1 - start));
        start = line_end + 1;
    }
    buffer.erase(0, start);
    return lines;
}

modbus::MasterTimeouts rtu_master_timeouts() {
    // libmodbus's own default between bytes (0.5 s) is for a line of unknown
    // speed. This loop runs at 100 Hz and times the valve's relay pulses, and
    // every wait here holds it: when noise made a response look longer than
    // it was (a burst in front of it), the master waited the whole byte
    // timeout for bytes that never came (0.53 s,
    // cases/wire-faults/modbus-line-noise-wired-rtu.yaml), which stretched the
    // relay pulses and broke the flow. 20 ms: USB-serial adapters deliver a
    // frame in chunks up to ~16 ms apart. The wait for a response's first byte
    // stays the master's 1 s: only a response lost whole waits for it, and
    // shorter, a slave answering late on a loaded machine turned each late
    // answer into a retry that could read it in place of its own.
    modbus::MasterTimeouts timeouts;
    timeouts.byte_timeout = std::chrono::milliseconds(20);
    return timeouts;
}

WiredBoardController::WiredBoardController(std::string node_name, ControllerConfig config,
                                           const std::filesystem::path& state_dir, WiredBoardOptions options)
    : name_(std::move(node_name)),
      options_(std::move(options)),
      firmware_(std::move(config), state_dir),
      poll_period_ns_(std::chrono::duration_cast<std::chrono::nanoseconds>(options_.poll_period).count()) {}

void WiredBoardController::configure(DdsContext& /*dds*/) {
    if (options_.nmea_port.empty()) throw std::runtime_error("wired mode needs the NMEA serial port");
    nmea_port_ = std::make_unique<SerialPort>(options_.nmea_port, options_.nmea_line);
    if (options_.modbus_rtu) {
        board_ = std::make_unique<modbus::ModbusMaster>(*options_.modbus_rtu, rtu_master_timeouts());
    } else if (options_.modbus_tcp) {
        board_ = std::make_unique<modbus::ModbusMaster>(*options_.modbus_tcp);
    } else {
        throw std::runtime_error("wired mode needs a Modbus RTU line or a Modbus TCP slave for the board's I/O");
    }
}

void WiredBoardController::activate(TimeNs now_ns) {
    firmware_.start(now_ns);
    next_poll_ns_ = now_ns;
    last_exchange_ns_ = now_ns;
}

template <class Call>
auto WiredBoardController::with_retries(Call call) {
    for (int attempt = 0;; ++attempt) {
        const TimeNs started_ns = attempt_clock_.now_ns();
        try {
            return call();
        } catch (const modbus::ModbusMasterError& error) {
            longest_failed_attempt_ns_ = std::max(longest_failed_attempt_ns_, attempt_clock_.now_ns() - started_ns);
            // A frame lost on the line is retried; a slave that refuses (an exception
            // response, the wrong map) is not going to change its mind.
            const bool timeout = error.kind() == modbus::ModbusMasterError::Kind::timeout;
            const bool transient = timeout || error.kind() == modbus::ModbusMasterError::Kind::bad_response;
            if (!transient || attempt >= options_.modbus_retries) throw;
            ++retries_used_;
            ++(timeout ? timeouts_retried_ : bad_responses_retried_);
        }
    }
}

void WiredBoardController::read_nmea(TimeNs now_ns) {
    // Whatever the UART holds now; complete lines go to the parser.
    for (;;) {
        const std::string chunk = nmea_port_->read_some(std::chrono::milliseconds(0));
        if (chunk.empty()) break;
        nmea_buffer_ += chunk;
    }
    for (const std::string& line : take_nmea_lines(nmea_buffer_)) firmware_.on_nmea_sentence(line, now_ns);
    // A line longer than any NMEA sentence is noise on the wire: drop it (the
    // parser would reject it anyway) rather than grow without bound.
    if (nmea_buffer_.size() > 4096) {
        firmware_.on_nmea_sentence(nmea_buffer_, now_ns);
        nmea_buffer_.clear();
    }
}

void WiredBoardController::poll_board(TimeNs now_ns) {
    const io::DeviceSignals inputs = with_retries([&] { return board_->read_device_signals(); });
    firmware_.on_encoder_count(inputs.wheel_encoder_count, inputs.wheel_encoder_last_edge_us, now_ns);
    firmware_.on_flow_meter_count(inputs.main_flow_pulses, inputs.main_flow_last_edge_us, now_ns);
    firmware_.on_pump_sensor_voltage(io::voltage_from_adc_counts(inputs.pump_flow_adc), now_ns);
    firmware_.on_boom_height_voltage(io::voltage_from_adc_counts(inputs.boom_height_adc), now_ns);
    if (!last_inputs_ || inputs.breakpoint_button != last_inputs_->breakpoint_button) {
        firmware_.on_breakpoint_button(inputs.breakpoint_button, now_ns);
    }
    if (!last_inputs_ || inputs.spray_switch != last_inputs_->spray_switch) {
        firmware_.on_spray_switch(inputs.spray_switch, now_ns);
    }
    last_inputs_ = inputs;
}

void WiredBoardController::write_outputs(TimeNs now_ns) {
    // A quarter of the rig's default fail-safe timeout (1 s): a refresh comes
    // well before any watchdog of that order, and costs 4 FC 15 a second.
    constexpr TimeNs kOutputRefreshNs = 250'000'000;
    const io::ActuatorCommands& actuators = firmware_.actuators();
    const bool refresh = now_ns - actuators_written_ns_ >= kOutputRefreshNs || retries_used_ != retries_at_write_;
    if (!written_actuators_ || !(*written_actuators_ == actuators) || refresh) {
        with_retries([&] {
            board_->write_actuator_commands(actuators);
            return 0;
        });
        written_actuators_ = actuators;
        actuators_written_ns_ = now_ns;
        retries_at_write_ = retries_used_;
    }
    const io::ControllerIndicators indicators = firmware_.indicators();
    if (!written_indicators_ || !(*written_indicators_ == indicators)) {
        with_retries([&] {
            board_->write_indicators(indicators);
            return 0;
        });
        written_indicators_ = indicators;
    }
}

TimeNs WiredBoardController::step(TimeNs now_ns) {
    // Outputs first, inputs after: a relay change must reach the wire at the
    // instant the firmware decided it, not one Modbus read later. (Polled first,
    // every relay-on that follows a PID decision went out a read transaction
    // late while its relay-off did not, so short valve pulses came out shorter
    // than planned and a correction within the motor's start delay did nothing.)
    read_nmea(now_ns);
    const TimeNs firmware_wake = firmware_.update(now_ns);
    try {
        write_outputs(now_ns);
        if (now_ns >= next_poll_ns_) {
            poll_board(now_ns);
            next_poll_ns_ = next_period_boundary(now_ns, poll_period_ns_);
        }
        last_exchange_ns_ = now_ns;
    } catch (const modbus::ModbusMasterError& error) {
        // An exchange that failed after its retries is a lost poll, as on a
        // noisy line: the firmware keeps the last inputs, the outputs are
        // written again at the next step (written_* are unchanged), and the
        // poll comes at the next period. Only a board that has answered
        // nothing for modbus_lost_after is lost, and ends the run.
        const bool transient = error.kind() == modbus::ModbusMasterError::Kind::timeout ||
                               error.kind() == modbus::ModbusMasterError::Kind::bad_response;
        const TimeNs lost_after_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(options_.modbus_lost_after).count();
        if (!transient || now_ns - last_exchange_ns_ > lost_after_ns) throw;
        ++exchanges_lost_;
        next_poll_ns_ = next_period_boundary(now_ns, poll_period_ns_);
    }
    for (const std::string& notice : firmware_.take_notices()) std::cerr << name_ << ": " << notice << "\n";
    firmware_.take_events();  // on this wire the events reach the rig as the indicator counters
    return std::min(firmware_wake, next_poll_ns_);
}

void WiredBoardController::shutdown() {
    // Leave the plant safe: relays off, sections closed, pump unloaded.
    if (!board_) return;
    if (retries_used_ > 0) {
        std::cerr << name_ << ": modbus: " << retries_used_ << " requests retried (" << timeouts_retried_
                  << " timeouts, " << bad_responses_retried_ << " bad responses), " << exchanges_lost_
                  << " exchanges lost after their retries (lost polls); the longest failed attempt held the loop "
                  << ns_to_seconds(longest_failed_attempt_ns_) * 1000.0 << " ms\n";
    }
    try {
        io::ActuatorCommands safe;
        safe.unloading_valve_open = true;
        board_->write_actuator_commands(safe);
    } catch (const std::exception& error) {
        std::cerr << name_ << ": could not leave the outputs safe at shutdown: " << error.what() << "\n";
    }
}

}  // namespace rig::controller
