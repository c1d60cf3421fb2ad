#pragma once
// The Modbus register map of the bench wire (docs/design.md "Who uses it": a real
// controller board wired to the rig over Modbus RTU/TCP). The rig is the slave
// (server) and serves the board's inputs; the controller board is the master
// (client) and writes its outputs. Same vocabulary as every other wire:
// rig/runtime/io_image.h. docs/modbus-register-map.md is the same table for people
// setting up a board or mbpoll; keep the two in step.
//
// Addresses are PDU addresses (0-based, what goes on the wire). Tools that use
// 1-based "references" (mbpoll without -0, many HMIs) show address A as A+1.
//
// Map version 3 (version 1 had no capture times; 2 added the flow meter's at
// 7-8, 3 the wheel encoder's at 9-10)
// | table (FC)                  | addr | name                 | type / range                                  |
// |-----------------------------|------|----------------------|-----------------------------------------------|
// | input registers (04)        | 0-1  | wheel_encoder_count  | uint32, high word at 0 (wraps at 2^32)        |
// |                             | 2-3  | main_flow_pulses     | uint32, high word at 2 (wraps at 2^32)        |
// |                             | 4    | pump_flow_adc        | 0..4095 (12-bit ADC, Eq. 8)                   |
// |                             | 5    | boom_height_adc      | 0..4095                                       |
// |                             | 6    | map_version          | 3 (read it first; a master checks it)         |
// |                             | 7-8  | main_flow_last_edge_us | uint32, high word at 7: the frequency input's |
// |                             |      |                      | 1 MHz capture timer at the last meter pulse   |
// |                             | 9-10 | wheel_encoder_last_edge_us | uint32, high word at 9: the same timer at |
// |                             |      |                      | the encoder's last counted edge               |
// | discrete inputs (02)        | 0    | breakpoint_button    | 1 = pressed                                   |
// |                             | 1    | spray_switch         | 1 = on                                        |
// | coils (01, 05, 15)          | 0    | ball_valve_forward   | relay 1, 1 = energised (towards open)         |
// |                             | 1    | ball_valve_reverse   | relay 2, 1 = energised (towards closed)       |
// |                             | 2    | unloading_valve_open | 1 = open (pump flow back to the tank)         |
// |                             | 3-7  | reserved             | read 0; writing 1 is ILLEGAL DATA VALUE       |
// |                             | 8-15 | section_valve_1..8   | coil 8+i = bit i of section_valves_open       |
// | holding registers (03,06,16)| 0    | breakpoints_stored   | uint16 counter (wraps)                        |
// |                             | 1    | breakpoints_reached  | uint16 counter (wraps)                        |
// |                             | 2    | indicator_flags      | bit0 breakpoint_pending, bit1 odometer_active;|
// |                             |      |                      | bits 2-15 reserved: nonzero = ILLEGAL DATA VALUE |
//
// Why this layout:
// - 32-bit counters are two registers, high word first (Modbus is big-endian
//   within a register; "high word first" extends that, and is mbpoll's -B).
//   A master must read both words in ONE request: the slave serves a request
//   from one consistent snapshot, so the pair never tears.
// - The section valves start at coil 8 so that one FC 15 of coils 0-15 carries
//   the relays in its first data byte and section_valves_open as its second.
//   Coils 3-7 are addressable so that this 16-coil write is legal; they are
//   reserved and must be written as 0.
// - The map version sits after the version-1 inputs; version 2 appended the
//   flow meter's capture time (7-8), version 3 the encoder's (9-10), so reading
//   0-10 in one request gets every input and the version. Registers 0-8 mean
//   what they meant in version 2.
// - Anything outside the tables is ILLEGAL DATA ADDRESS: a master with a wrong
//   map learns at once instead of reading zeros.
#include <array>
#include <cstdint>
#include <string>

#include "rig/runtime/io_image.h"

