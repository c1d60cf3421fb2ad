#include "harness/case_spec.h"

#include "emulators/land_wheel.h"
#include "harness/boundary_case.h"
#include "rig/config/file_access.h"
#include "rig/runtime/failure_kind.h"
#include "rig/wire/hid_board_protocol.h"
#include "rig/wire/modbus_protocol.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <unordered_map>
#include <optional>
#include <sstream>
#include <system_error>

namespace rig::harness {

namespace {

constexpr EnumChoice<RunMode> kRunModes[] = {
    {"lockstep", RunMode::lockstep},
    {"realtime", RunMode::realtime},
};
constexpr EnumChoice<CaseSystem> kSystems[] = {
    {"breakpoint", CaseSystem::breakpoint},
    {"boundary", CaseSystem::boundary},
};
constexpr EnumChoice<Scenario> kScenarios[] = {
    {"breakpoint_identification", Scenario::breakpoint_identification},
    {"breakpoint_continuation", Scenario::breakpoint_continuation},
    {"static_flow", Scenario::static_flow},
    {"valve_calibration", Scenario::valve_calibration},
};
constexpr EnumChoice<GnssWire> kGnssWires[] = {
    {"dds", GnssWire::dds},
    {"serial", GnssWire::serial},
};
constexpr EnumChoice<BoardIoWireKind> kBoardIoWires[] = {
    {"dds", BoardIoWireKind::dds},
    {"modbus_rtu", BoardIoWireKind::modbus_rtu},
    {"modbus_tcp", BoardIoWireKind::modbus_tcp},
    {"hid", BoardIoWireKind::hid},
};
constexpr EnumChoice<bool> kControllerPlaces[] = {
    {"process", false},
    {"external", true},
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

// Shortest text that reads back as the same double ("-60", not "-60.000000").
std::string number_text(double value) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
    return std::string(buffer, result.ptr);
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

// ---------------------------------------------------------------- sections
//
// Every number has a range, each with its physical reason: a finite value far
// outside physics (1e300 m, a 1e-300 Hz rate) would pass a sign check and then
// overflow simulated time (int64 ns) or allocate without end at run time.

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
            item.fail("at_s", "starts at " + number_text(lift.at_s) + " s, before the previous lift arrives (" +
                                  number_text(push_rod_free_s) + " s): one push rod moves one way at a time");
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
            item.fail("at_s", "starts at " + number_text(step.at_s) + " s, before the previous step's ramp ends (" +
                                  number_text(h.pump_throttle.back().at_s + h.throttle_ramp_s) +
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

// A device path or "pty"; PATH_MAX-style limits are far above any real port name.
std::string read_port(const YamlSection& section, std::string_view key, const std::string& fallback) {
    std::string port = section.optional<std::string>(key, fallback);
    if (port.empty()) section.fail(key, "must be 'pty' or a serial device path");
    if (port.size() > 255) section.fail(key, "is " + std::to_string(port.size()) + " characters long, at most 255");
    return port;
}

WiringSpec read_wiring(const YamlSection& section, CaseSystem system) {
    WiringSpec wiring;
    if (system == CaseSystem::boundary) {
        wiring.laser = section.optional_enum<GnssWire>("laser", kGnssWires, wiring.laser);
        wiring.laser_port = read_port(section, "laser_port", wiring.laser_port);
        wiring.laser_baud = section.optional_in_range<int>("laser_baud", wiring.laser_baud, Bounds::closed(1200, 4000000));
    }
    wiring.gnss = section.optional_enum<GnssWire>("gnss", kGnssWires, wiring.gnss);
    wiring.board_io = section.optional_enum<BoardIoWireKind>("board_io", kBoardIoWires, wiring.board_io);
    wiring.gnss_port = read_port(section, "gnss_port", wiring.gnss_port);
    // Serial lines: 1200 baud to 4 Mbaud (the fastest USB-serial adapters).
    wiring.nmea_baud = section.optional_in_range<int>("nmea_baud", wiring.nmea_baud, Bounds::closed(1200, 4000000));
    wiring.modbus_port = read_port(section, "modbus_port", wiring.modbus_port);
    wiring.modbus_baud = section.optional_in_range<int>("modbus_baud", wiring.modbus_baud, Bounds::closed(1200, 4000000));
    wiring.modbus_tcp = read_port(section, "modbus_tcp", wiring.modbus_tcp);
    wiring.hid_vid = static_cast<std::uint16_t>(
        section.optional_in_range<std::uint32_t>("hid_vid", wiring.hid_vid, Bounds::closed(0, 0xFFFF)));
    wiring.hid_pid = static_cast<std::uint16_t>(
        section.optional_in_range<std::uint32_t>("hid_pid", wiring.hid_pid, Bounds::closed(0, 0xFFFF)));
    // The board's input refresh: a timer, 1 Hz to 2 kHz.
    wiring.board_update_hz =
        section.optional_in_range<double>("board_update_hz", wiring.board_update_hz, Bounds::closed(1, 2000));
    wiring.external_controller = section.optional_enum<bool>("controller", kControllerPlaces, wiring.external_controller);
    return wiring;
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

// The section stays raw for the controller; only `command` is the rig's. It is
// read through a separate YamlSection (never finish()ed) so the controller's
// own keys are not reported as unknown here.
ControllerSpec read_controller(const YamlSection& root) {
    ControllerSpec controller;
    controller.params = root.raw("controller");
    if (controller.params.present && !controller.params.node.IsNull() && !controller.params.node.IsMap()) {
        root.fail("controller", "expected a mapping (key: value), got " + describe_node(controller.params.node));
    }
    const YamlSection section(controller.params);
    if (section.has("command")) {
        controller.command = section.string_list("command");
        if (controller.command.empty()) {
            section.fail("command", "must name the controller executable, e.g. [ \"rig-controller\" ]");
        }
        // An argv, not a data channel: bounded like a shell command line.
        if (controller.command.size() > 64) section.fail("command", "at most 64 arguments");
        for (std::size_t i = 0; i < controller.command.size(); ++i) {
            if (controller.command[i].size() > 4096) {
                throw ConfigError(section.item_location("command", i), "an argument of at most 4096 characters");
            }
        }
    }
    if (section.has("plugin")) {
        const std::string plugin = section.required<std::string>("plugin");
        if (plugin.empty() || plugin.size() > 4096) section.fail("plugin", "the path of a controller plugin (.so)");
        controller.plugin = plugin;
    }
    if (section.has("in_process")) controller.in_process = section.required<bool>("in_process");
    // The harness judges flow against the target the controller is given
    // (boom-sprayer pumps deliver at most ~200 L/min; see hydraulics).
    if (section.has("target_flow_l_min")) {
        controller.target_flow_l_min =
            section.required_in_range<double>("target_flow_l_min", Bounds::open_closed(0, 250));
    }
    return controller;
}

std::map<std::string, double> read_limits(const YamlSection& section) {
    std::map<std::string, double> limits;
    for (const std::string& name : section.keys()) {
        // Metric names are a few words; the name is repeated in every message.
        if (name.size() > 64) {
            throw ConfigError(section.key_location(name), "metric name of " + std::to_string(name.size()) +
                                                              " characters, at most 64");
        }
        if (const std::string problem = metric_name_problem(name); !problem.empty()) {
            throw ConfigError(section.key_location(name), problem);
        }
        // Limits are on metres, seconds, percent and counts of one case; no
        // metric the harness measures comes near a million of any of them.
        limits[name] = section.required_in_range<double>(name, Bounds::closed(-1e6, 1e6));
    }
    return limits;
}

PaperPoints read_paper(const YamlSection& section) {
    PaperPoints paper;
    for (const std::string& name : section.keys()) {
        if (name == "source") continue;
        if (name.size() > 64) {
            throw ConfigError(section.key_location(name), "metric name of " + std::to_string(name.size()) +
                                                              " characters, at most 64");
        }
        if (const std::string problem = metric_name_problem(name); !problem.empty()) {
            throw ConfigError(section.key_location(name), problem);
        }
        // The same range as a limit: the paper's numbers are of the same metrics.
        paper.values[name] = section.required_in_range<double>(name, Bounds::closed(-1e6, 1e6));
    }
    if (section.has("source")) {
        paper.source = section.required<std::string>("source");
        if (paper.source.empty() || paper.source.size() > 200) {
            section.fail("source", "where in the paper the numbers are, in at most 200 characters (e.g. \"Table 2\")");
        }
    }
    if (!paper.values.empty() && paper.source.empty()) {
        throw ConfigError(section.key_location(paper.values.begin()->first),
                          "the paper's numbers need a source: where in the paper they are (paper.source)");
    }
    return paper;
}

ExpectSpec read_expect(const YamlSection& section) {
    ExpectSpec expect;
    expect.fail = section.string_list("fail");
    if (section.has("error")) {
        expect.error = section.required<std::string>("error");
        if (!failure_kind_from_string(expect.error)) {
            section.fail("error", "'" + expect.error + "' is not a kind of run failure; one of: " + failure_kind_names());
        }
        if (!expect.fail.empty()) {
            section.fail("error", "a case that must end in an error cannot also expect metrics to break (`fail`): "
                                  "an errored case is not judged on its metrics");
        }
    }
    if (section.has("controller")) {
        const std::string whose = section.required<std::string>("controller");
        if (whose != "reference" && whose != "any") {
            section.fail("controller", "'" + whose +
                                           "' is not whose behaviour an expectation can describe: reference (the "
                                           "rig's reference controller, the default) or any");
        }
        expect.any_controller = whose == "any";
    }
    return expect;
}

TimeoutsSpec read_timeouts(const YamlSection& section) {
    TimeoutsSpec timeouts;
    // Wall time: a node acks a tick in milliseconds; a case runs minutes, a day at most.
    timeouts.node_ack_s =
        section.optional_in_range<double>("node_ack_s", timeouts.node_ack_s, Bounds::open_closed(0, 600));
    timeouts.case_wall_s =
        section.optional_in_range<double>("case_wall_s", timeouts.case_wall_s, Bounds::open_closed(0, 86400));
    return timeouts;
}

// The wires, the real-time sections and the board, seed 000's and seed 001's alike.
void check_bench_wiring(const CaseSpec& spec, const YamlSection& root) {
    if (spec.wiring.uses_bench_wire() && spec.mode != RunMode::realtime) {
        root.section("wiring").fail("serial, Modbus and HID wires have no virtual time: set `mode: realtime`");
    }
    if (spec.board.line_noise.any() && spec.wiring.board_io != BoardIoWireKind::modbus_rtu) {
        root.section("board").fail("line_noise", "line noise is injected on a Modbus RTU line: needs `wiring: { "
                                                 "board_io: modbus_rtu }`");
    }
    for (const char* section : {"realtime", "rig_faults"}) {
        if (root.has(section) && spec.mode != RunMode::realtime) {
            root.fail(section, "bounds and faults of the rig's real-time loop: only with `mode: realtime`");
        }
    }
    if (spec.wiring.external_controller && !spec.wiring.uses_bench_wire()) {
        root.section("wiring").fail("controller", "an external controller needs a bench wire (gnss: serial, board_io: ...)");
    }
}

// Checks between sections; run after finish(), when every value is real.
void check_cross_fields(const CaseSpec& spec, const YamlSection& root,
                        const std::map<std::string, double>& default_limits) {
    if (!stands_still(spec.scenario) && !(spec.vehicle.start_m < spec.breakpoint.along_m)) {
        root.section("vehicle").fail("start_m", "must be < breakpoint.along_m (" +
                                                    number_text(spec.breakpoint.along_m) +
                                                    ") so the vehicle approaches the breakpoint, got " +
                                                    number_text(spec.vehicle.start_m));
    }
    if (spec.scenario == Scenario::breakpoint_continuation) {
        const double strip_m = spec.vehicle.first_pass_m + spec.vehicle.overrun_m;
        if (!(spec.deposition.strip_start_allowance_m + spec.deposition.strip_end_allowance_m < strip_m)) {
            root.section("deposition").fail("strip_end_allowance_m",
                                            "the allowances leave nothing of the " + number_text(strip_m) +
                                                " m strip to judge (vehicle.first_pass_m + vehicle.overrun_m)");
        }
    }
    if (!stands_still(spec.scenario)) {
        // The land wheel's terrain (odometer truth) is drawn for this much ground.
        const double terrain_m = emulators::LandWheelParams{}.terrain_length_m;
        const double driven_m =
            spec.vehicle.first_pass_m + (spec.breakpoint.along_m - spec.vehicle.start_m) + spec.vehicle.overrun_m;
        if (driven_m > terrain_m) {
            root.section("vehicle").fail("start_m", "the route drives " + number_text(driven_m) +
                                                        " m (first_pass_m + breakpoint.along_m - start_m + "
                                                        "overrun_m); at most " +
                                                        number_text(terrain_m) + " m of ground is modelled");
        }
    }
    check_bench_wiring(spec, root);
    if (spec.controller.in_process.value_or(false)) {
        // In process, the controller is stepped by the lockstep master: there is
        // no process boundary, so no wall clock and no bench wire to drive it.
        const YamlSection controller(spec.controller.params);
        if (spec.mode != RunMode::lockstep || spec.wiring.external_controller) {
            controller.fail("in_process", "a controller runs in process only in lockstep cases on DDS wires");
        }
        if (!spec.controller.command.empty() && spec.controller.plugin.empty()) {
            controller.fail("in_process", "`command` names a program; a controller runs in process from its "
                                          "shared library: give `plugin` too");
        }
    }
    if (spec.wiring.board_io == BoardIoWireKind::modbus_tcp) {
        try {
            modbus::parse_tcp_endpoint(spec.wiring.modbus_tcp);
        } catch (const std::exception& error) {
            root.section("wiring").fail("modbus_tcp", error.what());
        }
    }
    const YamlSection expect = root.section("expect");
    for (std::size_t index = 0; index < spec.expect.fail.size(); ++index) {
        const std::string& metric = spec.expect.fail[index];
        const std::string shown = metric.size() > 64 ? metric.substr(0, 64) + "..." : metric;
        if (!spec.limits.contains(metric) &&
            !(default_limits.contains(metric) && default_limit_applies(spec.scenario, metric))) {
            throw ConfigError(expect.item_location("fail", index),
                              "'" + shown + "' has no limit; expected failures must name limited metrics "
                              "(limits in this file or the defaults)");
        }
        for (std::size_t earlier = 0; earlier < index; ++earlier) {
            if (spec.expect.fail[earlier] == metric) {
                throw ConfigError(expect.item_location("fail", index), "'" + shown + "' is listed twice");
            }
        }
    }
}

}  // namespace

double BoomSpec::lift_duration_s(std::size_t index) const {
    const double from_m = index == 0 ? linkage_rise_m : lifts.at(index - 1).to_m;
    return std::abs(lifts.at(index).to_m - from_m) / lifts.at(index).rate_m_s;
}

std::string_view to_string(RunMode mode) { return name_of(kRunModes, mode); }
std::string_view to_string(Scenario scenario) { return name_of(kScenarios, scenario); }
std::string_view to_string(GnssWire wire) { return name_of(kGnssWires, wire); }
std::string_view to_string(BoardIoWireKind wire) { return name_of(kBoardIoWires, wire); }

bool default_limit_applies(Scenario scenario, const std::string& metric) {
    const bool identifies = !stands_still(scenario);
    const bool sprays = scenario != Scenario::breakpoint_identification && scenario != Scenario::valve_calibration;
    const bool continues = scenario == Scenario::breakpoint_continuation;
    if (metric == "breakpoint_error_m") return identifies;
    if (metric == "flow_adjust_time_s" || metric == "flow_error_pct") return sprays;
    if (metric == "overlap_m" || metric == "missed_m") return continues;
    return true;
}
std::string_view to_string(GnssTalker talker) { return name_of(kTalkers, talker); }
std::string_view to_string(GnssFix fix) { return name_of(kFixes, fix); }

std::string metric_name_problem(std::string_view name) {
    const auto fail = [&](const std::string& why) {
        std::string suffixes;
        for (const std::string_view suffix : kMetricUnitSuffixes) {
            if (!suffixes.empty()) suffixes += ", ";
            suffixes += '_';
            suffixes += suffix;
        }
        return "metric name '" + std::string(name) + "' " + why +
               "; metric names are snake_case with a unit suffix (" + suffixes + ")";
    };
    bool snake_case = !name.empty() && std::islower(static_cast<unsigned char>(name.front())) != 0 &&
                      name.back() != '_' && name.find("__") == std::string_view::npos;
    for (const char c : name) {
        const auto byte = static_cast<unsigned char>(c);
        if (!(std::islower(byte) || std::isdigit(byte) || c == '_')) snake_case = false;
    }
    if (!snake_case) return fail("is not snake_case");
    for (const std::string_view suffix : kMetricUnitSuffixes) {
        // At least one word before `_<suffix>`.
        if (name.size() > suffix.size() + 1 && name.ends_with(suffix) && name[name.size() - suffix.size() - 1] == '_') {
            return {};
        }
    }
    return fail("has no unit suffix");
}

std::map<std::string, double> effective_limits(const CaseSpec& spec, const std::map<std::string, double>& defaults) {
    std::map<std::string, double> limits;
    for (const auto& [name, limit] : defaults) {
        if (spec.system == CaseSystem::breakpoint && default_limit_applies(spec.scenario, name)) limits[name] = limit;
    }
    for (const auto& [name, limit] : spec.limits) limits[name] = limit;
    return limits;
}

namespace {

// Seed 001's boundary cases: their own sections (harness/boundary_case.h), then
// the ones every case has. No default limits apply: the case file gives each.
CaseSpec read_boundary_system_case(const YamlSection& root, CaseSpec spec) {
    auto boundary = std::make_shared<BoundaryCaseSpec>(read_boundary_case(root));
    spec.controller = read_controller(root);
    if (spec.controller.in_process.value_or(false) || !spec.controller.plugin.empty()) {
        YamlSection(spec.controller.params)
            .fail(spec.controller.plugin.empty() ? "in_process" : "plugin",
                  "seed 001's boundary cases run their controller as a program (no in-process mode yet)");
    }
    spec.controller.params = controller_section_with_area(spec.controller.params, *boundary);
    spec.limits = read_limits(root.section("limits"));
    spec.paper = read_paper(root.section("paper"));
    spec.expect = read_expect(root.section("expect"));
    spec.timeouts = read_timeouts(root.section("timeouts"));
    spec.wiring = read_wiring(root.section("wiring"), spec.system);
    spec.board = read_board_spec(root.section("board"));
    spec.realtime = read_realtime_section(root.section("realtime"));
    spec.rig_faults = read_rig_faults(root.section("rig_faults"));
    root.finish();
    check_bench_wiring(spec, root);
    // The Pi's outputs are six PWM lines, measured by the HID board's capture
    // (docs/hid-io-board.md), or its duties on DDS: it has no Modbus I/O.
    if (spec.wiring.board_io == BoardIoWireKind::modbus_rtu || spec.wiring.board_io == BoardIoWireKind::modbus_tcp) {
        root.section("wiring").fail("board_io", "seed 001's nozzle PWM comes on DDS or through the HID board's capture: "
                                                "dds or hid");
    }
    // The capture publishes actuator/nozzle_pwm/duty for the wired board: a
    // controller process beside it would be a second writer of that topic.
    if (spec.wiring.board_io == BoardIoWireKind::hid && !spec.wiring.external_controller) {
        root.section("wiring").fail("board_io", "the HID board captures a wired controller's PWM: needs `controller: external`");
    }
    if (spec.wiring.board_io == BoardIoWireKind::hid) {
        // rig/wire/wire_adapters.h NozzlePwmCaptureAdapter: six capture inputs, read at most at 1 kHz.
        if (spec.wiring.board_update_hz > 1000.0) {
            root.section("wiring").fail("board_update_hz", "the PWM capture is read at most 1000 times a second, got " +
                                                               number_text(spec.wiring.board_update_hz));
        }
        const int nozzles = boundary->flow_table_or_paper().nozzle_count();
        if (nozzles > hid::kPwmCaptureInputs) {
            root.section("wiring").fail("board_io", "the HID board captures " + std::to_string(hid::kPwmCaptureInputs) +
                                                        " PWM inputs; this sprayer has " + std::to_string(nozzles) +
                                                        " nozzles");
        }
    }
    check_boundary_case(*boundary, root);
    for (std::size_t index = 0; index < spec.expect.fail.size(); ++index) {
        if (!spec.limits.contains(spec.expect.fail[index])) {
            throw ConfigError(root.section("expect").item_location("fail", index),
                              "'" + spec.expect.fail[index] + "' has no limit in this file; expected failures must name limited metrics");
        }
    }
    spec.boundary = std::move(boundary);
    return spec;
}

CaseSpec read_case(const YamlSection& root, const std::filesystem::path& source_path,
                   const std::map<std::string, double>& default_limits) {
    CaseSpec spec;
    spec.source_path = source_path;

    spec.name = root.required<std::string>("name");
    spec.name_location = root.location("name");
    if (root.has("name")) {
        // The name is a directory under --out: `..` would be --out itself (and
        // its removal would delete what was there), `.` would be cases/.
        if (const std::string problem = plain_file_name_problem(spec.name, kMaxCaseNameLength); !problem.empty()) {
            const std::string shown = spec.name.size() > 40 ? spec.name.substr(0, 40) + "..." : spec.name;
            root.fail("name", "case name " + problem + ", got '" + shown + "'");
        }
    }
    spec.description = root.optional<std::string>("description", "");
    if (spec.description.size() > kMaxDescriptionLength) {
        root.fail("description", "is " + std::to_string(spec.description.size()) + " characters long, at most " +
                                     std::to_string(kMaxDescriptionLength));
    }
    spec.seed = root.optional<std::uint64_t>("seed", spec.seed);
    if (root.has("seeds")) {
        if (root.has("seed")) root.fail("seeds", "give either `seed` or `seeds`, not both");
        const std::vector<std::string> seeds = root.string_list("seeds");
        if (seeds.empty()) root.fail("seeds", "must list at least one seed");
        for (std::size_t index = 0; index < seeds.size(); ++index) {
            std::uint64_t seed = 0;
            const auto [end, error] = std::from_chars(seeds[index].data(), seeds[index].data() + seeds[index].size(), seed);
            if (error != std::errc{} || end != seeds[index].data() + seeds[index].size()) {
                throw ConfigError(root.item_location("seeds", index),
                                  "a seed is a whole number >= 0, got '" + seeds[index] + "'");
            }
            if (std::find(spec.seeds.begin(), spec.seeds.end(), seed) != spec.seeds.end()) {
                throw ConfigError(root.item_location("seeds", index), "seed " + seeds[index] + " is listed twice");
            }
            spec.seeds.push_back(seed);
        }
        spec.seed = spec.seeds.front();
    }
    if (root.has("domain")) spec.domain = root.required_in_range<std::uint32_t>("domain", Bounds::closed(0, 232));
    spec.mode = root.optional_enum<RunMode>("mode", kRunModes, spec.mode);
    spec.system = root.optional_enum<CaseSystem>("system", kSystems, spec.system);
    if (spec.system == CaseSystem::boundary) return read_boundary_system_case(root, std::move(spec));
    spec.scenario = root.optional_enum<Scenario>("scenario", kScenarios, spec.scenario);
    spec.utc_start_iso = root.optional<std::string>("utc_start", spec.utc_start_iso);
    const auto utc_start = parse_utc(spec.utc_start_iso);
    if (!utc_start) {
        const std::string shown =
            spec.utc_start_iso.size() > 40 ? spec.utc_start_iso.substr(0, 40) + "..." : spec.utc_start_iso;
        root.fail("utc_start", "expected an ISO-8601 UTC time from 1980 to 2099 like 2023-07-15T02:00:00Z, got '" +
                                   shown + "'");
    }
    spec.utc_start = *utc_start;

    spec.field = read_field(root.required_section("field"));
    const bool standing = stands_still(spec.scenario);
    spec.vehicle = read_vehicle(standing ? root.section("vehicle") : root.required_section("vehicle"), standing);
    spec.boom = read_boom(root.section("boom"));
    spec.breakpoint = read_breakpoint(root.section("breakpoint"));
    spec.gnss = read_gnss(root.section("gnss"));
    spec.encoder = read_encoder(root.section("encoder"));
    spec.hydraulics = read_hydraulics(root.section("hydraulics"));
    spec.flow_meter = read_flow_meter(root.section("flow_meter"));
    spec.pump_sensor = read_pump_sensor(root.section("pump_sensor"));
    spec.boom_height_sensor = read_boom_height_sensor(root.section("boom_height_sensor"));
    spec.deposition = read_deposition(root.section("deposition"));
    spec.static_flow = read_static_flow(root.section("static_flow"));
    spec.wiring = read_wiring(root.section("wiring"), spec.system);
    spec.board = read_board_spec(root.section("board"));
    spec.realtime = read_realtime_section(root.section("realtime"));
    spec.rig_faults = read_rig_faults(root.section("rig_faults"));
    spec.controller = read_controller(root);
    spec.limits = read_limits(root.section("limits"));
    spec.paper = read_paper(root.section("paper"));
    spec.expect = read_expect(root.section("expect"));
    spec.timeouts = read_timeouts(root.section("timeouts"));

    root.finish();
    check_cross_fields(spec, root, default_limits);
    return spec;
}

}  // namespace

CaseSpec parse_case(std::string_view yaml_text, const std::filesystem::path& file_name,
                    const std::map<std::string, double>& default_limits) {
    CaseSpec spec = read_case(YamlSection::load_string(yaml_text, file_name.string()), file_name, default_limits);
    spec.source_text = std::string(yaml_text);
    return spec;
}

CaseSpec load_case_file(const std::filesystem::path& path, const std::map<std::string, double>& default_limits) {
    // Read once, by type and bounded (rig/config/file_access.h), then parsed from memory;
    // the text is kept for the trace.
    std::string text;
    try {
        text = read_regular_file(path, OpenOptions{.no_follow = false, .max_bytes = kMaxConfigFileBytes,
                                                   .what = "case file"});
    } catch (const FileAccessError& error) {
        throw ConfigError(SourceLocation{path.string(), 0, 0, "(file)"}, error.problem());
    }
    CaseSpec spec = read_case(YamlSection::load_string(text, path.string()), path, default_limits);
    spec.source_text = text;
    return spec;
}

namespace {

std::string location_text(const SourceLocation& where) {
    std::string text = where.file;
    if (where.line > 0) text += ":" + std::to_string(where.line) + ":" + std::to_string(where.column);
    return text;
}

}  // namespace

std::vector<std::string> duplicate_case_name_errors(const std::vector<CaseSpec>& specs) {
    std::vector<std::string> errors;
    std::unordered_map<std::string, std::size_t> first_with_name;
    for (std::size_t index = 0; index < specs.size(); ++index) {
        const auto [first, inserted] = first_with_name.emplace(specs[index].name, index);
        if (inserted) continue;
        const CaseSpec& earlier = specs[first->second];
        errors.push_back(ConfigError(specs[index].name_location,
                                     "case name '" + specs[index].name + "' is also the name of " +
                                         location_text(earlier.name_location) +
                                         "; one run writes each case to cases/NAME/ under --out, so the two "
                                         "would share a trace and a controller state: rename one")
                             .what());
    }
    return errors;
}

void check_case_timeline(const CaseSpec& spec, double case_end_s, double breakpoint_crossing_s) {
    const std::string length = number_text(case_end_s) + " s";
    const auto check = [&](double at_s, double for_s, const SourceLocation& at_where,
                           const SourceLocation& for_where, const char* what) {
        if (at_s < 0.0) {
            throw ConfigError(at_where, std::string(what) + " would start " + number_text(-at_s) +
                                            " s before the case does (at " + number_text(at_s) + " s)");
        }
        if (at_s >= case_end_s) {
            throw ConfigError(at_where, std::string(what) + " starts at " + number_text(at_s) +
                                            " s, after the case ends (" + length + ")");
        }
        if (for_s > case_end_s) {
            throw ConfigError(for_where, std::string(what) + " lasts " + number_text(for_s) +
                                             " s, longer than the whole case (" + length + ")");
        }
    };
    for (const GnssDropout& dropout : spec.gnss.dropouts) {
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
    for (const GnssDegraded& degraded : spec.gnss.degraded) {
        check(degraded.at_s, degraded.for_s, degraded.at_location, degraded.for_location, "the degraded episode");
    }
    for (std::size_t index = 0; index < spec.boom.lifts.size(); ++index) {
        const BoomLiftSpec& lift = spec.boom.lifts[index];
        check(lift.at_s, spec.boom.lift_duration_s(index), lift.at_location, lift.to_location, "the boom lift");
    }
    if (spec.rig_faults) {
        check(spec.rig_faults->master_stall_at_s, spec.rig_faults->master_stall_for_s, spec.rig_faults->at_location,
              spec.rig_faults->for_location, "the rig's stall");
    }
}

std::vector<std::filesystem::path> expand_case_paths(const std::vector<std::string>& args) {
    namespace fs = std::filesystem;
    std::vector<fs::path> paths;
    for (const std::string& arg : args) {
        const fs::path path(arg);
        std::error_code error;
        const fs::file_status status = fs::status(path, error);
        if (status.type() == fs::file_type::not_found) {
            throw ConfigError(SourceLocation{arg, 0, 0, "(file)"}, "no such case file or directory");
        }
        if (error) throw ConfigError(SourceLocation{arg, 0, 0, "(file)"}, "cannot access: " + error.message());
        if (status.type() != fs::file_type::directory) {
            paths.push_back(path);
            continue;
        }
        // Suites are folders of cases (cases/table3-fusion/...), so walk the tree;
        // hidden files and folders (.git, editor swap files) are skipped.
        std::vector<fs::path> cases;
        for (auto it = fs::recursive_directory_iterator(path, fs::directory_options::skip_permission_denied);
             it != fs::recursive_directory_iterator(); ++it) {
            const std::string file_name = it->path().filename().string();
            if (file_name.starts_with('.')) {
                if (it->is_directory()) it.disable_recursion_pending();
                continue;
            }
            const std::string extension = it->path().extension().string();
            if (extension != ".yaml" && extension != ".yml") continue;
            // A folder named like a case is walked into; anything else with a case's
            // name (a FIFO, a link to a device, a link loop) is kept, for
            // load_case_file to refuse by type, naming it, rather than skipped unsaid.
            std::error_code type_error;
            if (it->is_directory(type_error) && !type_error) continue;
            cases.push_back(it->path());
        }
        if (cases.empty()) {
            throw ConfigError(SourceLocation{arg, 0, 0, "(file)"}, "directory has no *.yaml or *.yml case files");
        }
        // Sorted by path below the directory: suite folder, then file name.
        std::sort(cases.begin(), cases.end(), [&path](const fs::path& a, const fs::path& b) {
            return a.lexically_relative(path).generic_string() < b.lexically_relative(path).generic_string();
        });
        paths.insert(paths.end(), cases.begin(), cases.end());
    }
    return paths;
}

ExpectSpec applied_expectation(const CaseSpec& spec, std::string* set_aside) {
    const bool expects = !spec.expect.fail.empty() || !spec.expect.error.empty();
    const bool reference =
        spec.controller.command.empty() && spec.controller.plugin.empty() && !spec.wiring.external_controller;
    if (!expects || reference || spec.expect.any_controller) return spec.expect;
    if (set_aside != nullptr) {
        // `fail` and `error` are exclusive (read_expect).
        std::string expected = spec.expect.error.empty() ? "failures of " : "an error, " + spec.expect.error;
        for (std::size_t index = 0; index < spec.expect.fail.size(); ++index) {
            expected += (index == 0 ? "" : ", ") + spec.expect.fail[index];
        }
        const std::string controller = spec.wiring.external_controller    ? std::string("an external board")
                                       : !spec.controller.command.empty() ? spec.controller.command.front()
                                                                          : spec.controller.plugin.string();
        *set_aside = "the case expects " + expected + " of the reference controller; it ran " + controller +
                     ", which is judged on the limits alone (expect.controller: any keeps the expectation)";
    }
    return ExpectSpec{};
}

}  // namespace rig::harness
