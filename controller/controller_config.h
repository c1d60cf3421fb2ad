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
#include "controller/valve_calibration_procedure.h"
#include "controller/valve_driver.h"
#include "rig/papers/seed000.h"

namespace rig {
class YamlSection;
}

namespace rig::controller {

enum class Positioning { rtk_only, fusion };
// What Eq. 2's output M is (the paper does not say): a flow correction in L/min,
// through the calibration to an opening (the loop gain does not depend on where
// on the valve curve it works), or a change of the opening in % from the
// pre-adjusted one (the loop gain follows the curve's steepness, 1-4 L/min per %),
// or a step of the opening in % each period from where the valve was last sent:
// the firmware drives the motor for as long as M says ("the opening degree ...
// controlled by adjusting the duration of power supply", sec. 2.1), so the
// motor integrates M and Kp acts as an integral gain, Ki as a double one.
enum class PidOutput { flow_l_min, opening_pct, opening_step_pct };

// TEST-ONLY. Bugs a real firmware has, put into the reference controller on
// purpose so that the rig must catch each one: the catalogue of faulty
// controllers (cases/faulty-controllers/, docs/faulty-controllers.md). A normal
// case never sets any of them; the harness judges a faulty run exactly as it
// judges any controller. Case files write them under `controller: { faults: ... }`.
struct ControllerFaults {
    bool never_resume = false;              // after a stored breakpoint, never opens the sections again
    bool never_spray = false;               // never opens the sections at all
    // > 0: while the sections should be open, the output stage drops them for
    // section_chatter_closed_s every period (a bouncing relay driver).
    double section_chatter_period_s = 0.0;
    double section_chatter_closed_s = 0.05;
    double lead_scale = 1.0;                // multiplies Eq. 7's lead v (t2 + t3): 2 opens twice as early
    // > 0: a lead table with one bad entry. Eq. 7's lead gets lead_bump_s more
    // seconds of travel at lead_bump_at_km_h, tapering linearly to none
    // lead_bump_half_width_km_h either side (the interpolation between the
    // table's entries): a fault that bites in a narrow band of speed only
    // (the known answer rig falsify's tests look for, docs/falsify.md).
    double lead_bump_s = 0.0;
    double lead_bump_at_km_h = 6.0;
    double lead_bump_half_width_km_h = 0.3;
    bool valve_held = false;                // the ball valve is never driven after the power-on reset (no pre-adjustment, no PID)
    // Keeps acting on a stale fix through a dropout: while GGA is missing it
    // re-feeds the last fix as a new one every receiver epoch, and every fix
    // (fresh or stale) re-anchors the odometer (fusion's s_b, Eq. 7).
    bool stale_fix_reanchor = false;
    // Reads the pull-wire boom-height sensor once, at power-on, and keeps that h
    // (and so Eq. 6's L4) for the whole run, whatever the push rod does after.
    bool boom_height_read_once = false;
    double crash_at_s = -1.0;               // >= 0: the process aborts (SIGABRT) at this simulated time
    double stall_at_s = -1.0;               // >= 0: stops answering the clock at this simulated time
    std::string read_topic;                 // reads this topic too, without saying so in its hello (truth/vehicle)
    std::string write_topic;                // writes forged samples on this topic (truth/vehicle, truth/hydraulics)
    bool any() const;
};

struct ControllerConfig {
    Positioning positioning = Positioning::fusion;
    double threshold_m = 5.0;              // odometer takes over inside this (sec. 3.2.1)
    // Boom geometry the controller believes (Eq. 6); the plant has its own truth.
    double l1_m = papers::seed000::kL1M;
    double l2_m = papers::seed000::kL2M;
    double l3_m = papers::seed000::kL3M;
    double linkage_rise_m = papers::seed000::kLinkageRiseM;
    // Land-wheel odometer (Eq. 5).
    double wheel_diameter_m = papers::seed000::kLandWheelDiameterM;
    std::uint32_t pulses_per_rev = papers::seed000::kEncoderPulsesPerRev;
    double speed_window_s = 0.2;           // t1 of Eq. 5
    double gnss_latency_compensation_s = 0.0;
    // GGA quality is a code, not a scale (4 RTK fixed, 5 RTK float, 2 DGPS, 1 GPS):
    // either any fix with a position is used, or RTK fixed only.
    bool rtk_fixed_only = false;
    double approach_window_m = 60.0;       // a stored breakpoint is armed when this close ahead...
    double arm_distance_m = 1.0;           // ...and the nozzle line is at least this far behind it
    double status_rate_hz = 10.0;
    std::string breakpoint_store_file = "breakpoints.txt";  // relative to the state dir
    // A topic of its own on which it writes a line of text at every change of its
    // spray phase (for the person reading the trace; the rig records a
    // controller's own topics without knowing their type). Empty: none.
    std::string diagnostics_topic;

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
    // three successive measurements within this fraction of the target. At 2 % (and
    // two measurements) it
    // started while the line was still filling and its integral pushed the flow
    // over the +-3 % band in 2 of 20 seeds of the 6 km/h continuation (and 1 run in
    // 7 of the wired case); at 1 %, 0 of 20 (`rig run` of continuation-6kmh over
    // seeds 1-20, flow_adjust_time_s 1.08-1.10 s). The paper does not say when its
    // PID starts.
    double flow_established_change_pct = 1.0;
    // The continuation is done ("target flow reached", Fig. 2) after the measured
    // flow stayed within this band for this long; the breakpoint is then cleared.
    double on_target_band_pct = 3.0;
    double on_target_hold_s = 0.5;
    // Eq. 3 on the KF11 (90 pulses/L), measured over a sliding window (controller/flow_rate_meter.h).
    double flow_meter_pulses_per_l = papers::seed000::kFlowMeterPulsesPerLitre;
    double flow_window_s = 0.25;
    // Eq. 8: pump-outlet sensor range Q_F and the converter's voltage span u.
    double pump_sensor_full_scale_m3_h = papers::seed000::kPumpSensorFullScaleM3H;
    double pump_sensor_span_v = 3.3;
    double pump_flow_smoothing_s = 0.5;     // the plunger pump pulsates; average before use
    // Pull-wire boom-height sensor: h at full span (Eq. 6 uses h).
    double boom_height_range_m = papers::seed000::kBoomHeightRangeM;
    double boom_height_span_v = 3.3;
    ValveDriverParams valve{};
    std::vector<CalibratedOpening> calibration = default_calibration();
    // `calibration_run:` present: while the spray switch is on, the controller
    // runs the valve calibration of sec. 2.4.2 instead of regulating (its phase
    // reads REGULATING, sections open), and when the switch goes off writes what
    // it measured to its state directory (controller/valve_calibration_procedure.h).
    // A run that ends with the switch on writes nothing.
    CalibrationRunConfig calibration_run{};
    ControllerFaults faults{};  // TEST-ONLY (see ControllerFaults)
};

// Reads and validates the section; throws rig::ConfigError (file:line:col: key: ...).
// The key `command` is the harness's (which executable to start) and is ignored.
ControllerConfig parse_controller_config(const YamlSection& section);
ControllerConfig load_controller_config(const std::filesystem::path& file);

}  // namespace rig::controller
