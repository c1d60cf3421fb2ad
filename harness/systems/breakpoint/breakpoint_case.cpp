#include "harness/systems/breakpoint/breakpoint_case.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <system_error>

#include "emulators/land_wheel.h"
#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

constexpr EnumChoice<Scenario> kScenarios[] = {
    {"breakpoint_identification", Scenario::breakpoint_identification},
    {"breakpoint_continuation", Scenario::breakpoint_continuation},
    {"static_flow", Scenario::static_flow},
    {"valve_calibration", Scenario::valve_calibration},
};
constexpr EnumChoice<GnssTalker> kTalkers[] = {
    {"GP", GnssTalker::gp},
    {"GN", GnssTalker::gn},
    {"BD", GnssTalker::bd},
    {"GB", GnssTalker::gb},
};
constexpr EnumChoice<GnssFix> kFixes[] = {
    {"rtk_fixed", GnssFix::rtk_fixed},
    {"rtk_float", GnssFix::rtk_float},
    {"dgps", GnssFix::dgps},
    {"autonomous", GnssFix::autonomous},
};

template <class E, std::size_t N>
std::string_view name_of(const EnumChoice<E> (&choices)[N], E value) {
    for (const EnumChoice<E>& choice : choices) {
        if (choice.value == value) return choice.name;
    }
    return "?";
}

// Fixed-width digits at text[pos, pos + count), or nullopt.
std::optional<int> digits_at(std::string_view text, std::size_t pos, std::size_t count) {
    if (pos + count > text.size()) return std::nullopt;
    int value = 0;
    const char* begin = text.data() + pos;
    const auto result = std::from_chars(begin, begin + count, value);
    if (result.ec != std::errc{} || result.ptr != begin + count || !std::isdigit(static_cast<unsigned char>(*begin))) {
        return std::nullopt;
    }
    return value;
}

// ISO-8601 UTC, `YYYY-MM-DDTHH:MM:SS[.fraction]Z`. The Z is required so that a
// case never depends on the time zone of the machine running it.
std::optional<std::chrono::sys_time<std::chrono::nanoseconds>> parse_utc(std::string_view text) {
    using namespace std::chrono;
    const auto year_value = digits_at(text, 0, 4);
    const auto month_value = digits_at(text, 5, 2);
    const auto day_value = digits_at(text, 8, 2);
    const auto hour_value = digits_at(text, 11, 2);
    const auto minute_value = digits_at(text, 14, 2);
    const auto second_value = digits_at(text, 17, 2);
    if (!year_value || !month_value || !day_value || !hour_value || !minute_value || !second_value) return std::nullopt;
    if (text[4] != '-' || text[7] != '-' || text[10] != 'T' || text[13] != ':' || text[16] != ':') return std::nullopt;
    if (text.back() != 'Z') return std::nullopt;
    const year_month_day date{year{*year_value}, month{static_cast<unsigned>(*month_value)},
                              day{static_cast<unsigned>(*day_value)}};
    // From the GPS epoch (1980) to 2099: RMC carries a two-digit year, and
    // nanoseconds since 1970 in 64 bits end in 2262.
    if (*year_value < 1980 || *year_value > 2099) return std::nullopt;
    if (!date.ok() || *hour_value > 23 || *minute_value > 59 || *second_value > 59) return std::nullopt;

    std::int64_t fraction_ns = 0;
    std::string_view rest = text.substr(19, text.size() - 20);  // between the seconds and the Z
    if (!rest.empty()) {
        if (rest.front() != '.' || rest.size() < 2 || rest.size() > 10) return std::nullopt;
        std::int64_t scale = 100'000'000;
        for (const char c : rest.substr(1)) {
            if (!std::isdigit(static_cast<unsigned char>(c))) return std::nullopt;
            fraction_ns += (c - '0') * scale;
            scale /= 10;
        }
    }
    return sys_days{date} + hours{*hour_value} + minutes{*minute_value} + seconds{*second_value} +
           nanoseconds{fraction_ns};
}

