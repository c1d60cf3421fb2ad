#include "rig/wire/hid_board_protocol.h"

#include <cstdio>
#include <initializer_list>
#include <stdexcept>
#include <utility>

namespace rig::hid {
namespace {

// Byte offsets, named once (the header's tables are the specification).
namespace command_offset {
constexpr std::size_t kVersion = 1;
constexpr std::size_t kSequence = 2;
constexpr std::size_t kWheelTarget = 4;
constexpr std::size_t kFlowTarget = 8;
constexpr std::size_t kSpreadInterval = 12;
constexpr std::size_t kPumpFlowCode = 16;
constexpr std::size_t kBoomHeightCode = 18;
constexpr std::size_t kDigitalOutputs = 20;
constexpr std::size_t kFlags = 21;
constexpr std::size_t kPwmCaptureInputs = 22;  // version 2; reserved in version 1
constexpr std::size_t kFirstReservedV1 = 22;
constexpr std::size_t kFirstReservedV2 = 23;
}  // namespace command_offset

namespace edge_offset {
constexpr std::size_t kVersion = 1;
constexpr std::size_t kSequence = 2;
constexpr std::size_t kReportTime = 4;
constexpr std::size_t kLevels = 8;
constexpr std::size_t kFlags = 9;
constexpr std::size_t kCount = 10;
constexpr std::size_t kReservedByte11 = 11;
constexpr std::size_t kBaseTime = 12;
constexpr std::size_t kFirstEdge = 16;
constexpr std::size_t kEdgeSize = 3;
}  // namespace edge_offset
constexpr std::uint8_t kOverflowBit = 0x01;
constexpr std::uint8_t kEdgeFlagsUsed = kOverflowBit;
constexpr std::uint32_t kEdgeInputShift = 20;
constexpr std::uint32_t kEdgeRisingBit = 1u << 23;

namespace status_offset {
constexpr std::size_t kVersion = 1;
constexpr std::size_t kSequence = 2;
constexpr std::size_t kCommandSequence = 4;
constexpr std::size_t kRelayInputs = 6;
constexpr std::size_t kSectionValves = 7;
constexpr std::size_t kWheelEmitted = 8;
constexpr std::size_t kFlowEmitted = 12;
constexpr std::size_t kBoardTime = 16;
constexpr std::size_t kIndicatorInputs = 20;
constexpr std::size_t kFlags = 21;
constexpr std::size_t kCommandProblem = 22;
constexpr std::size_t kReservedByte23 = 23;
constexpr std::size_t kBreakpointsStored = 24;
constexpr std::size_t kBreakpointsReached = 26;
constexpr std::size_t kFirstReserved = 28;
}  // namespace status_offset

// Bits in use per bit-field byte; everything else is reserved.
constexpr std::uint8_t kButtonBit = 0x01, kSpraySwitchBit = 0x02;
constexpr std::uint8_t kDigitalOutputsUsed = kButtonBit | kSpraySwitchBit;
constexpr std::uint8_t kRebaseBit = 0x01;
constexpr std::uint8_t kCommandFlagsUsed = kRebaseBit;
constexpr std::uint8_t kForwardBit = 0x01, kReverseBit = 0x02, kUnloadingBit = 0x04;
constexpr std::uint8_t kRelayInputsUsed = kForwardBit | kReverseBit | kUnloadingBit;
constexpr std::uint8_t kPendingBit = 0x01, kOdometerBit = 0x02;
constexpr std::uint8_t kIndicatorInputsUsed = kPendingBit | kOdometerBit;
constexpr std::uint8_t kPulsesPendingBit = 0x01, kRateLimitedBit = 0x02, kTargetBehindBit = 0x04;
constexpr std::uint8_t kStatusFlagsUsed = kPulsesPendingBit | kRateLimitedBit | kTargetBehindBit;
constexpr std::uint8_t kLastProblemCode = static_cast<std::uint8_t>(ReportProblem::value_out_of_range);

void put_u16(Report& report, std::size_t offset, std::uint16_t value) {
    report[offset] = static_cast<std::uint8_t>(value & 0xFF);
    report[offset + 1] = static_cast<std::uint8_t>(value >> 8);
}

void put_u32(Report& report, std::size_t offset, std::uint32_t value) {
    for (std::size_t i = 0; i < 4; ++i) report[offset + i] = static_cast<std::uint8_t>(value >> (8 * i));
}

std::uint16_t get_u16(std::span<const std::uint8_t> bytes, std::size_t offset) {
    return static_cast<std::uint16_t>(bytes[offset] | (bytes[offset + 1] << 8));
}

std::uint32_t get_u32(std::span<const std::uint8_t> bytes, std::size_t offset) {
    std::uint32_t value = 0;
    for (std::size_t i = 0; i < 4; ++i) value |= static_cast<std::uint32_t>(bytes[offset + i]) << (8 * i);
    return value;
}

std::string hex_byte(unsigned value) {
    char text[8];
    std::snprintf(text, sizeof text, "0x%02X", value & 0xFFu);
    return text;
}

bool bit(std::uint8_t byte, std::uint8_t mask) { return (byte & mask) != 0; }

std::uint8_t bits(std::initializer_list<std::pair<bool, std::uint8_t>> flags) {
    std::uint8_t byte = 0;
    for (const auto& [set, mask] : flags) {
        if (set) byte = static_cast<std::uint8_t>(byte | mask);
    }
    return byte;
}

// Checks shared by both reports, in the order a reader would: length, id,
// version. Returns the error, or nullopt when the frame is fine.
std::optional<ReportError> check_frame(std::span<const std::uint8_t> bytes, std::uint8_t expected_id,
                                       const char* report_name) {
    if (bytes.size() != kReportSize) {
        return ReportError{ReportProblem::wrong_length, std::string(report_name) + " report is " +
                                                            std::to_string(bytes.size()) + " bytes, expected " +
                                                            std::to_string(kReportSize) + " (report id included)"};
    }
    if (bytes[0] != expected_id) {
        return ReportError{ReportProblem::wrong_report_id, "report id " + hex_byte(bytes[0]) + ", expected " +
                                                               hex_byte(expected_id) + " (" + report_name + ")"};
    }
    const std::uint8_t oldest = expected_id == kEdgeReportId ? kPwmCaptureVersion : kOldestProtocolVersion;
    if (bytes[1] < oldest || bytes[1] > kProtocolVersion) {
        return ReportError{ReportProblem::unsupported_version,
                           std::string(report_name) + " report has protocol version " + std::to_string(bytes[1]) +
                               ", this rig speaks versions " + std::to_string(oldest) + ".." +
                               std::to_string(kProtocolVersion)};
    }
    return std::nullopt;
}

std::optional<ReportError> check_reserved_bits(std::span<const std::uint8_t> bytes, std::size_t offset,
                                               std::uint8_t used, const char* field) {
    const auto reserved = static_cast<std::uint8_t>(bytes[offset] & ~used);
    if (reserved == 0) return std::nullopt;
    return ReportError{ReportProblem::reserved_bits_set, "byte " + std::to_string(offset) + " (" + field +
                                                             "): reserved bits " + hex_byte(reserved) + " set"};
}

std::optional<ReportError> check_reserved_bytes(std::span<const std::uint8_t> bytes, std::size_t first,
                                                std::size_t end) {
    for (std::size_t offset = first; offset < end; ++offset) {
        if (bytes[offset] != 0) {
            return ReportError{ReportProblem::reserved_bits_set, "reserved byte " + std::to_string(offset) + " is " +
                                                                     hex_byte(bytes[offset]) + ", must be 0"};
        }
    }
    return std::nullopt;
}

std::optional<ReportError> check_analog_code(std::span<const std::uint8_t> bytes, std::size_t offset,
                                             const char* field) {
    const std::uint16_t code = get_u16(bytes, offset);
    if (code <= kMaxAnalogCode) return std::nullopt;
    return ReportError{ReportProblem::value_out_of_range, "bytes " + std::to_string(offset) + "-" +
                                                              std::to_string(offset + 1) + " (" + field + "): " +
                                                              std::to_string(code) + " exceeds the 12-bit range 0.." +
                                                              std::to_string(kMaxAnalogCode)};
}

template <class T>
Decoded<T> refused(ReportError error) {
    return Decoded<T>{std::nullopt, std::move(error)};
}

}  // namespace

const char* to_string(ReportProblem problem) {
    switch (problem) {
        case ReportProblem::none: return "none";
        case ReportProblem::wrong_length: return "wrong length";
        case ReportProblem::wrong_report_id: return "wrong report id";
        case ReportProblem::unsupported_version: return "unsupported protocol version";
        case ReportProblem::reserved_bits_set: return "reserved bits set";
        case ReportProblem::value_out_of_range: return "value out of range";
    }
    return "unknown problem";
}

std::int64_t counter_ahead(std::uint32_t from, std::uint32_t to) {
    return static_cast<std::int32_t>(to - from);  // two's complement: the short way round
}

Report encode_command(const BoardCommand& command) {
    const io::DeviceSignals& signals = command.signals;
    for (const auto& [code, field] : {std::pair{signals.pump_flow_adc, "pump_flow_adc"},
                                      std::pair{signals.boom_height_adc, "boom_height_adc"}}) {
        if (code > kMaxAnalogCode) {
            throw std::invalid_argument(std::string("HID command: ") + field + " " + std::to_string(code) +
                                        " exceeds the 12-bit range 0.." + std::to_string(kMaxAnalogCode));
        }
    }
    Report report{};
    report[0] = kCommandReportId;
    if ((command.pwm_capture_inputs & ~kPwmCaptureInputMask) != 0) {
        throw std::invalid_argument("HID command: pwm_capture_inputs " + hex_byte(command.pwm_capture_inputs) +
                                    " names an input above " + std::to_string(kPwmCaptureInputs - 1));
    }
    // Version 1 unless capture is asked for: a version-1 board gets exactly what it always did.
    report[command_offset::kVersion] = command.pwm_capture_inputs != 0 ? kPwmCaptureVersion : kOldestProtocolVersion;
    report[command_offset::kPwmCaptureInputs] = command.pwm_capture_inputs;
    put_u16(report, command_offset::kSequence, command.sequence);
    put_u32(report, command_offset::kWheelTarget, signals.wheel_encoder_count);
    put_u32(report, command_offset::kFlowTarget, signals.main_flow_pulses);
    put_u32(report, command_offset::kSpreadInterval, command.spread_interval_us);
    put_u16(report, command_offset::kPumpFlowCode, signals.pump_flow_adc);
    put_u16(report, command_offset::kBoomHeightCode, signals.boom_height_adc);
    report[command_offset::kDigitalOutputs] =
        bits({{signals.breakpoint_button, kButtonBit}, {signals.spray_switch, kSpraySwitchBit}});
    report[command_offset::kFlags] = bits({{command.rebase_counters, kRebaseBit}});
    return report;
}

Report encode_status(const BoardStatus& status) {
    const auto problem = static_cast<std::uint8_t>(status.last_command_problem);
    if (problem > kLastProblemCode) {
        throw std::invalid_argument("HID status: last_command_problem code " + std::to_string(problem) +
                                    " is not a ReportProblem");
    }
    Report report{};
    report[0] = kStatusReportId;
    if (status.protocol_version < kOldestProtocolVersion || status.protocol_version > kProtocolVersion) {
        throw std::invalid_argument("HID status: protocol_version " + std::to_string(status.protocol_version) +
                                    " is not 1.." + std::to_string(kProtocolVersion));
    }
    report[status_offset::kVersion] = status.protocol_version;
    put_u16(report, status_offset::kSequence, status.sequence);
    put_u16(report, status_offset::kCommandSequence, status.last_command_sequence);
    report[status_offset::kRelayInputs] = bits({{status.actuators.ball_valve_forward, kForwardBit},
                                                {status.actuators.ball_valve_reverse, kReverseBit},
                                                {status.actuators.unloading_valve_open, kUnloadingBit}});
    report[status_offset::kSectionValves] = status.actuators.section_valves_open;
    put_u32(report, status_offset::kWheelEmitted, status.wheel_encoder_emitted);
    put_u32(report, status_offset::kFlowEmitted, status.main_flow_emitted);
    put_u32(report, status_offset::kBoardTime, status.board_time_us);
    report[status_offset::kIndicatorInputs] = bits({{status.indicators.breakpoint_pending, kPendingBit},
                                                    {status.indicators.odometer_active, kOdometerBit}});
    report[status_offset::kFlags] = bits({{status.pulses_pending, kPulsesPendingBit},
                                          {status.rate_limited, kRateLimitedBit},
                                          {status.target_behind, kTargetBehindBit}});
    report[status_offset::kCommandProblem] = problem;
    put_u16(report, status_offset::kBreakpointsStored, status.indicators.breakpoints_stored);
    put_u16(report, status_offset::kBreakpointsReached, status.indicators.breakpoints_reached);
    return report;
}

Decoded<BoardCommand> decode_command(std::span<const std::uint8_t> bytes) {
    if (auto error = check_frame(bytes, kCommandReportId, "command")) return refused<BoardCommand>(*error);
    for (auto error : {check_analog_code(bytes, command_offset::kPumpFlowCode, "pump-flow sensor code"),
                       check_analog_code(bytes, command_offset::kBoomHeightCode, "boom-height sensor code"),
                       check_reserved_bits(bytes, command_offset::kDigitalOutputs, kDigitalOutputsUsed,
                                           "digital outputs"),
                       check_reserved_bits(bytes, command_offset::kFlags, kCommandFlagsUsed, "command flags")}) {
        if (error) return refused<BoardCommand>(*error);
    }
    const bool v2 = bytes[command_offset::kVersion] >= kPwmCaptureVersion;
    if (v2) {
        if (auto error = check_reserved_bits(bytes, command_offset::kPwmCaptureInputs, kPwmCaptureInputMask,
                                             "PWM capture inputs")) {
            return refused<BoardCommand>(*error);
        }
    }
    if (auto error = check_reserved_bytes(
            bytes, v2 ? command_offset::kFirstReservedV2 : command_offset::kFirstReservedV1, kReportSize)) {
        return refused<BoardCommand>(*error);
    }
    BoardCommand command;
    command.sequence = get_u16(bytes, command_offset::kSequence);
    command.signals.wheel_encoder_count = get_u32(bytes, command_offset::kWheelTarget);
    command.signals.main_flow_pulses = get_u32(bytes, command_offset::kFlowTarget);
    command.spread_interval_us = get_u32(bytes, command_offset::kSpreadInterval);
    command.signals.pump_flow_adc = get_u16(bytes, command_offset::kPumpFlowCode);
    command.signals.boom_height_adc = get_u16(bytes, command_offset::kBoomHeightCode);
    const std::uint8_t outputs = bytes[command_offset::kDigitalOutputs];
    command.signals.breakpoint_button = bit(outputs, kButtonBit);
    command.signals.spray_switch = bit(outputs, kSpraySwitchBit);
    command.rebase_counters = bit(bytes[command_offset::kFlags], kRebaseBit);
    command.protocol_version = bytes[command_offset::kVersion];
    command.pwm_capture_inputs = v2 ? bytes[command_offset::kPwmCaptureInputs] : 0;
    return Decoded<BoardCommand>{command, {}};
}

Decoded<BoardStatus> decode_status(std::span<const std::uint8_t> bytes) {
    if (auto error = check_frame(bytes, kStatusReportId, "status")) return refused<BoardStatus>(*error);
    for (auto error :
         {check_reserved_bits(bytes, status_offset::kRelayInputs, kRelayInputsUsed, "relay inputs"),
          check_reserved_bits(bytes, status_offset::kIndicatorInputs, kIndicatorInputsUsed, "indicator inputs"),
          check_reserved_bits(bytes, status_offset::kFlags, kStatusFlagsUsed, "status flags"),
          check_reserved_bytes(bytes, status_offset::kReservedByte23, status_offset::kReservedByte23 + 1),
          check_reserved_bytes(bytes, status_offset::kFirstReserved, kReportSize)}) {
        if (error) return refused<BoardStatus>(*error);
    }
    const std::uint8_t problem = bytes[status_offset::kCommandProblem];
    if (problem > kLastProblemCode) {
        return refused<BoardStatus>({ReportProblem::value_out_of_range,
                                     "byte 22 (last command problem): code " + std::to_string(problem) +
                                         " is not defined (0.." + std::to_string(kLastProblemCode) + ")"});
    }
    BoardStatus status;
    status.sequence = get_u16(bytes, status_offset::kSequence);
    status.last_command_sequence = get_u16(bytes, status_offset::kCommandSequence);
    const std::uint8_t relays = bytes[status_offset::kRelayInputs];
    status.actuators.ball_valve_forward = bit(relays, kForwardBit);
    status.actuators.ball_valve_reverse = bit(relays, kReverseBit);
    status.actuators.unloading_valve_open = bit(relays, kUnloadingBit);
    status.actuators.section_valves_open = bytes[status_offset::kSectionValves];
    status.wheel_encoder_emitted = get_u32(bytes, status_offset::kWheelEmitted);
    status.main_flow_emitted = get_u32(bytes, status_offset::kFlowEmitted);
    status.board_time_us = get_u32(bytes, status_offset::kBoardTime);
    const std::uint8_t indicators = bytes[status_offset::kIndicatorInputs];
    status.indicators.breakpoint_pending = bit(indicators, kPendingBit);
    status.indicators.odometer_active = bit(indicators, kOdometerBit);
    const std::uint8_t flags = bytes[status_offset::kFlags];
    status.pulses_pending = bit(flags, kPulsesPendingBit);
    status.rate_limited = bit(flags, kRateLimitedBit);
    status.target_behind = bit(flags, kTargetBehindBit);
    status.last_command_problem = static_cast<ReportProblem>(problem);
    status.indicators.breakpoints_stored = get_u16(bytes, status_offset::kBreakpointsStored);
    status.indicators.breakpoints_reached = get_u16(bytes, status_offset::kBreakpointsReached);
    status.protocol_version = bytes[status_offset::kVersion];
    return Decoded<BoardStatus>{status, {}};
}

Report encode_edges(const EdgeReport& edges) {
    if (edges.edges.size() > kMaxEdgesPerReport) {
        throw std::invalid_argument("HID edges: " + std::to_string(edges.edges.size()) + " edges, a report holds " +
                                    std::to_string(kMaxEdgesPerReport));
    }
    if ((edges.levels & ~kPwmCaptureInputMask) != 0) {
        throw std::invalid_argument("HID edges: levels " + hex_byte(edges.levels) + " name an input above " +
                                    std::to_string(kPwmCaptureInputs - 1));
    }
    Report report{};
    report[0] = kEdgeReportId;
    report[edge_offset::kVersion] = kPwmCaptureVersion;
    put_u16(report, edge_offset::kSequence, edges.sequence);
    put_u32(report, edge_offset::kReportTime, edges.report_time_us);
    report[edge_offset::kLevels] = edges.levels;
    report[edge_offset::kFlags] = bits({{edges.overflow, kOverflowBit}});
    report[edge_offset::kCount] = static_cast<std::uint8_t>(edges.edges.size());
    const std::uint32_t base = edges.edges.empty() ? 0 : edges.edges.front().time_us;
    put_u32(report, edge_offset::kBaseTime, base);
    std::uint32_t previous_offset = 0;
    for (std::size_t i = 0; i < edges.edges.size(); ++i) {
        const CapturedEdge& edge = edges.edges[i];
        const std::string which = "HID edges: edge " + std::to_string(i);
        if (edge.input >= kPwmCaptureInputs) {
            throw std::invalid_argument(which + ": input " + std::to_string(edge.input) + " is not 0.." +
                                        std::to_string(kPwmCaptureInputs - 1));
        }
        const std::int64_t offset = counter_ahead(base, edge.time_us);
        if (offset < previous_offset || offset > kMaxEdgeOffsetUs) {
            throw std::invalid_argument(which + ": " + std::to_string(offset) + " us after edge 0 (edges in time order, within " +
                                        std::to_string(kMaxEdgeOffsetUs) + " us)");
        }
        if (counter_ahead(edge.time_us, edges.report_time_us) < 0) {
            throw std::invalid_argument(which + ": after the report time");
        }
        previous_offset = static_cast<std::uint32_t>(offset);
        const std::uint32_t packed = static_cast<std::uint32_t>(offset) |
                                     (static_cast<std::uint32_t>(edge.input) << kEdgeInputShift) |
                                     (edge.rising ? kEdgeRisingBit : 0u);
        const std::size_t at = edge_offset::kFirstEdge + i * edge_offset::kEdgeSize;
        for (std::size_t b = 0; b < edge_offset::kEdgeSize; ++b) report[at + b] = static_cast<std::uint8_t>(packed >> (8 * b));
    }
    return report;
}

Decoded<EdgeReport> decode_edges(std::span<const std::uint8_t> bytes) {
    if (auto error = check_frame(bytes, kEdgeReportId, "edge")) return refused<EdgeReport>(*error);
    const std::size_t count = bytes[edge_offset::kCount];
    if (count > kMaxEdgesPerReport) {
        return refused<EdgeReport>({ReportProblem::value_out_of_range,
                                    "byte 10 (edge count): " + std::to_string(count) + " edges, a report holds " +
                                        std::to_string(kMaxEdgesPerReport)});
    }
    for (auto error : {check_reserved_bits(bytes, edge_offset::kLevels, kPwmCaptureInputMask, "capture input levels"),
                       check_reserved_bits(bytes, edge_offset::kFlags, kEdgeFlagsUsed, "edge flags"),
                       check_reserved_bytes(bytes, edge_offset::kReservedByte11, edge_offset::kReservedByte11 + 1),
                       check_reserved_bytes(bytes, edge_offset::kFirstEdge + count * edge_offset::kEdgeSize,
                                            kReportSize)}) {
        if (error) return refused<EdgeReport>(*error);
    }
    EdgeReport report;
    report.sequence = get_u16(bytes, edge_offset::kSequence);
    report.report_time_us = get_u32(bytes, edge_offset::kReportTime);
    report.levels = bytes[edge_offset::kLevels];
    report.overflow = bit(bytes[edge_offset::kFlags], kOverflowBit);
    const std::uint32_t base = get_u32(bytes, edge_offset::kBaseTime);
    if (count == 0 && base != 0) {
        return refused<EdgeReport>({ReportProblem::reserved_bits_set, "bytes 12-15 (base time): " +
                                                                          std::to_string(base) +
                                                                          " with no edges, must be 0"});
    }
    std::uint32_t previous_offset = 0;
    for (std::size_t i = 0; i < count; ++i) {
        const std::size_t at = edge_offset::kFirstEdge + i * edge_offset::kEdgeSize;
        std::uint32_t packed = 0;
        for (std::size_t b = 0; b < edge_offset::kEdgeSize; ++b) packed |= static_cast<std::uint32_t>(bytes[at + b]) << (8 * b);
        const std::uint32_t offset = packed & kMaxEdgeOffsetUs;
        const auto input = static_cast<std::uint8_t>((packed >> kEdgeInputShift) & 0x7u);
        const std::string where = "bytes " + std::to_string(at) + "-" + std::to_string(at + 2) + " (edge " +
                                  std::to_string(i) + "): ";
        if (input >= kPwmCaptureInputs) {
            return refused<EdgeReport>({ReportProblem::value_out_of_range,
                                        where + "input " + std::to_string(input) + " is not 0.." +
                                            std::to_string(kPwmCaptureInputs - 1)});
        }
        if (i == 0 && offset != 0) {
            return refused<EdgeReport>({ReportProblem::value_out_of_range,
                                        where + "the first edge is the base, its offset " + std::to_string(offset) +
                                            " must be 0"});
        }
        if (offset < previous_offset) {
            return refused<EdgeReport>({ReportProblem::value_out_of_range,
                                        where + "offset " + std::to_string(offset) + " us before the previous edge's " +
                                            std::to_string(previous_offset)});
        }
        previous_offset = offset;
        const std::uint32_t time = base + offset;  // wraps with the board's clock
        if (counter_ahead(time, report.report_time_us) < 0) {
            return refused<EdgeReport>({ReportProblem::value_out_of_range,
                                        where + "at board time " + std::to_string(time) + " us, after the report time " +
                                            std::to_string(report.report_time_us)});
        }
        report.edges.push_back(CapturedEdge{time, input, (packed & kEdgeRisingBit) != 0});
    }
    return Decoded<EdgeReport>{std::move(report), {}};
}

}  // namespace rig::hid
