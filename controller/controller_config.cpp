#include "controller/controller_config.h"

#include <array>
#include <cstdlib>

#include "controller/breakpoint_store.h"
#include "rig/config/yaml_fields.h"

namespace rig::controller {

namespace {

// Every number has a range with its physical reason (as in harness/spec/case_spec.cpp):
// a finite value far outside physics would otherwise pass and overflow a timer
// or a count at run time. Rates and periods are timers of simulated int64 ns,
// so each has a positive lower bound.

// A valve calibration has one line per calibrated opening: one per percent at most.
constexpr std::size_t kMaxCalibrationLines = 101;

void read_flow_control(const YamlSection& section, ControllerConfig& config) {
    // Boom-sprayer pumps deliver at most ~200 L/min.
    config.target_flow_l_min =
        section.optional_in_range("target_flow_l_min", config.target_flow_l_min, Bounds::open_closed(0.0, 250.0));
    // Booms have 1-13 sections; 16 is the most an ISOBUS section controller drives.
    config.section_count = section.optional_in_range("section_count", config.section_count, Bounds::closed(1, 16));
    // Below the slowest working speed (3 km/h in the paper); 20 km/h would never spray.
    config.min_spray_speed_km_h =
        section.optional_in_range("min_spray_speed_km_h", config.min_spray_speed_km_h, Bounds::closed(0.0, 20.0));
    config.hysteresis_compensation = section.optional<bool>("hysteresis_compensation", config.hysteresis_compensation);
    // Eq. 7 times: the paper's are 1.4 s and 0.27 s; 30 s and 5 s are broken hardware.
    config.assumed_flow_adjust_s =
        section.optional_in_range("assumed_flow_adjust_s", config.assumed_flow_adjust_s, Bounds::closed(0.0, 30.0));
    config.assumed_spray_delay_s =
        section.optional_in_range("assumed_spray_delay_s", config.assumed_spray_delay_s, Bounds::closed(0.0, 5.0));

    const YamlSection pid = section.section("pid");
    // Gains in L/min (or %) per L/min of error: the paper's are below 1; 100 is a relay.
    config.pid.kp = pid.optional_in_range("kp", config.pid.kp, Bounds::closed(0.0, 100.0));
    config.pid.ki = pid.optional_in_range("ki", config.pid.ki, Bounds::closed(0.0, 100.0));
    config.pid.kd = pid.optional_in_range("kd", config.pid.kd, Bounds::closed(0.0, 100.0));
    // The PID's period is a timer: 10 ms (faster than the flow meter's window) to 5 s.
    config.pid_period_s = pid.optional_in_range("period_s", config.pid_period_s, Bounds::closed(0.01, 5.0));
    static constexpr std::array<EnumChoice<PidOutput>, 3> kPidOutputs{{{"flow_l_min", PidOutput::flow_l_min},
                                                                      {"opening_pct", PidOutput::opening_pct},
                                                                      {"opening_step_pct", PidOutput::opening_step_pct}}};
    config.pid_output = pid.optional_enum<PidOutput>("output", kPidOutputs, config.pid_output);
    // At most the largest pump's flow (L/min).
    config.pid_integral_limit_l_min =
        pid.optional_in_range("integral_limit_l_min", config.pid_integral_limit_l_min, Bounds::open_closed(0.0, 250.0));
    config.flow_established_change_pct = pid.optional_in_range(
        "established_change_pct", config.flow_established_change_pct, Bounds::open_closed(0.0, 100.0));
    pid.finish();

    // Table 5's band is 3 %; 50 % is no band. Held for up to 30 s.
    config.on_target_band_pct =
        section.optional_in_range("on_target_band_pct", config.on_target_band_pct, Bounds::open_closed(0.0, 50.0));
    config.on_target_hold_s =
        section.optional_in_range("on_target_hold_s", config.on_target_hold_s, Bounds::closed(0.0, 30.0));

    const YamlSection meter = section.section("flow_meter");
    // Turbine meters: 1-10000 pulses per litre (the KF11 90), as the case's flow_meter.
    config.flow_meter_pulses_per_l =
        meter.optional_in_range("pulses_per_l", config.flow_meter_pulses_per_l, Bounds::closed(1.0, 10000.0));
    config.flow_window_s = meter.optional_in_range("window_s", config.flow_window_s, Bounds::closed(0.05, 10.0));
    meter.finish();

    const YamlSection pump = section.section("pump_sensor");
    // Turbine flow sensors span 0.1-1000 m^3/h; converters 0.1-10 V (3.3 V on the STM32's ADC).
    config.pump_sensor_full_scale_m3_h = pump.optional_in_range("full_scale_m3_h", config.pump_sensor_full_scale_m3_h,
                                                                Bounds::closed(0.1, 1000.0));
    config.pump_sensor_span_v = pump.optional_in_range("span_v", config.pump_sensor_span_v, Bounds::closed(0.1, 10.0));
    config.pump_flow_smoothing_s =
        pump.optional_in_range("smoothing_s", config.pump_flow_smoothing_s, Bounds::closed(0.0, 10.0));
    pump.finish();

    const YamlSection height = section.section("boom_height_sensor");
    // Pull-wire sensors reach 0.1-10 m, on a 0.1-10 V span.
    config.boom_height_range_m =
        height.optional_in_range("range_m", config.boom_height_range_m, Bounds::closed(0.1, 10.0));
    config.boom_height_span_v = height.optional_in_range("span_v", config.boom_height_span_v, Bounds::closed(0.1, 10.0));
    height.finish();

    const YamlSection valve = section.section("valve");
    // Motorised ball valves turn in 2-30 s (the paper's 11 s); 0.1 s is a solenoid. The
    // reset drives (open, then back) last at most two minutes; deadband up to 10 %.
    config.valve.travel_s = valve.optional_in_range("travel_s", config.valve.travel_s, Bounds::closed(0.1, 120.0));
    config.valve.start_delay_s =
        valve.optional_in_range("start_delay_s", config.valve.start_delay_s, Bounds::closed(0.0, 1.0));
    config.valve.backlash_pct = valve.optional_in_range("backlash_pct", config.valve.backlash_pct, Bounds::closed(0.0, 20.0));
    config.valve.reset_open_s = valve.optional_in_range("reset_open_s", config.valve.reset_open_s, Bounds::closed(0.0, 120.0));
    config.valve.reset_back_s = valve.optional_in_range("reset_back_s", config.valve.reset_back_s, Bounds::closed(0.0, 120.0));
    config.valve.deadband_pct = valve.optional_in_range("deadband_pct", config.valve.deadband_pct, Bounds::closed(0.0, 10.0));
    const std::vector<YamlSection> lines = valve.list("calibration");
    if (lines.size() > kMaxCalibrationLines) {
        valve.fail("calibration", "at most " + std::to_string(kMaxCalibrationLines) + " lines (one per % of opening)");
    }
    if (!lines.empty()) {
        config.calibration.clear();
        for (const YamlSection& line : lines) {
            // Flow = slope x opening + intercept: slopes of the paper's table are 0.1-4 L/min per %.
            config.calibration.push_back(CalibratedOpening{
                line.required_in_range<double>("opening_pct", Bounds::closed(0.0, 100.0)),
                line.required_in_range<double>("slope", Bounds::closed(-10.0, 10.0)),
                line.required_in_range<double>("intercept_l_min", Bounds::closed(-250.0, 250.0))});
        }
    }
    valve.finish();
    try {
        ValveCalibration{config.calibration};
    } catch (const std::invalid_argument& error) {
        valve.fail("calibration", error.what());
    }
}

// TEST-ONLY faults (ControllerFaults).
ControllerFaults read_faults(const YamlSection& section) {
    ControllerFaults faults;
    faults.never_resume = section.optional<bool>("never_resume", faults.never_resume);
    faults.never_spray = section.optional<bool>("never_spray", faults.never_spray);
    faults.section_chatter_period_s = section.optional_in_range(
        "section_chatter_period_s", faults.section_chatter_period_s, Bounds::closed(0.0, 60.0));
    faults.section_chatter_closed_s = section.optional_in_range(
        "section_chatter_closed_s", faults.section_chatter_closed_s, Bounds::open_closed(0.0, 10.0));
    if (faults.section_chatter_period_s > 0.0 && !(faults.section_chatter_closed_s < faults.section_chatter_period_s)) {
        section.fail("section_chatter_closed_s", "must be shorter than section_chatter_period_s");
    }
    faults.lead_scale = section.optional_in_range("lead_scale", faults.lead_scale, Bounds::closed(0.0, 20.0));
    faults.lead_bump_s = section.optional_in_range("lead_bump_s", faults.lead_bump_s, Bounds::closed(0.0, 10.0));
    faults.lead_bump_at_km_h =
        section.optional_in_range("lead_bump_at_km_h", faults.lead_bump_at_km_h, Bounds::closed(0.0, 30.0));
    faults.lead_bump_half_width_km_h = section.optional_in_range(
        "lead_bump_half_width_km_h", faults.lead_bump_half_width_km_h, Bounds::open_closed(0.0, 30.0));
    faults.valve_held = section.optional<bool>("valve_held", faults.valve_held);
    faults.stale_fix_reanchor = section.optional<bool>("stale_fix_reanchor", faults.stale_fix_reanchor);
    faults.boom_height_read_once = section.optional<bool>("boom_height_read_once", faults.boom_height_read_once);
    faults.crash_at_s = section.optional_in_range("crash_at_s", faults.crash_at_s, Bounds::closed(0.0, 86400.0));
    faults.stall_at_s = section.optional_in_range("stall_at_s", faults.stall_at_s, Bounds::closed(0.0, 86400.0));
    static constexpr std::array<std::string_view, 2> kForgeable = {"truth/vehicle", "truth/hydraulics"};
    faults.read_topic = section.optional_enum("read_topic", kForgeable, faults.read_topic);
    faults.write_topic = section.optional_enum("write_topic", kForgeable, faults.write_topic);
    section.finish();
    return faults;
}

}  // namespace

bool ControllerFaults::any() const {
    return never_resume || never_spray || section_chatter_period_s > 0.0 || lead_scale != 1.0 || lead_bump_s > 0.0 ||
           valve_held ||
           stale_fix_reanchor || boom_height_read_once || crash_at_s >= 0.0 || stall_at_s >= 0.0 || !read_topic.empty() || !write_topic.empty();
}

namespace {

CalibrationRunConfig read_calibration_run(const YamlSection& section) {
    CalibrationRunConfig run;
    run.enabled = true;
    if (section.has("openings_pct")) {
        const std::vector<std::string> openings = section.string_list("openings_pct");
        // One per % of opening at most, like a calibration's lines.
        if (openings.empty() || openings.size() > kMaxCalibrationLines) {
            section.fail("openings_pct", "must list 1 to " + std::to_string(kMaxCalibrationLines) + " openings");
        }
        run.openings_pct.clear();
        for (std::size_t i = 0; i < openings.size(); ++i) {
            char* end = nullptr;
            const double opening = std::strtod(openings[i].c_str(), &end);
            if (openings[i].empty() || end != openings[i].c_str() + openings[i].size() || !(opening >= 0.0) ||
                !(opening <= 100.0)) {
                const std::string shown = openings[i].size() > 20 ? openings[i].substr(0, 20) + "..." : openings[i];
                throw ConfigError(section.item_location("openings_pct", i),
                                  "an opening must be a number in [0, 100] %, got '" + shown + "'");
            }
            run.openings_pct.push_back(opening);
        }
    }
    // The pipeline settles in tenths of a second and the meter's window is 0.25 s;
    // a minute per point would take an hour per calibration.
    run.settle_s = section.optional_in_range("settle_s", run.settle_s, Bounds::closed(0.1, 60.0));
    run.measure_s = section.optional_in_range("measure_s", run.measure_s, Bounds::closed(0.1, 60.0));
    run.steady_pump_pct = section.optional_in_range("steady_pump_pct", run.steady_pump_pct, Bounds::open_closed(0.0, 50.0));
    // A straight line needs two points; R^2 means something from three.
    run.min_points = section.optional_in_range("min_points", run.min_points, Bounds::closed(2, 1000));
    run.min_span_l_min = section.optional_in_range("min_span_l_min", run.min_span_l_min, Bounds::closed(0.0, 200.0));
    section.finish();
    return run;
}

}  // namespace

ControllerConfig parse_controller_config(const YamlSection& section) {
    ControllerConfig config;
    // The rig's own keys of the section (harness/spec/case_spec.h kControllerRigKeys):
    // how to run the controller, not how it behaves.
    for (const char* rig_key : {"command", "plugin", "in_process"}) section.allow(rig_key);
    static constexpr std::array<EnumChoice<Positioning>, 2> kPositioning{
        {{"fusion", Positioning::fusion}, {"rtk_only", Positioning::rtk_only}}};
    config.positioning = section.optional_enum<Positioning>("positioning", kPositioning, config.positioning);
    // Fig. 13 sweeps 5-50 m; an odometer stretch of 500 m is a whole row.
    config.threshold_m = section.optional_in_range("threshold_m", config.threshold_m, Bounds::open(0.0, 500.0));
    const YamlSection boom = section.section("boom");
    // Antenna to nozzle line (Eq. 6): metres; L2 divides h, so it cannot be 0.
    config.l1_m = boom.optional_in_range("l1_m", config.l1_m, Bounds::closed(0.0, 20.0));
    config.l2_m = boom.optional_in_range("l2_m", config.l2_m, Bounds::open_closed(0.0, 20.0));
    config.l3_m = boom.optional_in_range("l3_m", config.l3_m, Bounds::closed(0.0, 20.0));
    config.linkage_rise_m = boom.optional_in_range("linkage_rise_m", config.linkage_rise_m, Bounds::closed(-5.0, 5.0));
    boom.finish();
    const YamlSection odometer = section.section("odometer");
    // Land wheels 0.1-5 m; shaft encoders up to 1e6 p/r; Eq. 5's window 10 ms (one
    // encoder sample) to 10 s.
    config.wheel_diameter_m =
        odometer.optional_in_range("wheel_diameter_m", config.wheel_diameter_m, Bounds::closed(0.1, 5.0));
    config.pulses_per_rev =
        odometer.optional_in_range<std::uint32_t>("pulses_per_rev", config.pulses_per_rev, Bounds::closed(1, 1e6));
    config.speed_window_s =
        odometer.optional_in_range("speed_window_s", config.speed_window_s, Bounds::closed(0.01, 10.0));
    odometer.finish();
    // Receiver latency is tens of ms; a second is a stale fix.
    config.gnss_latency_compensation_s = section.optional_in_range(
        "gnss_latency_compensation_s", config.gnss_latency_compensation_s, Bounds::closed_open(0.0, 1.0));
    config.rtk_fixed_only = section.optional<bool>("rtk_fixed_only", config.rtk_fixed_only);
    // Distances along the row: at most 10 km, like the case's positions.
    config.approach_window_m =
        section.optional_in_range("approach_window_m", config.approach_window_m, Bounds::open(0.0, 10'000.0));
    config.arm_distance_m =
        section.optional_in_range("arm_distance_m", config.arm_distance_m, Bounds::closed(0.0, 1'000.0));
    if (config.arm_distance_m >= config.approach_window_m) {
        section.fail("arm_distance_m", "must be less than approach_window_m");
    }
    // A timer: 1 Hz to 1 kHz.
    config.status_rate_hz =
        section.optional_in_range("status_rate_hz", config.status_rate_hz, Bounds::closed(1.0, 1000.0));
    // The store is the one file the controller writes: a plain name inside its
    // --state-dir (no '/', no '..'), so a case cannot point it at another file.
    config.diagnostics_topic = section.optional<std::string>("diagnostics_topic", config.diagnostics_topic);
    if (!config.diagnostics_topic.empty()) {
        // Its own namespace: never a topic of the contract (docs/controller-contract.md).
        for (const char* reserved : {"rig/", "device/", "actuator/", "controller/", "truth/"}) {
            if (config.diagnostics_topic.rfind(reserved, 0) == 0) {
                section.fail("diagnostics_topic", "must not start with '" + std::string(reserved) +
                                                      "' (the contract's topics); e.g. reference/phases");
            }
        }
        if (config.diagnostics_topic.size() > 64) section.fail("diagnostics_topic", "is longer than 64 characters");
    }
    config.breakpoint_store_file = section.optional<std::string>("breakpoint_store_file", config.breakpoint_store_file);
    if (const std::string problem = breakpoint_store_name_problem(config.breakpoint_store_file); !problem.empty()) {
        section.fail("breakpoint_store_file", problem);
    }
    read_flow_control(section, config);
    if (section.has("calibration_run")) config.calibration_run = read_calibration_run(section.section("calibration_run"));
    config.faults = read_faults(section.section("faults"));
    section.finish();
    return config;
}

ControllerConfig load_controller_config(const std::filesystem::path& file) {
    return parse_controller_config(YamlSection::load_file(file));
}

}  // namespace rig::controller
