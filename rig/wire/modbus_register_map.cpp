#include "rig/wire/modbus_register_map.h"

#include <stdexcept>

namespace rig::modbus {
namespace {

std::uint16_t high_word(std::uint32_t value) { return static_cast<std::uint16_t>(value >> 16); }
std::uint16_t low_word(std::uint32_t value) { return static_cast<std::uint16_t>(value & 0xFFFFu); }
std::uint32_t join_words(std::uint16_t high, std::uint16_t low) {
    return (static_cast<std::uint32_t>(high) << 16) | low;
}

std::uint16_t checked_adc(std::uint16_t value, const char* field) {
    if (value > io::kAdcFullScale) {
        throw std::invalid_argument(std::string("DeviceSignals.") + field + " = " + std::to_string(value) +
                                    " exceeds the 12-bit ADC full scale " + std::to_string(io::kAdcFullScale));
    }
    return value;
}

std::string hex16(std::uint16_t value) {
    static constexpr char kHexDigits[] = "0123456789ABCDEF";
    std::string hex = "0x";
    for (int shift = 12; shift >= 0; shift -= 4) hex += kHexDigits[(value >> shift) & 0xFu];
    return hex;
}

bool is_reserved_coil(std::uint16_t address) {
    return address >= kCoilFirstReserved && address < kCoilFirstSectionValve;
}

}  // namespace

InputRegisters encode_input_registers(const io::DeviceSignals& signals) {
    InputRegisters registers{};
    registers[kInputWheelEncoderCountHigh] = high_word(signals.wheel_encoder_count);
    registers[kInputWheelEncoderCountLow] = low_word(signals.wheel_encoder_count);
    registers[kInputMainFlowPulsesHigh] = high_word(signals.main_flow_pulses);
    registers[kInputMainFlowPulsesLow] = low_word(signals.main_flow_pulses);
    registers[kInputPumpFlowAdc] = checked_adc(signals.pump_flow_adc, "pump_flow_adc");
    registers[kInputBoomHeightAdc] = checked_adc(signals.boom_height_adc, "boom_height_adc");
    registers[kInputMapVersion] = kRegisterMapVersion;
    registers[kInputMainFlowLastEdgeHigh] = high_word(signals.main_flow_last_edge_us);
    registers[kInputMainFlowLastEdgeLow] = low_word(signals.main_flow_last_edge_us);
    registers[kInputWheelEncoderLastEdgeHigh] = high_word(signals.wheel_encoder_last_edge_us);
    registers[kInputWheelEncoderLastEdgeLow] = low_word(signals.wheel_encoder_last_edge_us);
    return registers;
}

DiscreteInputs encode_discrete_inputs(const io::DeviceSignals& signals) {
    DiscreteInputs inputs{};
    inputs[kDiscreteBreakpointButton] = signals.breakpoint_button;
    inputs[kDiscreteSpraySwitch] = signals.spray_switch;
    return inputs;
}

void encode_device_signals(const io::DeviceSignals& signals, RegisterImage& image) {
    // Both encoded before either is stored: a throw leaves the image as it was.
    const InputRegisters registers = encode_input_registers(signals);
    image.discrete_inputs = encode_discrete_inputs(signals);
    image.input_registers = registers;
}

io::DeviceSignals decode_device_signals(const InputRegisters& input_registers, const DiscreteInputs& discrete_inputs) {
    io::DeviceSignals signals;
    signals.wheel_encoder_count =
        join_words(input_registers[kInputWheelEncoderCountHigh], input_registers[kInputWheelEncoderCountLow]);
    signals.main_flow_pulses =
        join_words(input_registers[kInputMainFlowPulsesHigh], input_registers[kInputMainFlowPulsesLow]);
    signals.main_flow_last_edge_us =
        join_words(input_registers[kInputMainFlowLastEdgeHigh], input_registers[kInputMainFlowLastEdgeLow]);
    signals.wheel_encoder_last_edge_us =
        join_words(input_registers[kInputWheelEncoderLastEdgeHigh], input_registers[kInputWheelEncoderLastEdgeLow]);
    signals.pump_flow_adc = input_registers[kInputPumpFlowAdc];
    signals.boom_height_adc = input_registers[kInputBoomHeightAdc];
    signals.breakpoint_button = discrete_inputs[kDiscreteBreakpointButton];
    signals.spray_switch = discrete_inputs[kDiscreteSpraySwitch];
    return signals;
}

Coils encode_coils(const io::ActuatorCommands& commands) {
    Coils coils{};
    coils[kCoilBallValveForward] = commands.ball_valve_forward;
    coils[kCoilBallValveReverse] = commands.ball_valve_reverse;
    coils[kCoilUnloadingValve] = commands.unloading_valve_open;
    for (std::uint16_t section = 0; section < kSectionValveCount; ++section) {
        coils[kCoilFirstSectionValve + section] = ((commands.section_valves_open >> section) & 1u) != 0;
    }
    return coils;
}

io::ActuatorCommands decode_coils(const Coils& coils) {
    io::ActuatorCommands commands;
    commands.ball_valve_forward = coils[kCoilBallValveForward];
    commands.ball_valve_reverse = coils[kCoilBallValveReverse];
    commands.unloading_valve_open = coils[kCoilUnloadingValve];
    unsigned sections = 0;
    for (std::uint16_t section = 0; section < kSectionValveCount; ++section) {
        if (coils[kCoilFirstSectionValve + section]) sections |= 1u << section;
    }
    commands.section_valves_open = static_cast<std::uint8_t>(sections);
    return commands;
}

HoldingRegisters encode_holding_registers(const io::ControllerIndicators& indicators) {
    HoldingRegisters registers{};
    registers[kHoldingBreakpointsStored] = indicators.breakpoints_stored;
    registers[kHoldingBreakpointsReached] = indicators.breakpoints_reached;
    registers[kHoldingIndicatorFlags] = static_cast<std::uint16_t>((indicators.breakpoint_pending ? kFlagBreakpointPending : 0u) |
                                                                   (indicators.odometer_active ? kFlagOdometerActive : 0u));
    return registers;
}

io::ControllerIndicators decode_holding_registers(const HoldingRegisters& registers) {
    io::ControllerIndicators indicators;
    indicators.breakpoints_stored = registers[kHoldingBreakpointsStored];
    indicators.breakpoints_reached = registers[kHoldingBreakpointsReached];
    const std::uint16_t flags = registers[kHoldingIndicatorFlags];
    indicators.breakpoint_pending = (flags & kFlagBreakpointPending) != 0;
    indicators.odometer_active = (flags & kFlagOdometerActive) != 0;
    return indicators;
}

std::string coil_write_problem(std::uint16_t address, bool value) {
    if (value && is_reserved_coil(address)) {
        return "coil " + std::to_string(address) + " is reserved and must be written as 0";
    }
    return {};
}

std::string holding_register_write_problem(std::uint16_t address, std::uint16_t value) {
    if (address == kHoldingIndicatorFlags && (value & ~kIndicatorFlagsDefined) != 0) {
        return "holding register " + std::to_string(address) + " (indicator_flags) = " + hex16(value) +
               " sets reserved bits (only bit 0 breakpoint_pending and bit 1 odometer_active are defined)";
    }
    return {};
}

std::string input_register_name(std::uint16_t address) {
    switch (address) {
        case kInputWheelEncoderCountHigh: return "wheel_encoder_count (high word)";
        case kInputWheelEncoderCountLow: return "wheel_encoder_count (low word)";
        case kInputMainFlowPulsesHigh: return "main_flow_pulses (high word)";
        case kInputMainFlowPulsesLow: return "main_flow_pulses (low word)";
        case kInputMainFlowLastEdgeHigh: return "main_flow_last_edge_us (high word)";
        case kInputMainFlowLastEdgeLow: return "main_flow_last_edge_us (low word)";
        case kInputWheelEncoderLastEdgeHigh: return "wheel_encoder_last_edge_us (high word)";
        case kInputWheelEncoderLastEdgeLow: return "wheel_encoder_last_edge_us (low word)";
        case kInputPumpFlowAdc: return "pump_flow_adc";
        case kInputBoomHeightAdc: return "boom_height_adc";
        case kInputMapVersion: return "map_version";
        default: return "unmapped";
    }
}

std::string coil_name(std::uint16_t address) {
    if (address == kCoilBallValveForward) return "ball_valve_forward";
    if (address == kCoilBallValveReverse) return "ball_valve_reverse";
    if (address == kCoilUnloadingValve) return "unloading_valve_open";
    if (is_reserved_coil(address)) return "reserved";
    if (address >= kCoilFirstSectionValve && address < kCoilCount) {
        return "section_valve_" + std::to_string(address - kCoilFirstSectionValve + 1);
    }
    return "unmapped";
}

std::string holding_register_name(std::uint16_t address) {
    switch (address) {
        case kHoldingBreakpointsStored: return "breakpoints_stored";
        case kHoldingBreakpointsReached: return "breakpoints_reached";
        case kHoldingIndicatorFlags: return "indicator_flags";
        default: return "unmapped";
    }
}

}  // namespace rig::modbus