// A position along the A-B line (see kMaxAlongM).
const Bounds kAlongBounds = Bounds::closed(-kMaxAlongM, kMaxAlongM);
// A time of an event inside a case, or a duration (see kMaxEventS).
const Bounds kEventStartBounds = Bounds::closed(0, kMaxEventS);
const Bounds kEventLengthBounds = Bounds::open_closed(0, kMaxEventS);
// Dropout and degraded lists: a real log has a handful; this bounds the work.
constexpr std::size_t kMaxEpisodes = 1000;

FieldSpec read_field(const YamlSection& section) {
    FieldSpec field;
    const YamlSection origin = section.required_section("origin");
    // Transverse Mercator field frame: not near the poles.
    field.origin.lat_deg = origin.required_in_range<double>("lat_deg", Bounds::closed(-85, 85));
    field.origin.lon_deg = origin.required_in_range<double>("lon_deg", Bounds::closed(-180, 180));
    // Dead Sea shore (-430 m) to above the highest farmland (~5000 m), with margin.
    field.origin.height_m = origin.optional_in_range<double>("height_m", 0.0, Bounds::closed(-1000, 10000));
    field.heading_deg = section.required_in_range<double>("heading_deg", Bounds::closed_open(0, 360));
    return field;
}

// A static test has the vehicle standing: then its section is optional.
VehicleSpec read_vehicle(const YamlSection& section, bool standing) {
    VehicleSpec vehicle;
    if (standing) {
        vehicle.speed_km_h = section.optional_in_range<double>("speed_km_h", 0.0, Bounds::closed(0, 30));
        vehicle.start_m = section.optional_in_range<double>("start_m", 0.0, kAlongBounds);
        return vehicle;
    }
    // A boom sprayer works at 3-12 km/h; 30 is a road speed. Below 0.5 km/h
    // the route would take days (10 km at 0.5 km/h is 20 h).
    vehicle.speed_km_h = section.required_in_range<double>("speed_km_h", Bounds::closed(0.5, 30));
    // A loaded tractor pulls away at ~0.5 m/s^2; 0.05 takes 33 s to 6 km/h, 5 is a sports car.
    vehicle.accel_m_s2 =
        section.optional_in_range<double>("accel_m_s2", vehicle.accel_m_s2, Bounds::closed(0.05, 5));
    vehicle.start_m = section.required_in_range<double>("start_m", kAlongBounds);
    // Past the breakpoint and before it: a headland-to-headland row is at most ~1 km.
    vehicle.overrun_m = section.optional_in_range<double>("overrun_m", vehicle.overrun_m, Bounds::closed(0, 1000));
    vehicle.first_pass_m =
        section.optional_in_range<double>("first_pass_m", vehicle.first_pass_m, Bounds::open_closed(0, 1000));
    // Ten minutes is far more than the valve reset (~2 x 11 s) needs.
    vehicle.wait_before_first_pass_s = section.optional_in_range<double>(
        "wait_before_first_pass_s", vehicle.wait_before_first_pass_s, Bounds::closed(0, 600));
    return vehicle;
}

BoomSpec read_boom(const YamlSection& section) {
    BoomSpec boom;
    // Antenna to nozzle line on a tractor and its boom: metres, not tens of metres.
    // L2 divides h in Eq. 6 (atan(h/L2)), so it cannot be 0.
    boom.l1_m = section.optional_in_range<double>("l1_m", boom.l1_m, Bounds::closed(0, 20));
    boom.l2_m = section.optional_in_range<double>("l2_m", boom.l2_m, Bounds::open_closed(0, 20));
    boom.l3_m = section.optional_in_range<double>("l3_m", boom.l3_m, Bounds::closed(0, 20));
    // The three-point linkage lifts the boom by well under 2 m.
    const Bounds rise_bounds = Bounds::closed(0, 5);
    boom.linkage_rise_m = section.optional_in_range<double>("linkage_rise_m", boom.linkage_rise_m, rise_bounds);
    const std::vector<YamlSection> lifts = section.list("lifts");
    if (lifts.size() > kMaxEpisodes) section.fail("lifts", "at most " + std::to_string(kMaxEpisodes) + " items");
    double push_rod_free_s = 0.0;
    for (const YamlSection& item : lifts) {
        BoomLiftSpec lift;
        lift.at_s = item.required_in_range<double>("at_s", kEventStartBounds);
        lift.at_location = item.location("at_s");
        lift.to_m = item.required_in_range<double>("to_m", rise_bounds);
        lift.to_location = item.location("to_m");
        // Electric linear actuators move at a few mm/s to tens of mm/s under
        // load; a hydraulic lift cylinder reaches tenths of a metre per second.
        lift.rate_m_s = item.required_in_range<double>("rate_m_s", Bounds::closed(0.005, 1));
        if (lift.at_s < push_rod_free_s) {
            item.fail("at_s", "starts at " + shortest_text(lift.at_s) + " s, before the previous lift arrives (" +
                                  shortest_text(push_rod_free_s) + " s): one push rod moves one way at a time");
        }
        boom.lifts.push_back(lift);
        push_rod_free_s = lift.at_s + boom.lift_duration_s(boom.lifts.size() - 1);
    }
    return boom;
}