namespace rig::modbus {

inline constexpr std::uint16_t kRegisterMapVersion = 3;

// Input registers (FC 04).
inline constexpr std::uint16_t kInputWheelEncoderCountHigh = 0;
inline constexpr std::uint16_t kInputWheelEncoderCountLow = 1;
inline constexpr std::uint16_t kInputMainFlowPulsesHigh = 2;
inline constexpr std::uint16_t kInputMainFlowPulsesLow = 3;
inline constexpr std::uint16_t kInputPumpFlowAdc = 4;
inline constexpr std::uint16_t kInputBoomHeightAdc = 5;
inline constexpr std::uint16_t kInputMapVersion = 6;
inline constexpr std::uint16_t kInputMainFlowLastEdgeHigh = 7;
inline constexpr std::uint16_t kInputMainFlowLastEdgeLow = 8;
inline constexpr std::uint16_t kInputWheelEncoderLastEdgeHigh = 9;
inline constexpr std::uint16_t kInputWheelEncoderLastEdgeLow = 10;
inline constexpr std::uint16_t kInputRegisterCount = 11;

// Discrete inputs (FC 02).
inline constexpr std::uint16_t kDiscreteBreakpointButton = 0;
inline constexpr std::uint16_t kDiscreteSpraySwitch = 1;
inline constexpr std::uint16_t kDiscreteInputCount = 2;

// Coils (FC 01, 05, 15).
inline constexpr std::uint16_t kCoilBallValveForward = 0;
inline constexpr std::uint16_t kCoilBallValveReverse = 1;
inline constexpr std::uint16_t kCoilUnloadingValve = 2;
inline constexpr std::uint16_t kCoilFirstReserved = 3;
inline constexpr std::uint16_t kCoilFirstSectionValve = 8;  // section i (0-based bit) at 8 + i
inline constexpr std::uint16_t kSectionValveCount = 8;
inline constexpr std::uint16_t kCoilCount = kCoilFirstSectionValve + kSectionValveCount;

// Holding registers (FC 03, 06, 16).
inline constexpr std::uint16_t kHoldingBreakpointsStored = 0;
inline constexpr std::uint16_t kHoldingBreakpointsReached = 1;
inline constexpr std::uint16_t kHoldingIndicatorFlags = 2;
inline constexpr std::uint16_t kHoldingRegisterCount = 3;
inline constexpr std::uint16_t kFlagBreakpointPending = 1u << 0;
inline constexpr std::uint16_t kFlagOdometerActive = 1u << 1;
inline constexpr std::uint16_t kIndicatorFlagsDefined = kFlagBreakpointPending | kFlagOdometerActive;

using InputRegisters = std::array<std::uint16_t, kInputRegisterCount>;
using DiscreteInputs = std::array<bool, kDiscreteInputCount>;
using Coils = std::array<bool, kCoilCount>;
using HoldingRegisters = std::array<std::uint16_t, kHoldingRegisterCount>;

// All four tables: what a slave serves. Value-initialised it is all zeros, the
// map version included; encode_device_signals() fills the inputs and the version.
struct RegisterImage {
    InputRegisters input_registers{};
    DiscreteInputs discrete_inputs{};
    Coils coils{};
    HoldingRegisters holding_registers{};
};

// --- board inputs (slave encodes, master decodes) ---

// Throws std::invalid_argument naming the field when an ADC value exceeds the
// 12-bit full scale (io::kAdcFullScale): a 12-bit converter cannot produce it, so
// it is an emulator bug, not something to put on the wire.
InputRegisters encode_input_registers(const io::DeviceSignals& signals);
DiscreteInputs encode_discrete_inputs(const io::DeviceSignals& signals);
// Writes both input tables of `image`.
void encode_device_signals(const io::DeviceSignals& signals, RegisterImage& image);
// The map version register is not part of DeviceSignals; masters check it with
// map_version_of() before trusting the rest.
io::DeviceSignals decode_device_signals(const InputRegisters& input_registers, const DiscreteInputs& discrete_inputs);
inline std::uint16_t map_version_of(const InputRegisters& input_registers) {
    return input_registers[kInputMapVersion];
}

// --- board outputs (master encodes, slave decodes) ---

Coils encode_coils(const io::ActuatorCommands& commands);          // reserved coils 0
io::ActuatorCommands decode_coils(const Coils& coils);              // reserved coils ignored
HoldingRegisters encode_holding_registers(const io::ControllerIndicators& indicators);
io::ControllerIndicators decode_holding_registers(const HoldingRegisters& registers);  // reserved bits ignored

// Write checks the slave applies before storing (so reserved bits never get in).
// Empty string = acceptable; otherwise why not, e.g.
//   "coil 5 is reserved and must be written as 0".
// `address` must be inside the table (the caller checked ILLEGAL DATA ADDRESS).
std::string coil_write_problem(std::uint16_t address, bool value);
std::string holding_register_write_problem(std::uint16_t address, std::uint16_t value);

// Human names, for logs and error messages ("coil 8 (section_valve_1)").
std::string input_register_name(std::uint16_t address);
std::string coil_name(std::uint16_t address);
std::string holding_register_name(std::uint16_t address);

}  // namespace rig::modbus
