#pragma once
// Report protocol of the rig's USB-HID bench I/O board (docs/hid-io-board.md has
// the same tables plus the HID report descriptor and firmware notes).
//
// The board sits between the rig and the controller under test (the paper's
// STM32F407): it turns the rig's device signals (rig/runtime/io_image.h) into pulses,
// levels and voltages on the controller's input pins, and senses the
// controller's relay and valve outputs. Two reports, both 64 bytes including
// the report id in byte 0 (the HID descriptor declares 63 data bytes after the
// id), integers little-endian, every reserved bit and byte zero.
//
// OUT report 0x01 "command" (rig -> board)
//   off size  field
//    0   1    report id 0x01
//    1   1    protocol version (kProtocolVersion)
//    2   2    command sequence: +1 per command report, wraps
//    4   4    wheel-encoder target: the CUMULATIVE pulse count the encoder output
//             shall have reached at the end of the spread interval (wraps at 2^32)
//    8   4    main-flow-meter target: same, for the KF11-P10 pulse output
//   12   4    spread interval, microseconds
//   16   2    pump-flow sensor output, 12-bit code 0..4095 (top 4 bits reserved)
//   18   2    boom-height sensor output, 12-bit code 0..4095 (top 4 bits reserved)
//   20   1    digital outputs: bit0 breakpoint button pressed, bit1 spray switch
//             on; bits 2-7 reserved
//   21   1    command flags: bit0 re-base counters; bits 1-7 reserved
//   22  42    reserved
//
// IN report 0x02 "status" (board -> rig), sent periodically and on change
//    0   1    report id 0x02
//    1   1    protocol version
//    2   2    status sequence: +1 per status report, wraps (gaps = lost reports)
//    4   2    sequence of the last command report the board applied
//    6   1    relay inputs: bit0 ball valve forward, bit1 ball valve reverse,
//             bit2 unloading valve open; bits 3-7 reserved
//    7   1    section valves open: bit i = section i (sections 0..7)
//    8   4    wheel-encoder pulses emitted so far (cumulative, wraps)
//   12   4    main-flow-meter pulses emitted so far (cumulative, wraps)
//   16   4    board time, microseconds, free-running (wraps every 71.6 min)
//   20   1    indicator inputs: bit0 breakpoint pending, bit1 odometer active;
//             bits 2-7 reserved
//   21   1    status flags: bit0 pulses pending (still spreading), bit1 rate
//             limited (a target needs more than kMaxPulseRateHz), bit2 target
//             behind (a target lies behind the emitted count: held, no pulses);
//             bits 3-7 reserved
//   22   1    problem with the last command report received: a ReportProblem
//             code, 0 when it was applied
//   23   1    reserved
//   24   2    breakpoints stored: rising edges counted on the controller's
//             "breakpoint stored" output (wraps)
//   26   2    breakpoints reached: same, "at breakpoint" output
//   28  36    reserved
//
// Pulse outputs carry cumulative counts, not increments, so that no pulse is
// ever lost or doubled when a report is lost, late or superseded. On a command
// the board computes, per output, remaining = target - emitted (mod 2^32, as a
// signed 32-bit number) and emits that many pulses evenly over the spread
// interval (the k-th of n at t0 + k * interval / n; interval 0 = at once, as
// fast as allowed). A new command replaces what was left of the previous one:
// its target is absolute, so the board ends exactly on it. Spacing is never
// shorter than 1 / kMaxPulseRateHz: a faster demand is met late (flag "rate
// limited"), not dropped. A target behind the emitted count is held (flag
// "target behind"): a pulse output cannot take pulses back. "Re-base" makes the
// board take the targets as already emitted, without pulses (start of a run).
//
// Analog outputs are the 12-bit code the controller's ADC (3.3 V reference,
// rig/runtime/io_image.h) shall read: the board outputs code * 3.3 V / 4095 through its
// DAC, calibrated against the controller's converter.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "rig/runtime/io_image.h"

namespace rig::hid {

inline constexpr std::size_t kReportSize = 64;  // including the report id byte
inline constexpr std::uint8_t kProtocolVersion = 1;
inline constexpr std::uint8_t kCommandReportId = 0x01;  // OUT
inline constexpr std::uint8_t kStatusReportId = 0x02;   // IN
inline constexpr std::uint16_t kMaxAnalogCode = io::kAdcFullScale;  // 12 bits
// Firmware limit per pulse output. The fastest real signal is far below it:
// the land-wheel encoder at 6 km/h on a 1 m wheel gives 531 Hz, the KF11-P10 at
// its 14.14 m3/h maximum 354 Hz.
inline constexpr std::uint32_t kMaxPulseRateHz = 20'000;

using Report = std::array<std::uint8_t, kReportSize>;

// Why a report was refused; also sent back by the board in status byte 22.
enum class ReportProblem : std::uint8_t {
    none = 0,
    wrong_length = 1,
    wrong_report_id = 2,
    unsupported_version = 3,
    reserved_bits_set = 4,
    value_out_of_range = 5,
};
const char* to_string(ReportProblem problem);

// OUT report. `signals` carries the targets: wheel_encoder_count and
// main_flow_pulses are the cumulative counts to reach, the rest are levels.
struct BoardCommand {
    std::uint16_t sequence = 0;
    io::DeviceSignals signals;
    std::uint32_t spread_interval_us = 0;
    bool rebase_counters = false;
};

// IN report.
struct BoardStatus {
    std::uint16_t sequence = 0;
    std::uint16_t last_command_sequence = 0;
    io::ActuatorCommands actuators;       // relay and valve outputs sensed
    io::ControllerIndicators indicators;  // status outputs sensed
    std::uint32_t wheel_encoder_emitted = 0;
    std::uint32_t main_flow_emitted = 0;
    std::uint32_t board_time_us = 0;
    bool pulses_pending = false;
    bool rate_limited = false;
    bool target_behind = false;
    ReportProblem last_command_problem = ReportProblem::none;
};

// A report that was refused: the problem and a one-line reason naming the byte
// and value, e.g. "byte 20 (digital outputs): reserved bits 0x04 set".
struct ReportError {
    ReportProblem problem = ReportProblem::none;
    std::string reason;
};

template <class T>
struct Decoded {
    std::optional<T> value;
    ReportError error;  // meaningful when !ok()
    bool ok() const { return value.has_value(); }
};

// Encoders throw std::invalid_argument for values the report cannot carry (an
// analog code above 4095), naming the field.
Report encode_command(const BoardCommand& command);
Report encode_status(const BoardStatus& status);

// Decoders never throw and never read past `bytes`: any byte string gets either
// a value or a ReportError.
Decoded<BoardCommand> decode_command(std::span<const std::uint8_t> bytes);
Decoded<BoardStatus> decode_status(std::span<const std::uint8_t> bytes);

// Signed distance from `from` to `to` on a counter that wraps at 2^32:
// positive when `to` is ahead. (from 0xFFFFFFF0 to 0x10 -> +32.)
std::int64_t counter_ahead(std::uint32_t from, std::uint32_t to);

}  // namespace rig::hid
