#pragma once
// Every topic name, declared once. Device topics carry wire-level data,
// actuator topics controller commands, truth topics plant state (never read
// by the controller). Types live in the .idl files beside this header.
namespace rig::topics {

// Time (rig/lockstep.h)
inline constexpr const char* kClockTick = "rig/clock/tick";          // msg::ClockTick
inline constexpr const char* kClockAck = "rig/clock/ack";            // msg::ClockAck

// Bench self-test (rig/dds_check.h)
inline constexpr const char* kDdsCheckPing = "rig/dds_check/ping";  // msg::NmeaSentence
inline constexpr const char* kDdsCheckPong = "rig/dds_check/pong";  // msg::NmeaSentence

// Device topics (emulators -> controller)
inline constexpr const char* kGnssNmea = "device/gnss/nmea";         // msg::NmeaSentence
inline constexpr const char* kWheelEncoder = "device/wheel_encoder/count";  // msg::EncoderCount
inline constexpr const char* kBreakpointButton = "device/breakpoint_button/level";  // msg::ButtonLevel

// Controller outputs
inline constexpr const char* kControllerStatus = "controller/status";          // msg::ControllerStatus
inline constexpr const char* kBreakpointEvent = "controller/breakpoint_event"; // msg::BreakpointEvent

// Truth (plant -> harness, emulators)
inline constexpr const char* kVehicleTruth = "truth/vehicle";        // msg::VehicleTruth

}  // namespace rig::topics
