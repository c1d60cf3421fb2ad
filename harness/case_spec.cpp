#include "harness/case_spec.h"

#include "rig/lockstep.h"
#include "rig/modbus_protocol.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <fstream>
#include <optional>
#include <sstream>
#include <system_error>

namespace rig::harness {

namespace {

constexpr EnumChoice<RunMode> kRunModes[] = {
    {"lockstep", RunMode::lockstep},
    {"realtime", RunMode::realtime},
};
constexpr EnumChoice<Scenario> kScenarios[] = {
    {"breakpoint_identification", Scenario::breakpoint_identification},
    {"breakpoint_continuation", Scenario::breakpoint_continuation},
    {"static_flow", Scenario::static_flow},
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

bool is_case_name(std::string_view name) {
    return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '.' || c == '_' || c == '-';
    });
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

FieldSpec read_field(const YamlSection& section) {
    FieldSpec field;
    const YamlSection origin = section.required_section("origin");
    field.origin.lat_deg = origin.required_in_range<double>("lat_deg", Bounds::closed(-85, 85));
    field.origin.lon_deg = origin.required_in_range<double>("lon_deg", Bounds::closed(-180, 180));
    field.origin.height_m = origin.optional_in_range<double>("height_m", 0.0, Bounds::closed(-1000, 10000));
    field.heading_deg = section.required_in_range<double>("heading_deg", Bounds::closed_open(0, 360));
    return field;
}

// A static test has the vehicle standing: then its section is optional.
VehicleSpec read_vehicle(const YamlSection& section, bool standing) {
    VehicleSpec vehicle;
    if (standing) {
        vehicle.speed_km_h = section.optional_in_range<double>("speed_km_h", 0.0, Bounds::closed(0, 30));
        vehicle.start_m = section.optional<double>("start_m", 0.0);
        return vehicle;
    }
    vehicle.speed_km_h = section.required_in_range<double>("speed_km_h", Bounds::open_closed(0, 30));
    vehicle.accel_m_s2 = section.optional_in_range<double>("accel_m_s2", vehicle.accel_m_s2, Bounds::open_closed(0, 5));
    vehicle.start_m = section.required<double>("start_m");
    vehicle.overrun_m = section.optional_in_range<double>("overrun_m", vehicle.overrun_m, Bounds::at_least(0));
    vehicle.first_pass_m =
        section.optional_in_range<double>("first_pass_m", vehicle.first_pass_m, Bounds::open_closed(0, 1000));
    vehicle.wait_before_first_pass_s = section.optional_in_range<double>(
        "wait_before_first_pass_s", vehicle.wait_before_first_pass_s, Bounds::closed(0, 600));
    return vehicle;
}

BoomSpec read_boom(const YamlSection& section) {
    BoomSpec boom;
    boom.l1_m = section.optional_in_range<double>("l1_m", boom.l1_m, Bounds::at_least(0));
    boom.l2_m = section.optional_in_range<double>("l2_m", boom.l2_m, Bounds::at_least(0));
    boom.l3_m = section.optional_in_range<double>("l3_m", boom.l3_m, Bounds::at_least(0));
    boom.linkage_rise_m = section.optional_in_range<double>("linkage_rise_m", boom.linkage_rise_m, Bounds::at_least(0));
    return boom;
}

BreakpointSpec read_breakpoint(const YamlSection& section) {
    BreakpointSpec breakpoint;
    breakpoint.along_m = section.optional<double>("along_m", breakpoint.along_m);
    breakpoint.button_at_s =
        section.optional_in_range<double>("button_at_s", breakpoint.button_at_s, Bounds::greater_than(0));
    return breakpoint;
}

GnssSpec read_gnss(const YamlSection& section) {
    GnssSpec gnss;
    gnss.talker = section.optional_enum<GnssTalker>("talker", kTalkers, gnss.talker);
    gnss.rate_hz = section.optional_in_range<double>("rate_hz", gnss.rate_hz, Bounds::open_closed(0, 20));
    gnss.latency_s = section.optional_in_range<double>("latency_s", gnss.latency_s, Bounds::closed_open(0, 1));
    if (section.has("epoch_phase_s")) {
        gnss.epoch_phase_s = section.required_in_range<double>("epoch_phase_s", Bounds::closed_open(0, 1.0 / gnss.rate_hz));
    }
    gnss.fix = section.optional_enum<GnssFix>("fix", kFixes, gnss.fix);

    const YamlSection noise = section.section("noise");
    gnss.noise.base_m = noise.optional_in_range<double>("base_m", gnss.noise.base_m, Bounds::at_least(0));
    gnss.noise.ppm = noise.optional_in_range<double>("ppm", gnss.noise.ppm, Bounds::at_least(0));
    gnss.noise.baseline_km = noise.optional_in_range<double>("baseline_km", gnss.noise.baseline_km, Bounds::at_least(0));

    for (const YamlSection& item : section.list("dropouts")) {
        GnssDropout dropout;
        if (item.has("before_breakpoint_s")) {
            if (item.has("at_s")) item.fail("at_s", "give either at_s or before_breakpoint_s, not both");
            dropout.before_breakpoint_s = item.required_in_range<double>("before_breakpoint_s", Bounds::at_least(0));
        } else {
            dropout.at_s = item.required_in_range<double>("at_s", Bounds::at_least(0));
        }
        dropout.for_s = item.required_in_range<double>("for_s", Bounds::greater_than(0));
        gnss.dropouts.push_back(dropout);
    }
    for (const YamlSection& item : section.list("degraded")) {
        GnssDegraded degraded;
        degraded.at_s = item.required_in_range<double>("at_s", Bounds::at_least(0));
        degraded.for_s = item.required_in_range<double>("for_s", Bounds::greater_than(0));
        degraded.fix = item.optional_enum<GnssFix>("fix", kFixes, degraded.fix);
        degraded.sigma_m = item.required_in_range<double>("sigma_m", Bounds::at_least(0));
        gnss.degraded.push_back(degraded);
    }
    return gnss;
}

EncoderSpec read_encoder(const YamlSection& section) {
    EncoderSpec encoder;
    encoder.pulses_per_rev =
        section.optional_in_range<std::uint32_t>("pulses_per_rev", encoder.pulses_per_rev, Bounds::greater_than(0));
    encoder.wheel_diameter_m =
        section.optional_in_range<double>("wheel_diameter_m", encoder.wheel_diameter_m, Bounds::greater_than(0));
    encoder.rate_hz = section.optional_in_range<double>("rate_hz", encoder.rate_hz, Bounds::open_closed(0, 1000));
    encoder.slip_pct = section.optional_in_range<double>("slip_pct", encoder.slip_pct, Bounds::closed(-20, 20));
    encoder.slip_sd_pct = section.optional_in_range<double>("slip_sd_pct", encoder.slip_sd_pct, Bounds::at_least(0));
    encoder.deflection_pct =
        section.optional_in_range<double>("deflection_pct", encoder.deflection_pct, Bounds::closed_open(0, 20));
    encoder.terrain_sd_m_per_sqrt_m = section.optional_in_range<double>(
        "terrain_sd_m_per_sqrt_m", encoder.terrain_sd_m_per_sqrt_m, Bounds::closed(0, 1));
    return encoder;
}

HydraulicsSpec read_hydraulics(const YamlSection& section) {
    HydraulicsSpec h;
    h.pump_flow_l_min = section.optional_in_range<double>("pump_flow_l_min", h.pump_flow_l_min, Bounds::open_closed(0, 200));
    h.pump_pulsation_pct =
        section.optional_in_range<double>("pump_pulsation_pct", h.pump_pulsation_pct, Bounds::closed(0, 50));
    h.pump_pulsation_hz =
        section.optional_in_range<double>("pump_pulsation_hz", h.pump_pulsation_hz, Bounds::open_closed(0, 500));
    h.pipeline_time_constant_s = section.optional_in_range<double>("pipeline_time_constant_s",
                                                                   h.pipeline_time_constant_s, Bounds::open_closed(0, 10));
    const YamlSection valve = section.section("valve");
    h.valve_travel_s = valve.optional_in_range<double>("travel_s", h.valve_travel_s, Bounds::open_closed(0, 120));
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
    if (section.has("section_nozzles")) {
        h.section_nozzles.clear();
        const std::vector<std::string> counts = section.string_list("section_nozzles");
        for (std::size_t i = 0; i < counts.size(); ++i) {
            int nozzles = 0;
            const auto result = std::from_chars(counts[i].data(), counts[i].data() + counts[i].size(), nozzles);
            if (result.ec != std::errc{} || result.ptr != counts[i].data() + counts[i].size() || nozzles < 1 ||
                nozzles > 64) {
                throw ConfigError(section.item_location("section_nozzles", i),
                                  "a section's nozzle count must be a whole number in [1, 64], got '" + counts[i] + "'");
            }
            h.section_nozzles.push_back(nozzles);
        }
        if (h.section_nozzles.empty() || h.section_nozzles.size() > 8) {
            section.fail("section_nozzles", "must list 1 to 8 sections");
        }
    }
    h.boom_width_m = section.optional_in_range<double>("boom_width_m", h.boom_width_m, Bounds::open_closed(0, 60));
    h.section_valve_open_s =
        section.optional_in_range<double>("section_valve_open_s", h.section_valve_open_s, Bounds::closed(0, 5));
    h.section_valve_close_s =
        section.optional_in_range<double>("section_valve_close_s", h.section_valve_close_s, Bounds::closed(0, 5));
    h.droplet_fall_s = section.optional_in_range<double>("droplet_fall_s", h.droplet_fall_s, Bounds::closed(0, 2));
    h.min_nozzle_flow_l_min =
        section.optional_in_range<double>("min_nozzle_flow_l_min", h.min_nozzle_flow_l_min, Bounds::open_closed(0, 20));
    return h;
}

FlowMeterSpec read_flow_meter(const YamlSection& section) {
    FlowMeterSpec meter;
    meter.pulses_per_l = section.optional_in_range<double>("pulses_per_l", meter.pulses_per_l, Bounds::open_closed(0, 1e5));
    meter.k_factor_error_pct =
        section.optional_in_range<double>("k_factor_error_pct", meter.k_factor_error_pct, Bounds::closed(-50, 50));
    meter.rate_hz = section.optional_in_range<double>("rate_hz", meter.rate_hz, Bounds::open_closed(0, 1000));
    return meter;
}

PumpSensorSpec read_pump_sensor(const YamlSection& section) {
    PumpSensorSpec sensor;
    sensor.full_scale_m3_h =
        section.optional_in_range<double>("full_scale_m3_h", sensor.full_scale_m3_h, Bounds::open_closed(0, 1000));
    sensor.noise_mv = section.optional_in_range<double>("noise_mv", sensor.noise_mv, Bounds::closed(0, 1000));
    sensor.offset_ma = section.optional_in_range<double>("offset_ma", sensor.offset_ma, Bounds::closed(-4, 16));
    sensor.rate_hz = section.optional_in_range<double>("rate_hz", sensor.rate_hz, Bounds::open_closed(0, 1000));
    return sensor;
}

BoomHeightSensorSpec read_boom_height_sensor(const YamlSection& section) {
    BoomHeightSensorSpec sensor;
    sensor.range_m = section.optional_in_range<double>("range_m", sensor.range_m, Bounds::open_closed(0, 10));
    sensor.rate_hz = section.optional_in_range<double>("rate_hz", sensor.rate_hz, Bounds::open_closed(0, 1000));
    return sensor;
}

DepositionSpec read_deposition(const YamlSection& section) {
    DepositionSpec deposition;
    deposition.cell_m = section.optional_in_range<double>("cell_m", deposition.cell_m, Bounds::closed(0.005, 1));
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

WiringSpec read_wiring(const YamlSection& section) {
    WiringSpec wiring;
    wiring.gnss = section.optional_enum<GnssWire>("gnss", kGnssWires, wiring.gnss);
    wiring.board_io = section.optional_enum<BoardIoWireKind>("board_io", kBoardIoWires, wiring.board_io);
    wiring.gnss_port = section.optional<std::string>("gnss_port", wiring.gnss_port);
    wiring.nmea_baud = section.optional_in_range<int>("nmea_baud", wiring.nmea_baud, Bounds::closed(1200, 4000000));
    wiring.modbus_port = section.optional<std::string>("modbus_port", wiring.modbus_port);
    wiring.modbus_baud = section.optional_in_range<int>("modbus_baud", wiring.modbus_baud, Bounds::closed(1200, 4000000));
    wiring.modbus_tcp = section.optional<std::string>("modbus_tcp", wiring.modbus_tcp);
    wiring.hid_vid = static_cast<std::uint16_t>(
        section.optional_in_range<std::uint32_t>("hid_vid", wiring.hid_vid, Bounds::closed(0, 0xFFFF)));
    wiring.hid_pid = static_cast<std::uint16_t>(
        section.optional_in_range<std::uint32_t>("hid_pid", wiring.hid_pid, Bounds::closed(0, 0xFFFF)));
    wiring.board_update_hz =
        section.optional_in_range<double>("board_update_hz", wiring.board_update_hz, Bounds::closed(1, 2000));
    wiring.external_controller = section.optional_enum<bool>("controller", kControllerPlaces, wiring.external_controller);
    if (wiring.gnss_port.empty()) section.fail("gnss_port", "must be 'pty' or a serial device path");
    if (wiring.modbus_port.empty()) section.fail("modbus_port", "must be 'pty' or a serial device path");
    return wiring;
}

StaticFlowSpec read_static_flow(const YamlSection& section) {
    StaticFlowSpec static_flow;
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
    }
    // The harness judges flow against the target the controller is given.
    if (section.has("target_flow_l_min")) {
        controller.target_flow_l_min =
            section.required_in_range<double>("target_flow_l_min", Bounds::open_closed(0, 250));
    }
    return controller;
}

std::map<std::string, double> read_limits(const YamlSection& section) {
    std::map<std::string, double> limits;
    for (const std::string& name : section.keys()) {
        if (const std::string problem = metric_name_problem(name); !problem.empty()) {
            throw ConfigError(section.key_location(name), problem);
        }
        limits[name] = section.required<double>(name);
    }
    return limits;
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
    return expect;
}

TimeoutsSpec read_timeouts(const YamlSection& section) {
    TimeoutsSpec timeouts;
    timeouts.node_ack_s =
        section.optional_in_range<double>("node_ack_s", timeouts.node_ack_s, Bounds::open_closed(0, 600));
    timeouts.case_wall_s =
        section.optional_in_range<double>("case_wall_s", timeouts.case_wall_s, Bounds::open_closed(0, 86400));
    return timeouts;
}

// Checks between sections; run after finish(), when every value is real.
void check_cross_fields(const CaseSpec& spec, const YamlSection& root,
                        const std::map<std::string, double>& default_limits) {
    if (spec.scenario != Scenario::static_flow && !(spec.vehicle.start_m < spec.breakpoint.along_m)) {
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
    if (spec.wiring.uses_bench_wire() && spec.mode != RunMode::realtime) {
        root.section("wiring").fail("serial, Modbus and HID wires have no virtual time: set `mode: realtime`");
    }
    if (spec.wiring.external_controller && !spec.wiring.uses_bench_wire()) {
        root.section("wiring").fail("controller", "an external controller needs a bench wire (gnss: serial, board_io: ...)");
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
        if (!spec.limits.contains(metric) &&
            !(default_limits.contains(metric) && default_limit_applies(spec.scenario, metric))) {
            throw ConfigError(expect.item_location("fail", index),
                              "'" + metric + "' has no limit; expected failures must name limited metrics "
                              "(limits in this file or the defaults)");
        }
        for (std::size_t earlier = 0; earlier < index; ++earlier) {
            if (spec.expect.fail[earlier] == metric) {
                throw ConfigError(expect.item_location("fail", index), "'" + metric + "' is listed twice");
            }
        }
    }
}

}  // namespace

std::string_view to_string(RunMode mode) { return name_of(kRunModes, mode); }
std::string_view to_string(Scenario scenario) { return name_of(kScenarios, scenario); }
std::string_view to_string(GnssWire wire) { return name_of(kGnssWires, wire); }
std::string_view to_string(BoardIoWireKind wire) { return name_of(kBoardIoWires, wire); }

bool default_limit_applies(Scenario scenario, const std::string& metric) {
    const bool identifies = scenario != Scenario::static_flow;
    const bool sprays = scenario != Scenario::breakpoint_identification;
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
        if (default_limit_applies(spec.scenario, name)) limits[name] = limit;
    }
    for (const auto& [name, limit] : spec.limits) limits[name] = limit;
    return limits;
}

namespace {

CaseSpec read_case(const YamlSection& root, const std::filesystem::path& source_path,
                   const std::map<std::string, double>& default_limits) {
    CaseSpec spec;
    spec.source_path = source_path;

    spec.name = root.required<std::string>("name");
    if (root.has("name") && !is_case_name(spec.name)) {
        root.fail("name", "must be letters, digits, '.', '_' or '-' (it names output files), got '" + spec.name + "'");
    }
    spec.description = root.optional<std::string>("description", "");
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
    spec.mode = root.optional_enum<RunMode>("mode", kRunModes, spec.mode);
    spec.scenario = root.optional_enum<Scenario>("scenario", kScenarios, spec.scenario);
    spec.utc_start_iso = root.optional<std::string>("utc_start", spec.utc_start_iso);
    const auto utc_start = parse_utc(spec.utc_start_iso);
    if (!utc_start) {
        root.fail("utc_start", "expected an ISO-8601 UTC time like 2023-07-15T02:00:00Z, got '" +
                                   spec.utc_start_iso + "'");
    }
    spec.utc_start = *utc_start;

    spec.field = read_field(root.required_section("field"));
    const bool standing = spec.scenario == Scenario::static_flow;
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
    spec.wiring = read_wiring(root.section("wiring"));
    spec.controller = read_controller(root);
    spec.limits = read_limits(root.section("limits"));
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
    CaseSpec spec = read_case(YamlSection::load_file(path), path, default_limits);
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    spec.source_text = text.str();
    return spec;
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
            if ((extension != ".yaml" && extension != ".yml") || !it->is_regular_file()) continue;
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

}  // namespace rig::harness
