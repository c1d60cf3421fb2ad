#pragma once
// The USB-HID bench I/O board as the rig sees it (protocol: rig/wire/hid_board_protocol.h,
// docs/hid-io-board.md). HidBoard speaks the protocol over a HidTransport:
// HidapiTransport for a real board (hidapi, hidraw backend), or a fake that
// behaves like the firmware (tests/fake_hid_board.h) on machines without one.
//
// Default identity: VID 0x1209 (pid.codes, open-source hardware) with PID
// 0x0001, pid.codes' shared *test* PID. It is meant for in-house benches only; a
// board built for others needs its own PID registered at pid.codes, and every
// function here takes the VID:PID as a parameter (`rig hid list --vid --pid`).
// Because a test PID may be shared with other gadgets, HidBoard checks the
// protocol id and version of every report the device sends.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "rig/runtime/clock.h"
#include "rig/wire/hid_board_protocol.h"
#include "rig/wire/pwm_capture.h"
#include "rig/runtime/io_image.h"

struct hid_device_;  // hidapi's device handle (hidapi.h stays out of this header)

namespace rig {

inline constexpr std::uint16_t kDefaultHidBoardVid = 0x1209;
inline constexpr std::uint16_t kDefaultHidBoardPid = 0x0001;

class HidError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// A report pipe to one board. Reports include the report id in byte 0.
class HidTransport {
public:
    virtual ~HidTransport() = default;
    // Sends one OUT report; throws HidError when it cannot be sent.
    virtual void write_report(std::span<const std::uint8_t> report) = 0;
    // The next IN report, waiting up to `timeout`; nullopt when none came.
    // Whatever length arrived is returned (the decoder judges it).
    virtual std::optional<std::vector<std::uint8_t>> read_report(std::chrono::milliseconds timeout) = 0;
    // "1209:0001 /dev/hidraw3" or "fake board": for error messages.
    virtual std::string description() const = 0;
};

// Opens the board by USB vendor and product id (HidapiTransport::open on a
// bench; an in-process board in a test of the whole run).
using HidTransportOpener = std::function<std::unique_ptr<HidTransport>(std::uint16_t vendor_id, std::uint16_t product_id)>;

struct HidDeviceInfo {
    std::string path;  // /dev/hidrawN
    std::uint16_t vendor_id = 0;
    std::uint16_t product_id = 0;
    std::string manufacturer;
    std::string product;
    std::string serial_number;
    int interface_number = -1;
};

// "1209:0001" (lower-case hex, as lsusb prints it).
std::string format_vid_pid(std::uint16_t vendor_id, std::uint16_t product_id);

// Every HID device with this VID:PID (0 = any, for either). Throws HidError if
// hidapi cannot be initialised.
std::vector<HidDeviceInfo> list_hid_devices(std::uint16_t vendor_id, std::uint16_t product_id);
std::vector<HidDeviceInfo> list_hid_boards(std::uint16_t vendor_id = kDefaultHidBoardVid,
                                           std::uint16_t product_id = kDefaultHidBoardPid);

// "no HID I/O board VID:PID 1209:0001 found (3 HID devices present)"
std::string no_board_message(std::uint16_t vendor_id, std::uint16_t product_id, std::size_t devices_present);

class HidapiTransport final : public HidTransport {
public:
    // The first board with this VID:PID (and this serial number, when given).
    // Throws HidError with no_board_message() when there is none, or naming the
    // device path and hidapi's reason when it cannot be opened (permissions:
    // the hidraw node needs a udev rule, see docs/hid-io-board.md).
    static std::unique_ptr<HidapiTransport> open(std::uint16_t vendor_id = kDefaultHidBoardVid,
                                                 std::uint16_t product_id = kDefaultHidBoardPid,
                                                 const std::string& serial_number = {});
    static std::unique_ptr<HidapiTransport> open_path(const std::string& path);
    ~HidapiTransport() override;
    HidapiTransport(const HidapiTransport&) = delete;
    HidapiTransport& operator=(const HidapiTransport&) = delete;

    void write_report(std::span<const std::uint8_t> report) override;
    std::optional<std::vector<std::uint8_t>> read_report(std::chrono::milliseconds timeout) override;
    std::string description() const override { return description_; }

private:
    HidapiTransport(hid_device_* device, std::string description);
    hid_device_* device_;
    std::string description_;
};

class HidBoard {
public:
    // `status_timeout` bounds read_actuators(): how long to wait for a status
    // report (the firmware sends one at least every 10 ms).
    explicit HidBoard(std::unique_ptr<HidTransport> transport,
                      std::chrono::milliseconds status_timeout = std::chrono::milliseconds(200));

    // Drives the controller's inputs: the two pulse outputs shall reach the
    // signals' cumulative counts `spread_ns` after the board receives this,
    // evenly spread; button, switch and analog outputs change at once. The
    // first call re-bases instead (see rebase()), so a run starts wherever the
    // board's counters are. Throws std::invalid_argument when a count goes
    // backwards (a pulse output cannot take pulses back: rebase() to start
    // over), when spread_ns is negative or above 2^32 us, or an analog code
    // exceeds 4095; HidError when the transport fails.
    void apply(const io::DeviceSignals& signals, TimeNs spread_ns);

    // The board takes the signals' counts as already emitted (no pulses) and
    // sets the levels: the start of a run.
    void rebase(const io::DeviceSignals& signals);

    // Reads the board's status (waiting up to status_timeout for the first
    // report, then taking every report already queued; edge reports in between
    // go to pwm_capture()) and returns the relay
    // and valve outputs sensed in the newest. Throws HidError naming the board
    // when no report comes in time, a report is malformed (with the decoder's
    // reason), or the board says it refused our last command.
    io::ActuatorCommands read_actuators();

    // Protocol version 2: PWM edge capture on the inputs in `inputs` (bit i =
    // input i, 0..5; 0 turns capture off), carried by every command from the
    // next apply() or rebase() on. The edge reports read_actuators() meets
    // from then on go to pwm_capture(). Throws std::invalid_argument for a bit
    // above 5 or bad params. A version-1 board refuses such a command: the next
    // read_actuators() throws HidError saying the board lacks PWM capture.
    void enable_pwm_capture(std::uint8_t inputs, PwmCaptureParams params = {});
    // nullptr until enable_pwm_capture() with inputs.
    const PwmCapture* pwm_capture() const { return pwm_capture_ ? &*pwm_capture_ : nullptr; }

    // From the newest status read so far (nullopt / defaults before the first).
    const std::optional<hid::BoardStatus>& last_status() const { return last_status_; }
    io::ControllerIndicators indicators() const;
    // Status reports missing between those read (sequence gaps).
    std::uint64_t status_reports_lost() const { return status_reports_lost_; }
    std::uint16_t last_command_sequence() const { return static_cast<std::uint16_t>(next_sequence_ - 1); }
    HidTransport& transport() { return *transport_; }

private:
    void send(const io::DeviceSignals& signals, std::uint32_t spread_interval_us, bool rebase);
    std::unique_ptr<HidTransport> transport_;
    std::chrono::milliseconds status_timeout_;
    std::uint16_t next_sequence_ = 1;
    std::optional<io::DeviceSignals> last_sent_;
    std::optional<hid::BoardStatus> last_status_;
    std::uint64_t status_reports_lost_ = 0;
    std::uint8_t pwm_capture_inputs_ = 0;
    std::optional<PwmCapture> pwm_capture_;
};

}  // namespace rig
