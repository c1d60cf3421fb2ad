#pragma once
// The rig's side of the bench wires (issue: plug in a real controller). Which
// wire each device uses is chosen in the case file (`wiring:`), like
// ros2_control's real-or-mock hardware: the emulators always publish their
// device topics and the plant always takes actuator topics; an adapter node here
// carries them over the chosen wire, so neither side changes for it.
//
//   NmeaSerialAdapter   device/gnss/nmea  ->  a serial port (the G970II's RS232 line, the AD300's RMC)
//   LaserSerialAdapter  device/laser_height/serial  ->  a serial port (seed 001's L4 laser)
//   BoardIoAdapter      device topics     ->  the board's inputs  (io::DeviceSignals)
//                       actuator topics   <-  the board's outputs (io::ActuatorCommands)
//                       controller/breakpoint_event <- the board's indicator counters
//     through a BoardIoWire: the Modbus slave (TCP or RTU, docs/modbus-register-map.md)
//     or the USB-HID I/O board (docs/hid-io-board.md).
//   NozzlePwmCaptureAdapter  the HID board's PWM capture (protocol version 2)
//                       ->  actuator/nozzle_pwm/duty (seed 001's nozzle valves)
//
// Adapters run in real time only: a wire has no virtual time.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "idl/topics.h"
#include "rig/runtime/actuator_topics.h"
#include "rig/runtime/board_input_topics.h"
#include "rig/runtime/dds_context.h"
#include "rig/wire/hid_board.h"
#include "rig/wire/pwm_capture.h"
#include "rig/runtime/io_image.h"
#include "rig/wire/modbus_slave.h"
#include "rig/runtime/node.h"
#include "rig/wire/serial_port.h"

namespace rig {

// Writes every sample of a text topic to a serial port, byte for byte, as the
// device on that line would send it (its terminator included). `TextOf` gives
// the sample's bytes.
//   Subscriptions: the topic it is made for
template <class Msg, std::string (*TextOf)(const Msg&)>
class TextSerialAdapter : public Node {
public:
    TextSerialAdapter(SerialPort& port, std::string name, const char* topic)
        : name_(std::move(name)), topic_(topic), port_(port) {}
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override { reader_ = std::make_unique<Reader<Msg>>(dds, topic_); }
    TimeNs step(TimeNs /*now_ns*/) override {
        for (const Msg& sample : reader_->take_all()) {
            port_.write_all(TextOf(sample), kWriteTimeout);
            ++written_;
        }
        return kNever;
    }
    bool has_unread_input() const override { return reader_->has_unread(); }
    // Samples written to the port so far.
    std::uint64_t written() const { return written_; }

private:
    static constexpr std::chrono::milliseconds kWriteTimeout{1000};  // a line that takes no bytes for 1 s is stuck
    std::string name_;
    const char* topic_;
    SerialPort& port_;
    std::unique_ptr<Reader<Msg>> reader_;
    std::uint64_t written_ = 0;
};

inline std::string nmea_sentence_text(const msg::NmeaSentence& sample) { return sample.sentence().to_string(); }
inline std::string serial_line_text(const msg::SerialLine& sample) { return sample.text().to_string(); }

// The receiver's NMEA (device/gnss/nmea) on a serial port, as the G970II or AD300 sends it.
class NmeaSerialAdapter final : public TextSerialAdapter<msg::NmeaSentence, nmea_sentence_text> {
public:
    explicit NmeaSerialAdapter(SerialPort& port) : TextSerialAdapter(port, "nmea_serial", topics::kGnssNmea) {}
    std::uint64_t sentences_written() const { return written(); }
};

// Seed 001's L4 laser lines (device/laser_height/serial) on a serial port.
class LaserSerialAdapter final : public TextSerialAdapter<msg::SerialLine, serial_line_text> {
public:
    explicit LaserSerialAdapter(SerialPort& port) : TextSerialAdapter(port, "laser_serial", topics::kLaserHeightSerial) {}
    std::uint64_t lines_written() const { return written(); }
};

// One board-I/O wire, as the adapter sees it.
class BoardIoWire {
public:
    virtual ~BoardIoWire() = default;
    virtual std::string description() const = 0;
    // Puts the board's inputs on the wire; `spread_ns` is how long until the next
    // update (a pulse output spreads the new pulses over it).
    virtual void put_inputs(const io::DeviceSignals& signals, TimeNs spread_ns) = 0;
    // The board's outputs as the wire has them now.
    virtual io::ActuatorCommands outputs() = 0;
    virtual io::ControllerIndicators indicators() = 0;
    // Something new on the wire since the last call (the adapter then runs at once).
    virtual bool changed() = 0;
};

// The rig as Modbus slave: the board (master) reads the inputs and writes its outputs.
class ModbusSlaveWire final : public BoardIoWire {
public:
    // Serve the register map on TCP (127.0.0.1 unless the options allow more) or RTU.
    explicit ModbusSlaveWire(const modbus::TcpSlaveOptions& options);
    explicit ModbusSlaveWire(const modbus::RtuSlaveOptions& options);
    // Called from the slave's thread whenever the master writes (wakes the run loop).
    void set_wake(std::function<void()> wake);
    std::string description() const override;
    void put_inputs(const io::DeviceSignals& signals, TimeNs spread_ns) override;
    io::ActuatorCommands outputs() override;
    io::ControllerIndicators indicators() override;
    bool changed() override;
    modbus::ModbusSlave& slave() { return *slave_; }

private:
    // Shared with the slave's callback, which may run until the slave is stopped.
    struct WriteSignal {
        std::mutex mutex;
        std::function<void()> wake;
    };
    modbus::ModbusSlaveCallbacks callbacks();
    std::shared_ptr<WriteSignal> signal_ = std::make_shared<WriteSignal>();
    std::unique_ptr<modbus::ModbusSlave> slave_;
    std::uint64_t writes_seen_ = 0;
};

// The USB-HID bench I/O board: pulse outputs, relay-sensing inputs.
class HidBoardWire final : public BoardIoWire {
public:
    explicit HidBoardWire(std::unique_ptr<HidBoard> board, std::string description);
    std::string description() const override { return description_; }
    void put_inputs(const io::DeviceSignals& signals, TimeNs spread_ns) override;
    io::ActuatorCommands outputs() override;
    io::ControllerIndicators indicators() override;
    bool changed() override { return false; }  // polled at every input update
    // Seed 001's capture (NozzlePwmCaptureAdapter) talks to the board itself.
    HidBoard& board() { return *board_; }

private:
    std::unique_ptr<HidBoard> board_;
    std::string description_;
    io::ActuatorCommands latest_{};
};

// Device topics onto a board-I/O wire, and the board's outputs back as actuator
// topics (and its breakpoint counters as events), at update_rate_hz and whenever
// the wire reports a change.
//   Subscriptions: device/wheel_encoder/count, device/main_flow_meter/count,
//                  device/pump_flow_sensor/voltage, device/boom_height_sensor/voltage,
//                  device/breakpoint_button/level, device/spray_switch/level
//   Publications:  actuator/ball_valve/relays, actuator/section_valves/open,
//                  actuator/unloading_valve/open, controller/breakpoint_event
class BoardIoAdapter final : public Node {
public:
    BoardIoAdapter(BoardIoWire& wire, double update_rate_hz);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;
    bool has_unread_input() const override;

private:
    void take_device_topics();
    void publish_outputs(TimeNs now_ns);

