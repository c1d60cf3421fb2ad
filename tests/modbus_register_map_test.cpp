// Modbus register map: encode/decode round trips over the whole value space
// that matters (every section mask, counter values at the word boundaries),
// the word order written out by hand, and the write checks for reserved
// coils and flag bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "rig/wire/modbus_register_map.h"

namespace rig::modbus {
namespace {

io::DeviceSignals signals_with(std::uint32_t wheel, std::uint32_t flow, std::uint16_t pump, std::uint16_t boom,
                               bool button, bool spray) {
    io::DeviceSignals signals;
    signals.wheel_encoder_count = wheel;
    signals.main_flow_pulses = flow;
    signals.pump_flow_adc = pump;
    signals.boom_height_adc = boom;
    signals.breakpoint_button = button;
    signals.spray_switch = spray;
    return signals;
}

void expect_same(const io::DeviceSignals& a, const io::DeviceSignals& b) {
    EXPECT_EQ(a.wheel_encoder_count, b.wheel_encoder_count);
    EXPECT_EQ(a.main_flow_pulses, b.main_flow_pulses);
    EXPECT_EQ(a.main_flow_last_edge_us, b.main_flow_last_edge_us);
    EXPECT_EQ(a.wheel_encoder_last_edge_us, b.wheel_encoder_last_edge_us);
    EXPECT_EQ(a.pump_flow_adc, b.pump_flow_adc);
    EXPECT_EQ(a.boom_height_adc, b.boom_height_adc);
    EXPECT_EQ(a.breakpoint_button, b.breakpoint_button);
    EXPECT_EQ(a.spray_switch, b.spray_switch);
}

TEST(ModbusRegisterMap, WordOrderIsHighWordFirst) {
    io::DeviceSignals signals = signals_with(0x12345678u, 0xCAFEF00Du, 4095, 17, false, true);
    signals.main_flow_last_edge_us = 0x0BADBEEFu;
    signals.wheel_encoder_last_edge_us = 0xFEEDC0DEu;
    const InputRegisters registers = encode_input_registers(signals);
    EXPECT_EQ(registers[0], 0x1234);
    EXPECT_EQ(registers[1], 0x5678);
    EXPECT_EQ(registers[2], 0xCAFE);
    EXPECT_EQ(registers[3], 0xF00D);
    EXPECT_EQ(registers[4], 4095);
    EXPECT_EQ(registers[5], 17);
    EXPECT_EQ(registers[6], kRegisterMapVersion);
    EXPECT_EQ(map_version_of(registers), 3);
    // Version 2's flow-meter capture, then version 3's encoder capture.
    EXPECT_EQ(registers[7], 0x0BAD);
    EXPECT_EQ(registers[8], 0xBEEF);
    EXPECT_EQ(registers[9], 0xFEED);
    EXPECT_EQ(registers[10], 0xC0DE);
    EXPECT_EQ(registers.size(), 11u);
}

TEST(ModbusRegisterMap, DeviceSignalsRoundTrip) {
    const std::vector<std::uint32_t> counts{0u, 1u, 0xFFFFu, 0x10000u, 0x7FFFFFFFu, 0x80000000u, 0xFFFFFFFEu, 0xFFFFFFFFu};
    const std::vector<std::uint16_t> adcs{0, 1, 2048, 4094, 4095};
    for (std::uint32_t wheel : counts) {
        for (std::uint32_t flow : counts) {
            for (std::uint16_t adc : adcs) {
                for (int bits = 0; bits < 4; ++bits) {
                    auto original = signals_with(wheel, flow, adc, static_cast<std::uint16_t>(4095 - adc),
                                                 (bits & 1) != 0, (bits & 2) != 0);
                    // The capture times (uint32 like the counts): the counts swapped round.
                    original.main_flow_last_edge_us = wheel;
                    original.wheel_encoder_last_edge_us = flow;
                    RegisterImage image;
                    encode_device_signals(original, image);
                    expect_same(decode_device_signals(image.input_registers, image.discrete_inputs), original);
                }
            }
        }
    }
}

TEST(ModbusRegisterMap, DiscreteInputsPlaces) {
    const DiscreteInputs only_button = encode_discrete_inputs(signals_with(0, 0, 0, 0, true, false));
    EXPECT_TRUE(only_button[kDiscreteBreakpointButton]);
    EXPECT_FALSE(only_button[kDiscreteSpraySwitch]);
    const DiscreteInputs only_spray = encode_discrete_inputs(signals_with(0, 0, 0, 0, false, true));
    EXPECT_FALSE(only_spray[0]);
    EXPECT_TRUE(only_spray[1]);
}

TEST(ModbusRegisterMap, AdcOverFullScaleIsRefusedAndNamed) {
    RegisterImage image;
    encode_device_signals(signals_with(7, 8, 100, 200, false, false), image);
    const RegisterImage before = image;
    try {
        encode_device_signals(signals_with(9, 9, 4096, 0, true, true), image);
        FAIL() << "pump_flow_adc 4096 accepted";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("pump_flow_adc = 4096"), std::string::npos) << error.what();
        EXPECT_NE(std::string(error.what()).find("4095"), std::string::npos) << error.what();
    }
    EXPECT_THROW(encode_input_registers(signals_with(0, 0, 0, 65535, false, false)), std::invalid_argument);
    EXPECT_EQ(image.input_registers, before.input_registers) << "a refused encode must not change the image";
    EXPECT_EQ(image.discrete_inputs, before.discrete_inputs);
}

TEST(ModbusRegisterMap, ActuatorCommandsRoundTripEverySectionMask) {
    for (unsigned mask = 0; mask < 256; ++mask) {
        for (unsigned relays = 0; relays < 8; ++relays) {
            io::ActuatorCommands commands;
            commands.ball_valve_forward = (relays & 1u) != 0;
            commands.ball_valve_reverse = (relays & 2u) != 0;
            commands.unloading_valve_open = (relays & 4u) != 0;
            commands.section_valves_open = static_cast<std::uint8_t>(mask);
            const Coils coils = encode_coils(commands);
            for (std::uint16_t reserved = kCoilFirstReserved; reserved < kCoilFirstSectionValve; ++reserved) {
                ASSERT_FALSE(coils[reserved]) << "reserved coil " << reserved;
            }
            const io::ActuatorCommands decoded = decode_coils(coils);
            ASSERT_EQ(decoded.ball_valve_forward, commands.ball_valve_forward);
            ASSERT_EQ(decoded.ball_valve_reverse, commands.ball_valve_reverse);
            ASSERT_EQ(decoded.unloading_valve_open, commands.unloading_valve_open);
            ASSERT_EQ(decoded.section_valves_open, commands.section_valves_open);
        }
    }
}

TEST(ModbusRegisterMap, CoilPlaces) {
    io::ActuatorCommands commands;
    commands.unloading_valve_open = true;
    commands.section_valves_open = 0b1000'0001;  // sections 1 and 8
    const Coils coils = encode_coils(commands);
    const std::vector<std::uint16_t> on{2, 8, 15};
    for (std::uint16_t address = 0; address < kCoilCount; ++address) {
        const bool expected = std::find(on.begin(), on.end(), address) != on.end();
        EXPECT_EQ(coils[address], expected) << "coil " << address << " (" << coil_name(address) << ")";
    }
    EXPECT_EQ(coil_name(8), "section_valve_1");
    EXPECT_EQ(coil_name(15), "section_valve_8");
    EXPECT_EQ(coil_name(5), "reserved");
    EXPECT_EQ(coil_name(16), "unmapped");
}

TEST(ModbusRegisterMap, ReservedCoilsAreIgnoredOnDecodeAndRefusedOnWrite) {
    Coils coils{};
    for (std::uint16_t address = kCoilFirstReserved; address < kCoilFirstSectionValve; ++address) coils[address] = true;
    const io::ActuatorCommands decoded = decode_coils(coils);
    EXPECT_FALSE(decoded.ball_valve_forward);
    EXPECT_FALSE(decoded.ball_valve_reverse);
    EXPECT_FALSE(decoded.unloading_valve_open);
    EXPECT_EQ(decoded.section_valves_open, 0);
    for (std::uint16_t address = 0; address < kCoilCount; ++address) {
        const bool reserved = address >= kCoilFirstReserved && address < kCoilFirstSectionValve;
        EXPECT_TRUE(coil_write_problem(address, false).empty()) << "writing 0 is always fine, coil " << address;
        EXPECT_EQ(coil_write_problem(address, true).empty(), !reserved) << "coil " << address;
    }
    EXPECT_EQ(coil_write_problem(4, true), "coil 4 is reserved and must be written as 0");
}

TEST(ModbusRegisterMap, IndicatorsRoundTrip) {
    for (std::uint16_t stored : std::vector<std::uint16_t>{0, 1, 255, 256, 65535}) {
        for (std::uint16_t reached : std::vector<std::uint16_t>{0, 7, 65535}) {
            for (int flags = 0; flags < 4; ++flags) {
                io::ControllerIndicators indicators;
                indicators.breakpoints_stored = stored;
                indicators.breakpoints_reached = reached;
                indicators.breakpoint_pending = (flags & 1) != 0;
                indicators.odometer_active = (flags & 2) != 0;
                const HoldingRegisters registers = encode_holding_registers(indicators);
                EXPECT_EQ(registers[kHoldingBreakpointsStored], stored);
                EXPECT_EQ(registers[kHoldingBreakpointsReached], reached);
                EXPECT_EQ(registers[kHoldingIndicatorFlags], flags);
                for (std::uint16_t address = 0; address < kHoldingRegisterCount; ++address) {
                    EXPECT_TRUE(holding_register_write_problem(address, registers[address]).empty());
                }
                const io::ControllerIndicators decoded = decode_holding_registers(registers);
                EXPECT_EQ(decoded.breakpoints_stored, stored);
                EXPECT_EQ(decoded.breakpoints_reached, reached);
                EXPECT_EQ(decoded.breakpoint_pending, indicators.breakpoint_pending);
                EXPECT_EQ(decoded.odometer_active, indicators.odometer_active);
            }
        }
    }
}

TEST(ModbusRegisterMap, ReservedFlagBitsAreRefusedOnWriteAndIgnoredOnDecode) {
    EXPECT_EQ(holding_register_write_problem(kHoldingIndicatorFlags, 0x0004),
              "holding register 2 (indicator_flags) = 0x0004 sets reserved bits (only bit 0 breakpoint_pending and "
              "bit 1 odometer_active are defined)");
    EXPECT_FALSE(holding_register_write_problem(kHoldingIndicatorFlags, 0x8003).empty());
    // The counters take any value.
    EXPECT_TRUE(holding_register_write_problem(kHoldingBreakpointsStored, 0xFFFF).empty());
    EXPECT_TRUE(holding_register_write_problem(kHoldingBreakpointsReached, 0xFFFF).empty());
    const io::ControllerIndicators decoded = decode_holding_registers({0, 0, 0xFFFC});
    EXPECT_FALSE(decoded.breakpoint_pending);
    EXPECT_FALSE(decoded.odometer_active);
}

TEST(ModbusRegisterMap, NamesForMessages) {
    EXPECT_EQ(input_register_name(0), "wheel_encoder_count (high word)");
    EXPECT_EQ(input_register_name(6), "map_version");
    EXPECT_EQ(input_register_name(7), "main_flow_last_edge_us (high word)");
    EXPECT_EQ(input_register_name(9), "wheel_encoder_last_edge_us (high word)");
    EXPECT_EQ(input_register_name(10), "wheel_encoder_last_edge_us (low word)");
    EXPECT_EQ(input_register_name(11), "unmapped");
    EXPECT_EQ(holding_register_name(2), "indicator_flags");
    EXPECT_EQ(holding_register_name(3), "unmapped");
}

}  // namespace
}  // namespace rig::modbus