BreakpointSpec read_breakpoint(const YamlSection& section) {
    BreakpointSpec breakpoint;
    breakpoint.along_m = section.optional_in_range<double>("along_m", breakpoint.along_m, kAlongBounds);
    // The operator presses the button seconds after stopping; ten minutes is generous.
    breakpoint.button_at_s =
        section.optional_in_range<double>("button_at_s", breakpoint.button_at_s, Bounds::open_closed(0, 600));
    return breakpoint;
}

GnssSpec read_gnss(const YamlSection& section) {
    GnssSpec gnss;
    gnss.talker = section.optional_enum<GnssTalker>("talker", kTalkers, gnss.talker);
    // Receivers output 1-20 Hz (the G970II 5 Hz); the epoch period 1/rate is a timer.
    gnss.rate_hz = section.optional_in_range<double>("rate_hz", gnss.rate_hz, Bounds::closed(1, 20));
    gnss.latency_s = section.optional_in_range<double>("latency_s", gnss.latency_s, Bounds::closed_open(0, 1));
    if (section.has("epoch_phase_s")) {
        gnss.epoch_phase_s = section.required_in_range<double>("epoch_phase_s", Bounds::closed_open(0, 1.0 / gnss.rate_hz));
    }
    gnss.fix = section.optional_enum<GnssFix>("fix", kFixes, gnss.fix);

    const YamlSection noise = section.section("noise");
    // Autonomous GPS is off by metres, RTK by 1-2 cm + 1 ppm; 100 m is a broken receiver.
    gnss.noise.base_m = noise.optional_in_range<double>("base_m", gnss.noise.base_m, Bounds::closed(0, 100));
    gnss.noise.ppm = noise.optional_in_range<double>("ppm", gnss.noise.ppm, Bounds::closed(0, 100));
    // RTK corrections are usable to a few tens of km from the base.
    gnss.noise.baseline_km =
        noise.optional_in_range<double>("baseline_km", gnss.noise.baseline_km, Bounds::closed(0, 200));

    const std::vector<YamlSection> dropouts = section.list("dropouts");
    if (dropouts.size() > kMaxEpisodes) section.fail("dropouts", "at most " + std::to_string(kMaxEpisodes) + " items");
    for (const YamlSection& item : dropouts) {
        GnssDropout dropout;
        if (item.has("before_breakpoint_s")) {
            if (item.has("at_s")) item.fail("at_s", "give either at_s or before_breakpoint_s, not both");
            dropout.before_breakpoint_s = item.required_in_range<double>("before_breakpoint_s", kEventStartBounds);
            dropout.at_location = item.location("before_breakpoint_s");
        } else {
            dropout.at_s = item.required_in_range<double>("at_s", kEventStartBounds);
            dropout.at_location = item.location("at_s");
        }
        dropout.for_s = item.required_in_range<double>("for_s", kEventLengthBounds);
        dropout.for_location = item.location("for_s");
        gnss.dropouts.push_back(dropout);
    }
    const std::vector<YamlSection> episodes = section.list("degraded");
    if (episodes.size() > kMaxEpisodes) section.fail("degraded", "at most " + std::to_string(kMaxEpisodes) + " items");
    for (const YamlSection& item : episodes) {
        GnssDegraded degraded;
        degraded.at_s = item.required_in_range<double>("at_s", kEventStartBounds);
        degraded.at_location = item.location("at_s");
        degraded.for_s = item.required_in_range<double>("for_s", kEventLengthBounds);
        degraded.for_location = item.location("for_s");
        degraded.fix = item.optional_enum<GnssFix>("fix", kFixes, degraded.fix);
        degraded.sigma_m = item.required_in_range<double>("sigma_m", Bounds::closed(0, 100));
        gnss.degraded.push_back(degraded);
    }
    // Percentages of bytes or sentences: 100 is a receiver whose every output is damaged.
    const YamlSection faults = section.section("wire_faults");
    gnss.wire_faults.byte_loss_pct = faults.optional_in_range<double>("byte_loss_pct", 0.0, Bounds::closed(0, 100));
    gnss.wire_faults.corrupt_checksum_pct =
        faults.optional_in_range<double>("corrupt_checksum_pct", 0.0, Bounds::closed(0, 100));
    gnss.wire_faults.truncate_pct = faults.optional_in_range<double>("truncate_pct", 0.0, Bounds::closed(0, 100));
    return gnss;
}

