#pragma once
// Every topic name, declared once. Device topics carry wire-level data,
// actuator topics controller commands, truth topics plant state (never read
// by the controller). Types live in the .idl files beside this header.
namespace rig::topics {

// Time (rig/runtime/lockstep.h)
inline constexpr const char* kClockTick = "rig/clock/tick";          // msg::ClockTick
inline constexpr const char* kClockAck = "rig/clock/ack";            // msg::ClockAck

// Bench self-test (rig/host/dds_check.h)
inline constexpr const char* kDdsCheckPing = "rig/dds_check/ping";  // msg::NmeaSentence
inline constexpr const char* kDdsCheckPong = "rig/dds_check/pong";  // msg::NmeaSentence
// The DDS floor of a lockstep round (rig/host/dds_pingpong.h, `rig bench`): the
// clock's own types and QoS on topics of their own.
inline constexpr const char* kBenchPing = "rig/bench/ping";  // msg::ClockTick
inline constexpr const char* kBenchPong = "rig/bench/pong";  // msg::ClockAck

// Device topics (emulators -> controller)
inline constexpr const char* kGnssNmea = "device/gnss/nmea";                        // msg::NmeaSentence
inline constexpr const char* kWheelEncoder = "device/wheel_encoder/count";          // msg::EncoderCount
inline constexpr const char* kMainFlowMeter = "device/main_flow_meter/count";       // msg::FlowMeterCount
inline constexpr const char* kPumpFlowSensor = "device/pump_flow_sensor/voltage";   // msg::AnalogInput
inline constexpr const char* kBoomHeightSensor = "device/boom_height_sensor/voltage";  // msg::AnalogInput
inline constexpr const char* kBreakpointButton = "device/breakpoint_button/level";   // msg::SwitchLevel
inline constexpr const char* kSpraySwitch = "device/spray_switch/level";             // msg::SwitchLevel
// Seed 001: the L4 laser boom-height sensor's serial lines (the AD300's RMC uses kGnssNmea).
inline constexpr const char* kLaserHeightSerial = "device/laser_height/serial";     // msg::SerialLine
// Seed 001: the two boom cameras' frames (Sec. 1.1; left sees nozzles 0-2, right 3-5).
inline constexpr const char* kCameraLeftFrame = "device/camera_left/frame";         // msg::CameraFrame
inline constexpr const char* kCameraRightFrame = "device/camera_right/frame";       // msg::CameraFrame

// Actuator topics (controller -> plant)
inline constexpr const char* kBallValveRelays = "actuator/ball_valve/relays";      // msg::BallValveRelays
inline constexpr const char* kSectionValves = "actuator/section_valves/open";      // msg::SectionValves
inline constexpr const char* kUnloadingValve = "actuator/unloading_valve/open";    // msg::UnloadingValve
// Seed 001: PWM duty per nozzle.
inline constexpr const char* kNozzlePwm = "actuator/nozzle_pwm/duty";              // msg::NozzlePwm

// Controller outputs
inline constexpr const char* kControllerStatus = "controller/status";          // msg::ControllerStatus
inline constexpr const char* kBreakpointEvent = "controller/breakpoint_event"; // msg::BreakpointEvent
// Seed 001: the density and level the controller's vision found in each frame.
inline constexpr const char* kVisionReport = "controller/vision/density";      // msg::VisionReport

// Truth (plant -> harness, emulators)
inline constexpr const char* kVehicleTruth = "truth/vehicle";        // msg::VehicleTruth
inline constexpr const char* kHydraulicsTruth = "truth/hydraulics";  // msg::HydraulicsTruth
// Seed 001's 2-D plant.
inline constexpr const char* kVehicle2dTruth = "truth/vehicle2d";    // msg::Vehicle2dTruth
inline constexpr const char* kNozzlesTruth = "truth/nozzles";        // msg::NozzlesTruth
// Seed 001's crop truth under each camera frame's ROIs.
inline constexpr const char* kCameraViewTruth = "truth/camera_view";  // msg::CameraViewTruth

}  // namespace rig::topics
