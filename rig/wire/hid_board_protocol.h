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
//    1   1    protocol version: 1, or 2 when byte 22 asks for capture
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
//   22   1    version 2: PWM capture inputs (below); version 1: reserved
//   23  41    reserved
//
// IN report 0x02 "status" (board -> rig), sent periodically and on change
//    0   1    report id 0x02
//    1   1    protocol version of the last command applied (1 or 2; same layout)
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
//
// Version 2 adds PWM edge capture on six inputs (seed 001: the Raspberry Pi's
// six GPIO PWM outputs to the nozzle valve drivers), backward compatible:
//   - command byte 22 "PWM capture inputs": bit i enables capture on input i
//     (0..5), bits 6-7 reserved. A command with capture enabled carries version
//     2; with none it carries version 1 and is byte for byte version 1's, so a
//     version-1 board keeps working (and refuses a version-2 command with
//     "unsupported version" in status byte 22: the rig says so).
//   - a version-2 board takes commands of version 1 and 2; its status reports
//     carry the version of the last command applied (1 until a version-2
//     command came), with version 1's layout either way, so a version-1 rig
//     never sees a version it does not speak.
//   - while capture is enabled on any input the board sends IN report 0x03
//     "PWM edges" (version 2 only):
//    0   1    report id 0x03
//    1   1    protocol version (2)
//    2   2    edge report sequence: +1 per edge report, wraps (a gap = lost edges)
//    4   4    report time: board time, microseconds (the status report's clock,
//             byte 16); capture is complete up to it: every edge before it is
//             in this report or an earlier one
//    8   1    capture input levels at the report time: bit i = input i high;
//             bits 6-7 reserved
//    9   1    flags: bit0 overflow (the board's edge buffer filled since the
//             previous edge report: edges were lost); bits 1-7 reserved
//   10   1    edge count n, 0..16
//   11   1    reserved
//   12   4    base time: board time of edge 0, microseconds (0 when n = 0)
//   16  3n    edges, oldest first, 3 bytes each (24 bits little-endian):
//             bits 0-19 time after the base, microseconds (< 2^20), bits 20-22
//             input 0..5, bit 23 the level after the edge (1 rising, 0 falling)
//   16+3n     reserved to the end
//   The board timestamps each edge with its 1 MHz timer (1 us, 0.001 % of a
//   9 Hz period) and sends an edge report every 10 ms while capture is on and
//   whenever 16 edges are waiting (at most one per 1 ms interrupt interval).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "rig/runtime/io_image.h"

namespace rig::hid {

inline constexpr std::size_t kReportSize = 64;  // including the report id byte
inline constexpr std::uint8_t kProtocolVersion = 2;        // the newest this rig speaks
inline constexpr std::uint8_t kOldestProtocolVersion = 1;  // the oldest it still speaks
inline constexpr std::uint8_t kCommandReportId = 0x01;  // OUT
inline constexpr std::uint8_t kStatusReportId = 0x02;   // IN
inline constexpr std::uint8_t kEdgeReportId = 0x03;     // IN, version 2
inline constexpr std::uint8_t kPwmCaptureVersion = 2;   // the first version with PWM capture
inline constexpr int kPwmCaptureInputs = 6;             // seed 001's six nozzle valves
inline constexpr std::uint8_t kPwmCaptureInputMask = 0x3F;
inline constexpr std::size_t kMaxEdgesPerReport = 16;   // (64 - 16) / 3
inline constexpr std::uint32_t kMaxEdgeOffsetUs = (1u << 20) - 1;
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
    // Version 2: bit i enables PWM edge capture on input i (0..5). The encoder
    // writes version 2 when any bit is set and version 1 otherwise.
    std::uint8_t pwm_capture_inputs = 0;
    // Decoder: the version the report carried. (The encoder ignores it.)
    std::uint8_t protocol_version = kOldestProtocolVersion;
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
    // 1 or 2: the version of the last command the board applied (the layout is
    // the same; a version-2 board answers a version-1 rig in version 1).
    std::uint8_t protocol_version = kOldestProtocolVersion;
};

// One edge the board captured on a PWM input.
struct CapturedEdge {
    std::uint32_t time_us = 0;  // board time (wraps with it)
    std::uint8_t input = 0;     // 0..5
    bool rising = false;        // the level after the edge is high
};

// IN report 0x03 (version 2).
struct EdgeReport {
    std::uint16_t sequence = 0;
    std::uint32_t report_time_us = 0;  // capture complete up to here
    std::uint8_t levels = 0;           // bit i: input i high at report_time_us
    bool overflow = false;             // edges were lost before this report
    std::vector<CapturedEdge> edges;   // oldest first, at most kMaxEdgesPerReport,
                                       // within kMaxEdgeOffsetUs of the first, none after report_time_us
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
// Throws std::invalid_argument for more than 16 edges, an input above 5,
// edges out of time order or spread over more than kMaxEdgeOffsetUs, an edge
// after the report time, or a level bit above 5.
Report encode_edges(const EdgeReport& report);

// Decoders never throw and never read past `bytes`: any byte string gets either
// a value or a ReportError.
Decoded<BoardCommand> decode_command(std::span<const std::uint8_t> bytes);
Decoded<BoardStatus> decode_status(std::span<const std::uint8_t> bytes);
Decoded<EdgeReport> decode_edges(std::span<const std::uint8_t> bytes);

// Signed distance from `from` to `to` on a counter that wraps at 2^32:
// positive when `to` is ahead. (from 0xFFFFFFF0 to 0x10 -> +32.)
std::int64_t counter_ahead(std::uint32_t from, std::uint32_t to);

}  // namespace rig::hid