    std::string name_ = "board_io";
    BoardIoWire& wire_;
    TimeNs period_ns_;
    TimeNs next_update_ns_ = 0;
    io::DeviceSignals signals_{};
    io::ControllerIndicators seen_indicators_{};
    // --- subscriptions
    std::unique_ptr<BoardInputReaders> device_inputs_;  // encoder, flow meter, sensors, button, switch
    // --- publications
    std::unique_ptr<ActuatorTopicsWriter> actuators_writer_;  // the three actuator topics
    std::unique_ptr<Writer<msg::BreakpointEvent>> event_writer_;
};

// Seed 001 on the bench: the controller's six GPIO PWM outputs, captured by
// the HID I/O board (protocol version 2, docs/hid-io-board.md "PWM edge
// capture"), become the actuator state a DDS controller publishes, so the
// plant takes them unchanged. The first step enables capture on the first
// `nozzles` inputs (a re-basing command: this board drives no pulse outputs
// here); each step then reads the board's reports and publishes when the
// decoded duties or frequency change.
//   Publications: actuator/nozzle_pwm/duty (msg::NozzlePwm)
class NozzlePwmCaptureAdapter final : public Node {
public:
    // Throws std::invalid_argument for nozzles outside 1..6 or a poll rate
    // outside (0, 1000] Hz. The board must outlive the adapter.
    NozzlePwmCaptureAdapter(HidBoard& board, int nozzles, double poll_rate_hz, PwmCaptureParams params = {});
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;
    bool has_unread_input() const override { return false; }  // polled
    std::uint64_t published() const { return published_; }

private:
    std::string name_ = "nozzle_pwm_capture";
    HidBoard& board_;
    int nozzles_;
    TimeNs period_ns_;
    PwmCaptureParams params_;
    bool started_ = false;
    std::optional<msg::NozzlePwm> last_published_;
    std::uint64_t published_ = 0;
    std::unique_ptr<Writer<msg::NozzlePwm>> writer_;
};

}  // namespace rig