EncoderSpec read_encoder(const YamlSection& section) {
    EncoderSpec encoder;
    // Shaft encoders: 100-10000 p/r (the ZSP5208 1000); more would flood the counter.
    encoder.pulses_per_rev = section.optional_in_range<std::uint32_t>("pulses_per_rev", encoder.pulses_per_rev,
                                                                      Bounds::closed(1, 100'000));
    // Land wheels are 0.3-1.5 m; a tractor's rear tyre up to ~2.2 m.
    encoder.wheel_diameter_m =
        section.optional_in_range<double>("wheel_diameter_m", encoder.wheel_diameter_m, Bounds::closed(0.1, 3));
    // Publication period 1/rate is a timer: at least 1 Hz.
    encoder.rate_hz = section.optional_in_range<double>("rate_hz", encoder.rate_hz, Bounds::closed(1, 1000));
    encoder.slip_pct = section.optional_in_range<double>("slip_pct", encoder.slip_pct, Bounds::closed(-20, 20));
    // A spread as large as half the slip range.
    encoder.slip_sd_pct = section.optional_in_range<double>("slip_sd_pct", encoder.slip_sd_pct, Bounds::closed(0, 10));
    encoder.deflection_pct =
        section.optional_in_range<double>("deflection_pct", encoder.deflection_pct, Bounds::closed_open(0, 20));
    encoder.terrain_sd_m_per_sqrt_m = section.optional_in_range<double>(
        "terrain_sd_m_per_sqrt_m", encoder.terrain_sd_m_per_sqrt_m, Bounds::closed(0, 1));
    return encoder;
}

HydraulicsSpec read_hydraulics(const YamlSection& section) {
    HydraulicsSpec h;
    // Boom-sprayer pumps: tens to ~200 L/min (at the start, and at each throttle step below).
    const Bounds pump_flow_bounds = Bounds::open_closed(0, 200);
    h.pump_flow_l_min = section.optional_in_range<double>("pump_flow_l_min", h.pump_flow_l_min, pump_flow_bounds);
    h.pump_pulsation_pct =
        section.optional_in_range<double>("pump_pulsation_pct", h.pump_pulsation_pct, Bounds::closed(0, 50));
    // Plunger strokes: ~500 rpm x 3 plungers = 27 Hz; 1-500 Hz covers any pump.
    h.pump_pulsation_hz =
        section.optional_in_range<double>("pump_pulsation_hz", h.pump_pulsation_hz, Bounds::closed(1, 500));
    // A hose fills in tenths of a second; 10 ms is a pipe with no volume.
    h.pipeline_time_constant_s = section.optional_in_range<double>(
        "pipeline_time_constant_s", h.pipeline_time_constant_s, Bounds::closed(0.01, 10));
    // A 12-36 m boom holds a few litres in all; 5 L of air is a boom run dry.
    h.pipeline_air_l = section.optional_in_range<double>("pipeline_air_l", h.pipeline_air_l, Bounds::closed(0, 5));
    // Flat fans are rated 0.2-5 L/min at 0.2-0.5 MPa (ISO 10625); sprayer pumps stop near 2 MPa.
    h.nozzle_rated_flow_l_min = section.optional_in_range<double>("nozzle_rated_flow_l_min",
                                                                  h.nozzle_rated_flow_l_min, Bounds::open_closed(0, 20));
    h.nozzle_rated_pressure_mpa = section.optional_in_range<double>(
        "nozzle_rated_pressure_mpa", h.nozzle_rated_pressure_mpa, Bounds::open_closed(0, 2));
    const YamlSection valve = section.section("valve");
    // Motorised ball valves turn in 2-30 s (the paper's 11 s); 0.1 s is a solenoid.
    h.valve_travel_s = valve.optional_in_range<double>("travel_s", h.valve_travel_s, Bounds::closed(0.1, 120));
    h.valve_backlash_pct = valve.optional_in_range<double>("backlash_pct", h.valve_backlash_pct, Bounds::closed(0, 20));
    h.valve_motor_start_delay_s =
        valve.optional_in_range<double>("motor_start_delay_s", h.valve_motor_start_delay_s, Bounds::closed(0, 1));
    h.valve_initial_opening_pct =
        valve.optional_in_range<double>("initial_opening_pct", h.valve_initial_opening_pct, Bounds::closed(0, 100));
    const YamlSection map = section.section("flow_map");
    h.interpolation_bulge_pct =
        map.optional_in_range<double>("interpolation_bulge_pct", h.interpolation_bulge_pct, Bounds::closed(-20, 20));
    h.calibration_drift_pct =
        map.optional_in_range<double>("calibration_drift_pct", h.calibration_drift_pct, Bounds::closed(-50, 50));
    // An engine settles at a new speed in about a second; a minute is a stalled one.
    h.throttle_ramp_s = section.optional_in_range<double>("throttle_ramp_s", h.throttle_ramp_s, Bounds::closed(0, 60));
    const std::vector<YamlSection> steps = section.list("pump_throttle");
    if (steps.size() > kMaxEpisodes) section.fail("pump_throttle", "at most " + std::to_string(kMaxEpisodes) + " items");
    for (const YamlSection& item : steps) {
        ThrottleStepSpec step;
        step.at_s = item.required_in_range<double>("at_s", kEventStartBounds);
        step.flow_l_min = item.required_in_range<double>("flow_l_min", pump_flow_bounds);
        item.finish();  // a missing at_s is said as missing, not as out of order
        if (!h.pump_throttle.empty() && !(step.at_s >= h.pump_throttle.back().at_s + h.throttle_ramp_s)) {
            item.fail("at_s", "starts at " + shortest_text(step.at_s) + " s, before the previous step's ramp ends (" +
                                  shortest_text(h.pump_throttle.back().at_s + h.throttle_ramp_s) +
                                  " s): one throttle moves one way at a time");
        }
        h.pump_throttle.push_back(step);
    }
    if (section.has("section_nozzles")) {
        h.section_nozzles.clear();
        const std::vector<std::string> counts = section.string_list("section_nozzles");
        // Checked before the items: a list of a million items is refused at once.
        if (counts.empty() || counts.size() > 8) section.fail("section_nozzles", "must list 1 to 8 sections");
        for (std::size_t i = 0; i < counts.size(); ++i) {
            int nozzles = 0;
            const auto result = std::from_chars(counts[i].data(), counts[i].data() + counts[i].size(), nozzles);
            if (result.ec != std::errc{} || result.ptr != counts[i].data() + counts[i].size() || nozzles < 1 ||
                nozzles > 64) {
                std::string shown = counts[i].size() > 20 ? counts[i].substr(0, 20) + "..." : counts[i];
                throw ConfigError(section.item_location("section_nozzles", i),
                                  "a section's nozzle count must be a whole number in [1, 64], got '" + shown + "'");
            }
            h.section_nozzles.push_back(nozzles);
        }
    }
    // Booms are 12-36 m (the paper's 12.2 m); 60 m is the widest built.
    h.boom_width_m = section.optional_in_range<double>("boom_width_m", h.boom_width_m, Bounds::closed(1, 60));
    h.section_valve_open_s =
        section.optional_in_range<double>("section_valve_open_s", h.section_valve_open_s, Bounds::closed(0, 5));
    h.section_valve_close_s =
        section.optional_in_range<double>("section_valve_close_s", h.section_valve_close_s, Bounds::closed(0, 5));
    h.droplet_fall_s = section.optional_in_range<double>("droplet_fall_s", h.droplet_fall_s, Bounds::closed(0, 2));
    // Flat-fan nozzles pass 0.2-5 L/min; a nozzle that passes 10 mL/min is shut.
    h.min_nozzle_flow_l_min =
        section.optional_in_range<double>("min_nozzle_flow_l_min", h.min_nozzle_flow_l_min, Bounds::closed(0.01, 20));
    return h;
}

FlowMeterSpec read_flow_meter(const YamlSection& section) {
    FlowMeterSpec meter;
    // Turbine meters give 1-10000 pulses per litre (the KF11 90); the pulse period is a timer.
    meter.pulses_per_l = section.optional_in_range<double>("pulses_per_l", meter.pulses_per_l, Bounds::closed(1, 1e4));
    meter.k_factor_error_pct =
        section.optional_in_range<double>("k_factor_error_pct", meter.k_factor_error_pct, Bounds::closed(-50, 50));
    meter.rate_hz = section.optional_in_range<double>("rate_hz", meter.rate_hz, Bounds::closed(1, 1000));
    return meter;
}

PumpSensorSpec read_pump_sensor(const YamlSection& section) {
    PumpSensorSpec sensor;
    // Turbine flow sensors span 0.1-1000 m^3/h (the WL-LWGA-20 8).
    sensor.full_scale_m3_h =
        section.optional_in_range<double>("full_scale_m3_h", sensor.full_scale_m3_h, Bounds::closed(0.1, 1000));
    // On a 3.3 V span; 1 V of noise is a broken wire.
    sensor.noise_mv = section.optional_in_range<double>("noise_mv", sensor.noise_mv, Bounds::closed(0, 1000));
    // A 4-20 mA loop: the zero can move by at most the loop's own range.
    sensor.offset_ma = section.optional_in_range<double>("offset_ma", sensor.offset_ma, Bounds::closed(-4, 16));
    sensor.rate_hz = section.optional_in_range<double>("rate_hz", sensor.rate_hz, Bounds::closed(1, 1000));
    return sensor;
}

BoomHeightSensorSpec read_boom_height_sensor(const YamlSection& section) {
    BoomHeightSensorSpec sensor;
    // Pull-wire sensors reach 0.1-10 m.
    sensor.range_m = section.optional_in_range<double>("range_m", sensor.range_m, Bounds::closed(0.1, 10));
    sensor.rate_hz = section.optional_in_range<double>("rate_hz", sensor.rate_hz, Bounds::closed(1, 1000));
    return sensor;
}

DepositionSpec read_deposition(const YamlSection& section) {
    DepositionSpec deposition;
    // Grid cells of 5 mm to 1 m; with kMaxAlongM that bounds the grid to a few million cells.
    deposition.cell_m = section.optional_in_range<double>("cell_m", deposition.cell_m, Bounds::closed(0.005, 1));
    // A flat fan's band along the track: 1 cm to 2 m.
    deposition.footprint_m =
        section.optional_in_range<double>("footprint_m", deposition.footprint_m, Bounds::closed(0.01, 2));
    deposition.sprayed_fraction =
        section.optional_in_range<double>("sprayed_fraction", deposition.sprayed_fraction, Bounds::open(0, 1));
    deposition.cv_row_m = section.optional_in_range<double>("cv_row_m", deposition.cv_row_m, Bounds::closed(0.01, 5));
    deposition.cv_window_m =
        section.optional_in_range<double>("cv_window_m", deposition.cv_window_m, Bounds::closed(0.1, 100));
    deposition.strip_start_allowance_m = section.optional_in_range<double>(
        "strip_start_allowance_m", deposition.strip_start_allowance_m, Bounds::closed(0, 100));
    deposition.strip_end_allowance_m = section.optional_in_range<double>(
        "strip_end_allowance_m", deposition.strip_end_allowance_m, Bounds::closed(0, 100));
    return deposition;
}

StaticFlowSpec read_static_flow(const YamlSection& section) {
    StaticFlowSpec static_flow;
    // A static test lasts minutes (Table 2's adjust times are seconds); an hour each at most.
    static_flow.spray_on_at_s =
        section.optional_in_range<double>("spray_on_at_s", static_flow.spray_on_at_s, Bounds::closed(0, 3600));
    static_flow.spray_for_s =
        section.optional_in_range<double>("spray_for_s", static_flow.spray_for_s, Bounds::open_closed(0, 3600));
    return static_flow;
}

}  // namespace

double BoomSpec::lift_duration_s(std::size_t index) const {
    const double from_m = index == 0 ? linkage_rise_m : lifts.at(index - 1).to_m;
    return std::abs(lifts.at(index).to_m - from_m) / lifts.at(index).rate_m_s;
}

std::string_view to_string(Scenario scenario) { return name_of(kScenarios, scenario); }
std::string_view to_string(GnssTalker talker) { return name_of(kTalkers, talker); }
std::string_view to_string(GnssFix fix) { return name_of(kFixes, fix); }

bool default_limit_applies(Scenario scenario, const std::string& metric) {
    const bool identifies = !stands_still(scenario);
    const bool sprays = scenario != Scenario::breakpoint_identification && scenario != Scenario::valve_calibration;
    const bool continues = scenario == Scenario::breakpoint_continuation;
    if (metric == "breakpoint_error_m") return identifies;
    if (metric == "flow_adjust_time_s" || metric == "flow_error_pct") return sprays;
    if (metric == "overlap_m" || metric == "missed_m") return continues;
    return true;
}
std::map<std::string, double> BreakpointSections::default_limits() const {
    std::map<std::string, double> limits;
    for (const auto& [name, limit] : kDefaultLimits) {
        if (default_limit_applies(scenario_kind, name)) limits[name] = limit;
    }
    return limits;
}

// Checks between seed 000's sections and the common ones; run after finish(), when every value is real.
void BreakpointSections::check_with(const CaseSpec& spec, const YamlSection& root) const {
    (void)spec;
    if (!stands_still(scenario_kind) && !(vehicle.start_m < breakpoint.along_m)) {
        root.section("vehicle").fail("start_m", "must be < breakpoint.along_m (" +
                                                    shortest_text(breakpoint.along_m) +
                                                    ") so the vehicle approaches the breakpoint, got " +
                                                    shortest_text(vehicle.start_m));
    }
    if (scenario_kind == Scenario::breakpoint_continuation) {
        const double strip_m = vehicle.first_pass_m + vehicle.overrun_m;
        if (!(deposition.strip_start_allowance_m + deposition.strip_end_allowance_m < strip_m)) {
            root.section("deposition").fail("strip_end_allowance_m",
                                            "the allowances leave nothing of the " + shortest_text(strip_m) +
                                                " m strip to judge (vehicle.first_pass_m + vehicle.overrun_m)");
        }
    }
    if (!stands_still(scenario_kind)) {
        // The land wheel's terrain (odometer truth) is drawn for this much ground.
        const double terrain_m = emulators::LandWheelParams{}.terrain_length_m;
        const double driven_m =
            vehicle.first_pass_m + (breakpoint.along_m - vehicle.start_m) + vehicle.overrun_m;
        if (driven_m > terrain_m) {
            root.section("vehicle").fail("start_m", "the route drives " + shortest_text(driven_m) +
                                                        " m (first_pass_m + breakpoint.along_m - start_m + "
                                                        "overrun_m); at most " +
                                                        shortest_text(terrain_m) + " m of ground is modelled");
        }
    }
}

std::shared_ptr<const BreakpointSections> read_breakpoint_sections(const YamlSection& root) {
    auto own = std::make_shared<BreakpointSections>();
    own->scenario_kind = root.optional_enum<Scenario>("scenario", kScenarios, own->scenario_kind);
    own->utc_start_iso = root.optional<std::string>("utc_start", own->utc_start_iso);
    const auto utc_start = parse_utc(own->utc_start_iso);
    if (!utc_start) {
        const std::string shown =
            own->utc_start_iso.size() > 40 ? own->utc_start_iso.substr(0, 40) + "..." : own->utc_start_iso;
        root.fail("utc_start", "expected an ISO-8601 UTC time from 1980 to 2099 like 2023-07-15T02:00:00Z, got '" +
                                   shown + "'");
    }
    own->utc_start = *utc_start;

    own->field = read_field(root.required_section("field"));
    const bool standing = stands_still(own->scenario_kind);
    own->vehicle = read_vehicle(standing ? root.section("vehicle") : root.required_section("vehicle"), standing);
    own->boom = read_boom(root.section("boom"));
    own->breakpoint = read_breakpoint(root.section("breakpoint"));
    own->gnss = read_gnss(root.section("gnss"));
    own->encoder = read_encoder(root.section("encoder"));
    own->hydraulics = read_hydraulics(root.section("hydraulics"));
    own->flow_meter = read_flow_meter(root.section("flow_meter"));
    own->pump_sensor = read_pump_sensor(root.section("pump_sensor"));
    own->boom_height_sensor = read_boom_height_sensor(root.section("boom_height_sensor"));
    own->deposition = read_deposition(root.section("deposition"));
    own->static_flow = read_static_flow(root.section("static_flow"));
    own->guidance = read_guidance_section(root);
    if (own->guidance) {
        const YamlSection guidance = root.section("guidance");
        own->antenna.forward_of_rear_axle_m = guidance.optional_in_range<double>(
            "antenna_forward_of_axle_m", own->antenna.forward_of_rear_axle_m, Bounds::closed(-1e9, 1e9));
        own->antenna.height_m = guidance.optional_in_range<double>("antenna_height_m", own->antenna.height_m,
                                                                   Bounds::closed(-1e9, 1e9));
        try {
            emulators::guidance::validate(own->antenna, "guidance");
        } catch (const std::invalid_argument& error) {
            guidance.fail(error.what());
        }
    }
    // The harness judges flow against the target the controller is given
    // (boom-sprayer pumps deliver at most ~200 L/min; see hydraulics). Read
    // through a section of its own, never finish()ed: the rest of the
    // controller's section is the controller's to check.
    const YamlSection controller(root.raw("controller"));
    if (controller.has("target_flow_l_min")) {
        own->target_flow_l_min = controller.required_in_range<double>("target_flow_l_min", Bounds::open_closed(0, 250));
    }
    return own;
}

const BreakpointSections& breakpoint_sections(const CaseSpec& spec) {
    const auto* own = dynamic_cast<const BreakpointSections*>(spec.system.get());
    if (own == nullptr) {
        throw std::logic_error(spec.source_path.string() + ": not a seed-000 (breakpoint) case");
    }
    return *own;
}

void check_case_timeline(const CaseSpec& spec, double case_end_s, double breakpoint_crossing_s) {
    const BreakpointSections& own = breakpoint_sections(spec);
    const auto check = [&](double at_s, double for_s, const SourceLocation& at_where, const SourceLocation& for_where,
                           const char* what) { check_event_in_case(at_s, for_s, at_where, for_where, what, case_end_s); };
    for (const GnssDropout& dropout : own.gnss.dropouts) {
        double at_s = dropout.at_s;
        if (dropout.before_breakpoint_s) {
            if (!std::isfinite(breakpoint_crossing_s)) {
                throw ConfigError(dropout.at_location,
                                  "a static test never crosses the breakpoint: give the dropout's at_s");
            }
            at_s = breakpoint_crossing_s - *dropout.before_breakpoint_s;
        }
        check(at_s, dropout.for_s, dropout.at_location, dropout.for_location, "the dropout");
    }
    for (const GnssDegraded& degraded : own.gnss.degraded) {
        check(degraded.at_s, degraded.for_s, degraded.at_location, degraded.for_location, "the degraded episode");
    }
    for (std::size_t index = 0; index < own.boom.lifts.size(); ++index) {
        const BoomLiftSpec& lift = own.boom.lifts[index];
        check(lift.at_s, own.boom.lift_duration_s(index), lift.at_location, lift.to_location, "the boom lift");
    }
    check_common_timeline(spec, case_end_s);
}

}  // namespace rig::harness
