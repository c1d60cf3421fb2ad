#pragma once
// The controller board's electrical interface as data: what the rig drives into
// the board (device signals) and what the board drives out (actuator commands,
// status outputs). It is the same whichever wire carries it (DDS topics, Modbus
// registers, a USB-HID I/O board), so the wire adapters in rig/ (Modbus slave,
// HID board) and the controller's hardware interface share one vocabulary
// (ros2_control-style: real or mock hardware behind one interface).
//
// Values are wire-level, not engineering units (docs/design.md "Data flow"): pulse
// counts, ADC counts, relay and valve states. The controller converts them
// (seed 000 Eq. 3, 5, 8) as firmware must.
#include <cstdint>

namespace rig::io {

// Board inputs: the rig's emulators drive these.
struct DeviceSignals {
    std::uint32_t wheel_encoder_count = 0;   // land-wheel encoder, cumulative pulses (wraps at 2^32)
    std::uint32_t main_flow_pulses = 0;      // KF11-P10 main-pipeline meter, cumulative pulses (90 /L)
    // The frequency input's capture timer (1 MHz, wraps) at the meter's last pulse
    // edge: Eq. 3's t2 measured edge to edge (controller/flow_rate_meter.h).
    std::uint32_t main_flow_last_edge_us = 0;
    // The counter input's capture timer (the same 1 MHz timer) at the encoder's
    // last counted edge: where the wheel was between reads (controller/breakpoint_locator.h).
    std::uint32_t wheel_encoder_last_edge_us = 0;
    std::uint16_t pump_flow_adc = 0;         // pump-outlet sensor, 4-20 mA -> 0-3.3 V -> 12-bit ADC (Eq. 8)
    std::uint16_t boom_height_adc = 0;       // pull-wire boom-height sensor -> 12-bit ADC
    bool breakpoint_button = false;          // breakpoint button on the board, pressed = true
    bool spray_switch = false;               // operator's main spray switch, on = true
    bool operator==(const DeviceSignals&) const = default;
};

// Board outputs: the controller drives these; the rig senses them.
struct ActuatorCommands {
    bool ball_valve_forward = false;         // relay 1: proportional valve motor towards open
    bool ball_valve_reverse = false;         // relay 2: towards closed (both on = fault, motor braked)
    bool unloading_valve_open = false;       // pump flow back to the tank
    std::uint8_t section_valves_open = 0;    // bit i = section i switch valve open (up to 8 sections)
    bool operator==(const ActuatorCommands&) const = default;
};

// Board status outputs the rig records so it can judge a wired controller the
// same way as one on DDS (no truth flows back: these are the controller's claims).
struct ControllerIndicators {
    std::uint16_t breakpoints_stored = 0;    // counts up each time a breakpoint is stored
    std::uint16_t breakpoints_reached = 0;   // counts up each time the nozzle line is declared at one
    bool breakpoint_pending = false;         // a stored breakpoint lies ahead
    bool odometer_active = false;            // fusion: inside the threshold, odometer integrating
    bool operator==(const ControllerIndicators&) const = default;
};

// The frequency input's capture timer (main_flow_last_edge_us): 1 MHz, 32 bits,
// counting from the case clock's t = 0 and wrapping every 2^32 us (71.6 min).
inline constexpr std::uint32_t kCaptureTimerHz = 1'000'000;

// 12-bit ADC full scale of the STM32F407's converters, and its reference voltage.
inline constexpr std::uint16_t kAdcFullScale = 4095;
inline constexpr double kAdcReferenceV = 3.3;

inline std::uint16_t adc_counts_from_voltage(double voltage_v) {
    const double counts = voltage_v / kAdcReferenceV * kAdcFullScale + 0.5;
    if (!(counts > 0.0)) return 0;
    return counts >= kAdcFullScale ? kAdcFullScale : static_cast<std::uint16_t>(counts);
}
inline double voltage_from_adc_counts(std::uint16_t counts) {
    return static_cast<double>(counts) / kAdcFullScale * kAdcReferenceV;
}

}  // namespace rig::io
