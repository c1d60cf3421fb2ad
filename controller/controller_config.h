#pragma once
// The reference controller's parameters: the case file's `controller:` section,
// handed to the controller as a YAML file by the harness. Defaults are the
// paper's (seed 000).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "controller/flow_pid.h"
#include "controller/valve_calibration.h"
#include "controller/valve_driver.h"

namespace rig {
class YamlSection;
}

namespace rig::controller {

enum class Positioning { rtk_only, fusion };
// What Eq. 2's output M is (the paper does not say): a flow correction in L/min,
// through the calibration to an opening (the loop gain does not depend on where
// on the valve curve it works), or a change of the opening in % from the
// pre-adjusted one (the loop gain follows the curve's steepness, 1-4 L/min per %).
enum class PidOutput { flow_l_min, opening_pct };

struct ControllerConfig {
    Positioning positioning = Positioning::fusion;
    double threshold_m = 5.0;              // odometer takes over inside this (sec. 3.2.1)
    // Boom geometry the controller believes (Eq. 6); the plant has its own truth.
    double l1_m = 0.50;
    double l2_m = 0.80;
    double l3_m = 0.45;
    double linkage_rise_m = 0.50;
    // Land-wheel odometer (Eq. 5).
    double wheel_diameter_m = 1.0;
    std::uint32_t pulses_per_rev = 1000;
    double speed_window_s = 0.2;           // t1 of Eq. 5
    double gnss_latency_compensation_s = 0.0;
    // GGA quality is a code, not a scale (4 RTK fixed, 5 RTK float, 2 DGPS, 1 GPS):
    // either any fix with a position is used, or RTK fixed only.
    bool rtk_fixed_only = false;
    double approach_window_m = 60.0;       // a stored breakpoint is armed when this close ahead...
    double arm_distance_m = 1.0;           // ...and the nozzle line is at least this far behind it
    double status_rate_hz = 10.0;
    std::string breakpoint_store_file = "breakpoints.txt";  // relative to the state dir

    // ---- Flow control and breakpoint continuation (sec. 2.2.1-2.2.3)
    double target_flow_l_min = 20.0;        // sec. 2.5.2
    int section_count = 3;                  // all sections open and close together
    // Zero-speed shutoff: sections close below this speed (0 = spray standing, a static test).
    double min_spray_speed_km_h = 1.0;
    // Eq. 7: open the nozzles v (t2 + t3) before the breakpoint; off = open at it.
    bool hysteresis_compensation = true;
    double assumed_flow_adjust_s = 1.359;   // t2: Table 2 mean adjust time
    double assumed_spray_delay_s = 0.267;   // t3: Table 1, signal -> droplets landing
    PidGains pid{};                         // Eq. 2, sec. 3.1.2
    PidOutput pid_output = PidOutput::flow_l_min;
    double pid_period_s = 0.1;
    double pid_integral_limit_l_min = 5.0;
    // The PID starts once the measured flow has settled after the sections opened:
    // two successive measurements within this fraction of the target.
    double flow_established_change_pct = 2.0;
    // The continuation is done ("target flow reached", Fig. 2) after the measured
    // flow stayed within this band for this long; the breakpoint is then cleared.
    double on_target_band_pct = 3.0;
    double on_target_hold_s = 0.5;
    // Eq. 3 on the KF11 (90 pulses/L), measured over a sliding window (controller/flow_rate_meter.h).
    double flow_meter_pulses_per_l = 90.0;
    double flow_window_s = 0.25;
    // Eq. 8: pump-outlet sensor range Q_F and the converter's voltage span u.
    double pump_sensor_full_scale_m3_h = 8.0;  // WL-LWGA-20: 0.8-8 m^3/h
    double pump_sensor_span_v = 3.3;
    double pump_flow_smoothing_s = 0.5;     // the plunger pump pulsates; average before use
    // Pull-wire boom-height sensor: h at full span (Eq. 6 uses h).
    double boom_height_range_m = 1.0;
    double boom_height_span_v = 3.3;
    ValveDriverParams valve{};
    std::vector<CalibratedOpening> calibration = default_calibration();
};

// Reads and validates the section; throws rig::ConfigError (file:line:col: key: ...).
// The key `command` is the harness's (which executable to start) and is ignored.
ControllerConfig parse_controller_config(const YamlSection& section);
ControllerConfig load_controller_config(const std::filesystem::path& file);

}  // namespace rig::controller
