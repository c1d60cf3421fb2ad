#include "harness/case_runner.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>
#include <thread>

#include <yaml-cpp/yaml.h>

#include "controller/controller_config.h"
#include "emulators/boom_height_sensor.h"
#include "emulators/flow_meter_kf11.h"
#include "emulators/panel_switch.h"
#include "emulators/pump_flow_sensor.h"
#include "emulators/spray_circuit.h"
#include "emulators/spray_circuit_node.h"
#include "emulators/gnss_g970.h"
#include "emulators/plant.h"
#include "emulators/seeded_random.h"
#include "emulators/wheel_encoder.h"
#include "harness/metrics.h"
#include "harness/trace_recorder.h"
#include "idl/topics.h"
#include "rig/child_process.h"
#include "rig/domain_lease.h"
#include "rig/lockstep.h"
#include "rig/pty_pair.h"
#include "rig/realtime.h"
#include "rig/wire_adapters.h"

namespace rig::harness {

namespace {

// How the case's scenario becomes a route (seed 000 sec. 2.5.1, 2.5.2):
//   breakpoint_*: the first pass drives first_pass_m up to the breakpoint and
//   stops with the nozzle line on it; the operator presses the button; the
//   sprayer turns at the headland (not simulated: it reappears at start_m) and
//   approaches the breakpoint again, driving overrun_m past it.
//   static_flow: the sprayer stands at the breakpoint; the spray switch goes on
//   at spray_on_at_s for spray_for_s (sec. 2.4's static tests).
constexpr double kStandAfterButtonS = 1.0;
constexpr double kStandBeforeApproachS = 2.0;
constexpr double kStandAfterStaticS = 3.0;
constexpr double kVehicleTruthRateHz = 20.0;
constexpr double kHydraulicsTruthRateHz = 100.0;
constexpr double kForeverS = 1e6;


ScenarioPlan build_scenario(const CaseSpec& spec, const emulators::BoomGeometry& boom) {
    const double bp = spec.breakpoint.along_m;
    ScenarioPlan scenario;
    if (spec.scenario == Scenario::static_flow) {
        scenario.start_along_m = bp;
        scenario.route.push_back(emulators::StandPhase{spec.static_flow.spray_on_at_s + spec.static_flow.spray_for_s +
                                                       kStandAfterStaticS});
        scenario.spray_switch.push_back({spec.static_flow.spray_on_at_s, spec.static_flow.spray_for_s});
        return scenario;
    }
    const double cruise_m_s = spec.vehicle.speed_km_h / 3.6;
    scenario.start_along_m = bp - spec.vehicle.first_pass_m;
    if (spec.vehicle.wait_before_first_pass_s > 0.0) {
        scenario.route.push_back(emulators::StandPhase{spec.vehicle.wait_before_first_pass_s});
    }
    scenario.route.push_back(emulators::DrivePhase{bp, cruise_m_s, spec.vehicle.accel_m_s2});
    const double stop_s = emulators::VehiclePlant(scenario.route, boom, scenario.start_along_m).end_time_s();
    const double button_at_s = stop_s + spec.breakpoint.button_at_s;
    scenario.button.push_back({button_at_s, 0.2});
    scenario.approach_starts_s = button_at_s + kStandAfterButtonS;
    scenario.route.push_back(emulators::StandPhase{spec.breakpoint.button_at_s + kStandAfterButtonS});
    scenario.route.push_back(emulators::RepositionPhase{spec.vehicle.start_m});
    scenario.route.push_back(emulators::StandPhase{kStandBeforeApproachS});
    scenario.route.push_back(
        emulators::DrivePhase{bp + spec.vehicle.overrun_m, cruise_m_s, spec.vehicle.accel_m_s2});
    if (spec.scenario == Scenario::breakpoint_continuation) scenario.spray_switch.push_back({0.0, kForeverS});
    return scenario;
}

emulators::SprayCircuitParams circuit_params(const CaseSpec& spec, double grid_from_m, double grid_to_m) {
    const HydraulicsSpec& h = spec.hydraulics;
    emulators::SprayCircuitParams params;
    params.pump_flow_l_min = h.pump_flow_l_min;
    params.pump_pulsation_pct = h.pump_pulsation_pct;
    params.pump_pulsation_hz = h.pump_pulsation_hz;
    params.valve = emulators::BallValveParams{h.valve_travel_s, h.valve_motor_start_delay_s, h.valve_backlash_pct,
                                              h.valve_initial_opening_pct};
    params.flow_map.interpolation_bulge_pct = h.interpolation_bulge_pct;
    params.flow_map.calibration_drift_pct = h.calibration_drift_pct;
    params.pipeline_time_constant_s = h.pipeline_time_constant_s;
    params.section_nozzles = h.section_nozzles;
    params.boom_width_m = h.boom_width_m;
    params.section_valve_open_s = h.section_valve_open_s;
    params.section_valve_close_s = h.section_valve_close_s;
    params.droplet_fall_s = h.droplet_fall_s;
    params.min_nozzle_flow_l_min = h.min_nozzle_flow_l_min;
    params.deposition.from_along_m = grid_from_m;
    params.deposition.to_along_m = grid_to_m;
    params.deposition.cell_along_m = spec.deposition.cell_m;
    params.deposition.footprint_along_m = spec.deposition.footprint_m;
    return params;
}

emulators::GnssFixKind to_fix_kind(GnssFix fix) {
    switch (fix) {
        case GnssFix::rtk_fixed: return emulators::GnssFixKind::rtk_fixed;
        case GnssFix::rtk_float: return emulators::GnssFixKind::rtk_float;
        case GnssFix::dgps: return emulators::GnssFixKind::dgps;
        case GnssFix::autonomous: return emulators::GnssFixKind::autonomous;
    }
    return emulators::GnssFixKind::rtk_fixed;
}

emulators::G970Params gnss_params(const CaseSpec& spec, std::uint64_t seed, double breakpoint_crossing_s) {
    emulators::G970Params params;
    std::string talker(to_string(spec.gnss.talker));
    std::transform(talker.begin(), talker.end(), talker.begin(), [](unsigned char c) { return std::toupper(c); });
    params.talker = talker;
    params.rate_hz = spec.gnss.rate_hz;
    params.latency_s = spec.gnss.latency_s;
    params.epoch_phase_s =
        spec.gnss.epoch_phase_s.value_or(emulators::SeededRandom(seed, "gnss_g970.epoch_phase").uniform01() /
                                         spec.gnss.rate_hz);
    params.fix = to_fix_kind(spec.gnss.fix);
    params.noise_base_m = spec.gnss.noise.base_m;
    params.noise_ppm = spec.gnss.noise.ppm;
    params.baseline_km = spec.gnss.noise.baseline_km;
    for (const GnssDropout& dropout : spec.gnss.dropouts) {
        const double at_s =
            dropout.before_breakpoint_s ? breakpoint_crossing_s - *dropout.before_breakpoint_s : dropout.at_s;
        params.dropouts.push_back(emulators::GnssEpisode{at_s, dropout.for_s});
    }
    for (const GnssDegraded& degraded : spec.gnss.degraded) {
        params.degraded.push_back(
            emulators::GnssEpisode{degraded.at_s, degraded.for_s, to_fix_kind(degraded.fix), degraded.sigma_m});
    }
    // UTC of sim time 0, from the case's utc_start.
    const auto start_day = std::chrono::floor<std::chrono::days>(spec.utc_start);
    const std::chrono::year_month_day ymd{start_day};
    params.utc_year = static_cast<int>(ymd.year());
    params.utc_month = static_cast<int>(static_cast<unsigned>(ymd.month()));
    params.utc_day = static_cast<int>(static_cast<unsigned>(ymd.day()));
    params.utc_start_seconds_of_day =
        std::chrono::duration<double>(spec.utc_start - std::chrono::sys_time<std::chrono::nanoseconds>(start_day))
            .count();
    params.seed = seed;
    return params;
}

}  // namespace

CaseWorld build_case_world(const CaseSpec& spec, std::uint64_t seed) {
    emulators::PlantParams plant_params;
    plant_params.origin_lat_deg = spec.field.origin.lat_deg;
    plant_params.origin_lon_deg = spec.field.origin.lon_deg;
    plant_params.origin_height_m = spec.field.origin.height_m;
    plant_params.heading_deg = spec.field.heading_deg;
    plant_params.boom =
        emulators::BoomGeometry{spec.boom.l1_m, spec.boom.l2_m, spec.boom.l3_m, spec.boom.linkage_rise_m};
    ScenarioPlan scenario = build_scenario(spec, plant_params.boom);
    plant_params.route = scenario.route;
    plant_params.start_nozzle_line_along_m = scenario.start_along_m;
    plant_params.wheel.slip_pct = spec.encoder.slip_pct;
    plant_params.wheel.slip_sd_pct = spec.encoder.slip_sd_pct;
    plant_params.wheel.deflection_pct = spec.encoder.deflection_pct;
    plant_params.wheel.terrain_sd_m_per_sqrt_m = spec.encoder.terrain_sd_m_per_sqrt_m;
    plant_params.seed = seed;
    emulators::Plant plant(plant_params);
    const double crossing_s = spec.scenario == Scenario::static_flow
                                  ? std::numeric_limits<double>::quiet_NaN()
                                  : plant.vehicle().time_when_nozzle_line_reaches(spec.breakpoint.along_m,
                                                                                  scenario.approach_starts_s);
    const TimeNs end_ns = seconds_to_ns(plant.vehicle().end_time_s() + 1.0);
    emulators::G970Params gnss = gnss_params(spec, seed, crossing_s);
    return CaseWorld{std::move(plant), std::move(scenario), std::move(gnss), crossing_s, end_ns};
}

namespace {

// The controller's parameters as their own YAML file (the case section minus `command`).
void write_controller_config(const CaseSpec& spec, const std::filesystem::path& file) {
    YAML::Node section = spec.controller.params.present ? YAML::Clone(spec.controller.params.node) : YAML::Node();
    if (section.IsMap()) section.remove("command");
    YAML::Emitter out;
    out << section;
    std::ofstream(file) << "# the `controller:` section of " << spec.source_path.string() << "\n"
                        << (section.IsNull() ? "{}" : out.c_str()) << "\n";
}

std::string log_tail(const std::filesystem::path& log, std::size_t max_lines = 6) {
    std::ifstream in(log);
    std::vector<std::string> lines;
    std::string line;
    while (std::getline(in, line)) {
        lines.push_back(line);
        if (lines.size() > max_lines) lines.erase(lines.begin());
    }
    std::string tail;
    for (const auto& kept : lines) tail += "\n    | " + kept;
    return tail;
}

// SCHED_FIFO priority the harness asks for in real-time runs (the controller asks for 40).
constexpr int kRealtimePriority = 50;

// The rig's ends of the bench wires a case asks for, and what the controller
// process must be told to use the far ends.
struct BenchWires {
    std::unique_ptr<PtyPair> gnss_pty;
    std::unique_ptr<SerialPort> gnss_device;
    SerialPort* gnss_port = nullptr;          // the rig writes NMEA here
    std::unique_ptr<PtyLink> modbus_link;
    std::unique_ptr<BoardIoWire> board_io;
    std::vector<std::string> controller_args;
    std::string description = "dds";
};

BenchWires open_bench_wires(const CaseSpec& spec) {
    BenchWires wires;
    const WiringSpec& wiring = spec.wiring;
    std::vector<std::string> parts;
    if (wiring.gnss == GnssWire::serial) {
        SerialSettings line;
        line.baud = wiring.nmea_baud;
        std::string far_end;
        if (wiring.gnss_port == "pty") {
            wires.gnss_pty = std::make_unique<PtyPair>(PtyOptions{line, {}});
            wires.gnss_port = &wires.gnss_pty->master();
            far_end = wires.gnss_pty->slave_path();
        } else {
            wires.gnss_device = std::make_unique<SerialPort>(wiring.gnss_port, line);
            wires.gnss_port = wires.gnss_device.get();
            far_end = wiring.gnss_port;
        }
        wires.controller_args.insert(wires.controller_args.end(),
                                     {"--nmea-serial", far_end, "--nmea-baud", std::to_string(wiring.nmea_baud)});
        parts.push_back("gnss serial " + far_end + " " + std::to_string(wiring.nmea_baud) + " baud");
    } else {
        parts.push_back("gnss dds");
    }
    switch (wiring.board_io) {
        case BoardIoWireKind::dds: parts.push_back("board_io dds"); break;
        case BoardIoWireKind::modbus_rtu: {
            modbus::RtuSlaveOptions options;
            options.line.baud = wiring.modbus_baud;
            std::string far_end = wiring.modbus_port;
            if (wiring.modbus_port == "pty") {
                wires.modbus_link = std::make_unique<PtyLink>();
                options.line.device = wires.modbus_link->slave_path_a();
                far_end = wires.modbus_link->slave_path_b();
            } else {
                options.line.device = wiring.modbus_port;
            }
            wires.board_io = std::make_unique<ModbusSlaveWire>(options);
            wires.controller_args.insert(wires.controller_args.end(), {"--modbus-rtu", far_end, "--modbus-baud",
                                                                       std::to_string(wiring.modbus_baud)});
            parts.push_back("board_io modbus_rtu " + far_end + " " + std::to_string(wiring.modbus_baud) + " baud");
            break;
        }
        case BoardIoWireKind::modbus_tcp: {
            modbus::TcpSlaveOptions options;
            const modbus::TcpEndpoint endpoint = modbus::parse_tcp_endpoint(wiring.modbus_tcp);
            options.bind_address = endpoint.address;
            options.port = endpoint.port;
            auto wire = std::make_unique<ModbusSlaveWire>(options);
            const std::string address = endpoint.address + ":" + std::to_string(wire->slave().tcp_port());
            wires.controller_args.insert(wires.controller_args.end(), {"--modbus-tcp", address});
            parts.push_back("board_io modbus_tcp " + address);
            wires.board_io = std::move(wire);
            break;
        }
        case BoardIoWireKind::hid: {
            // A real bench board; the controller is wired to it, not to the rig process.
            auto transport = HidapiTransport::open(wiring.hid_vid, wiring.hid_pid);
            const std::string description = transport->description();
            wires.board_io = std::make_unique<HidBoardWire>(std::make_unique<HidBoard>(std::move(transport)), description);
            parts.push_back("board_io hid " + description);
            break;
        }
    }
    wires.description.clear();
    for (const std::string& part : parts) wires.description += (wires.description.empty() ? "" : ", ") + part;
    return wires;
}

}  // namespace

void validate_for_run(const CaseSpec& spec, const RunOptions& /*options*/) {
    // The reference controller's own keys are checked before anything starts; a
    // case naming another controller leaves its section to that controller.
    if (spec.controller.command.empty()) {
        controller::parse_controller_config(YamlSection(spec.controller.params));
    }
}

namespace {

// The section-valve commands in the trace, as (time, mask).
std::vector<std::pair<TimeNs, std::uint16_t>> section_commands(const TraceRecorder& trace) {
    std::vector<std::pair<TimeNs, std::uint16_t>> commands;
    for (const auto& [t, sample] : trace.samples(topics::kSectionValves)) {
        commands.emplace_back(t, sample.at("open_mask").get<std::uint16_t>());
    }
    return commands;
}

// The regulation episode the flow metrics judge: in a continuation, the first
// opening after the headland turn; in a static test, the first opening.
std::optional<FlowEpisode> judged_episode(const TraceRecorder& trace, TimeNs from_ns, TimeNs end_ns) {
    std::optional<FlowEpisode> episode;
    std::uint16_t previous = 0;
    for (const auto& [t, mask] : section_commands(trace)) {
        if (!episode && t >= from_ns && mask != 0 && previous == 0) episode = FlowEpisode{t, end_ns};
        if (episode && t > episode->open_command_ns && mask == 0) {
            episode->end_ns = t;
            break;
        }
        previous = mask;
    }
    return episode;
}

std::vector<MainFlowSample> main_flow_samples(const TraceRecorder& trace) {
    std::vector<MainFlowSample> samples;
    for (const auto& [t, sample] : trace.samples(topics::kHydraulicsTruth)) {
        samples.push_back(MainFlowSample{t, sample.at("main_flow_l_min").get<double>()});
    }
    return samples;
}

// Table 1 from truth: section-open command -> valves open -> first droplets land.
void add_spray_timing_metrics(const TraceRecorder& trace, const emulators::SprayCircuit& circuit,
                              std::map<std::string, double>& metrics) {
    const auto commands = section_commands(trace);
    const auto first_open = std::find_if(commands.begin(), commands.end(), [](const auto& c) { return c.second != 0; });
    if (first_open == commands.end()) return;
    for (const auto& [t, sample] : trace.samples(topics::kHydraulicsTruth)) {
        if (t >= first_open->first && sample.at("sections_spraying_mask").get<int>() != 0) {
            metrics["section_valve_open_delay_s"] = ns_to_seconds(t - first_open->first);
            break;
        }
    }
    for (const emulators::LandingEdge& edge : circuit.landing_edges()) {
        if (edge.landing && edge.at_ns >= first_open->first) {
            metrics["spray_landing_delay_s"] = ns_to_seconds(edge.at_ns - first_open->first);
            break;
        }
    }
}

// Fig. 14: main flow (truth) and the controller's Eq. 3 reading, against the
// nozzle line's distance to the breakpoint, around the judged episode.
void add_flow_figure(const TraceRecorder& trace, const emulators::Plant& plant, const FlowEpisode& episode,
                     double breakpoint_along_m, CaseFigures& figures) {
    const TimeNs from_ns = episode.open_command_ns - seconds_to_ns(1.0);
    const TimeNs to_ns = std::min(episode.end_ns, episode.open_command_ns + seconds_to_ns(8.0));
    std::map<TimeNs, double> measured;
    for (const auto& [t, status] : trace.samples(topics::kControllerStatus)) {
        if (t >= from_ns && t <= to_ns && status.at("measured_flow_l_min").is_number()) {
            measured[t] = status.at("measured_flow_l_min").get<double>();
        }
    }
    for (const auto& [t, sample] : trace.samples(topics::kHydraulicsTruth)) {
        if (t < from_ns || t > to_ns) continue;
        FlowSample point;
        point.t_s = ns_to_seconds(t);
        point.distance_to_breakpoint_m = plant.truth_at(t).nozzle_line_along_m() - breakpoint_along_m;
        point.main_flow_l_min = sample.at("main_flow_l_min").get<double>();
        if (const auto it = measured.find(t); it != measured.end()) point.measured_flow_l_min = it->second;
        figures.flow.push_back(point);
    }
}

// Fig. 15: dose per row across the breakpoint, by pass, with the judged areas.
void add_dose_figure(const DoseProfile& profile, const DepositionResult& deposition, double breakpoint_along_m,
                     double window_m, CaseFigures& figures) {
    double from_m = breakpoint_along_m - 2.0 * window_m;
    double to_m = breakpoint_along_m + 2.0 * window_m;
    for (const AreaSpan& area : deposition.areas) {
        from_m = std::min(from_m, area.from_along_m - 1.0);
        to_m = std::max(to_m, area.to_along_m + 1.0);
    }
    const std::size_t rows = std::max(profile.first_pass.size(), profile.continuation.size());
    for (std::size_t row = 0; row < rows; ++row) {
        const double along_m = profile.row_centre_m(row);
        if (along_m < from_m || along_m > to_m) continue;
        figures.dose.push_back(DoseSample{along_m, row < profile.first_pass.size() ? profile.first_pass[row] : 0.0,
                                          row < profile.continuation.size() ? profile.continuation[row] : 0.0});
    }
    figures.areas = deposition.areas;
}

DoseProfile dose_profile(const emulators::DepositionGrid& grid) {
    DoseProfile profile;
    profile.first_row_centre_m = grid.row_centre_m(0);
    profile.row_m = grid.params().cell_along_m;
    profile.first_pass = grid.row_mean_dose_ul_cm2(0);
    profile.continuation = grid.row_mean_dose_ul_cm2(1);
    return profile;
}

}  // namespace

CaseRun run_case(const CaseSpec& spec, const RunOptions& options) {
    const WallStopwatch wall;
    CaseRun run;
    CaseResult& result = run.result;
    CaseFigures& figures = run.figures;
    result.name = spec.name;
    result.file = spec.source_path.string();
    result.seed = options.seed_override.value_or(spec.seed);
    result.limits = effective_limits(spec);
    const std::filesystem::path case_dir = options.out_dir / "cases" / spec.name;

    try {
        std::filesystem::remove_all(case_dir);
        std::filesystem::create_directories(case_dir / "controller-state");

        const CaseWorld world = build_case_world(spec, result.seed);
        const emulators::Plant& plant = world.plant;
        const ScenarioPlan& scenario = world.scenario;
        const bool static_test = spec.scenario == Scenario::static_flow;
        const TimeNs end_ns = world.end_ns;
        // The deposition grid spans everything the boom can reach, with a margin.
        const double grid_from_m = std::min(scenario.start_along_m, spec.vehicle.start_m) - 5.0;
        const double grid_to_m = spec.breakpoint.along_m + spec.vehicle.overrun_m + 5.0;
        emulators::SprayCircuit circuit(plant, circuit_params(spec, grid_from_m, grid_to_m));

        // The bench wires (real time only) come first: the controller is given their far ends.
        BenchWires wires = open_bench_wires(spec);
        result.mode = std::string(to_string(spec.mode));
        result.wiring = wires.description;

        // The controller under test, in its own process on this run's own domain
        // (none when a real board is wired up: `wiring: { controller: external }`).
        const DomainLease lease = DomainLease::acquire();
        write_controller_config(spec, case_dir / "controller.yaml");
        std::vector<std::string> argv = spec.controller.command;
        if (argv.empty()) argv.push_back(options.controller_executable.string());
        for (const std::string& arg :
             {std::string("--domain"), std::to_string(lease.domain_id()), std::string("--node-name"),
              std::string("controller"), std::string("--config"), (case_dir / "controller.yaml").string(),
              std::string("--state-dir"), (case_dir / "controller-state").string()}) {
            argv.push_back(arg);
        }
        if (spec.mode == RunMode::realtime) {
            argv.insert(argv.end(), {"--clock", "realtime"});
            argv.insert(argv.end(), wires.controller_args.begin(), wires.controller_args.end());
        }
        const std::filesystem::path controller_log = case_dir / "controller.log";
        std::optional<ChildProcess> controller;
        if (!spec.wiring.external_controller) controller.emplace(argv, controller_log);
        auto stop_controller = [&](std::chrono::milliseconds grace) {
            return controller ? controller->stop(grace) : std::string("process exited with status 0");
        };

        DdsContext dds(lease.domain_id(), "harness");
        TraceRecorder trace(dds, case_dir / "trace.sqlite");
        // Nodes hold DDS writers, so they are declared after (and destroyed before) the context.
        emulators::PlantNode plant_node(plant, kVehicleTruthRateHz);
        emulators::SprayCircuitNode circuit_node(circuit, kHydraulicsTruthRateHz);
        emulators::GnssG970 gnss(plant, world.gnss);
        emulators::WheelEncoder encoder(
            plant, emulators::WheelEncoderParams{spec.encoder.pulses_per_rev, spec.encoder.wheel_diameter_m,
                                                 spec.encoder.rate_hz});
        emulators::FlowMeterKf11 flow_meter(
            circuit, emulators::Kf11Params{spec.flow_meter.pulses_per_l, spec.flow_meter.k_factor_error_pct, 0.27,
                                           spec.flow_meter.rate_hz});
        emulators::PumpFlowSensor pump_sensor(
            circuit, emulators::PumpFlowSensorParams{spec.pump_sensor.full_scale_m3_h, spec.pump_sensor.noise_mv,
                                                     spec.pump_sensor.offset_ma, spec.pump_sensor.rate_hz, result.seed});
        emulators::BoomHeightSensor boom_height(
            plant, emulators::BoomHeightSensorParams{spec.boom_height_sensor.range_m, spec.boom_height_sensor.rate_hz});
        emulators::PanelSwitch button("breakpoint_button", topics::kBreakpointButton, scenario.button);
        emulators::PanelSwitch spray_switch("spray_switch", topics::kSpraySwitch, scenario.spray_switch);
        // Local nodes step in this order each instant: plant truth and the spray
        // circuit (which takes the actuator commands) before the devices sample
        // them, and the wire adapters last (they carry what the devices published).
        std::vector<Node*> local_nodes{&plant_node, &circuit_node, &gnss,        &encoder,     &flow_meter,
                                       &pump_sensor, &boom_height, &button,      &spray_switch};
        std::optional<NmeaSerialAdapter> nmea_adapter;
        if (wires.gnss_port) local_nodes.push_back(&nmea_adapter.emplace(*wires.gnss_port));
        std::optional<BoardIoAdapter> board_adapter;
        if (wires.board_io) local_nodes.push_back(&board_adapter.emplace(*wires.board_io, spec.wiring.board_update_hz));

        trace.set_meta("case", spec.name);
        trace.set_meta("case_file", spec.source_path.string());
        trace.set_meta("scenario", std::string(to_string(spec.scenario)));
        trace.set_meta("mode", result.mode);
        trace.set_meta("seed", std::to_string(result.seed));
        trace.set_meta("controller_command", controller ? controller->command_line() : "external (a wired board)");
        trace.set_meta("wiring", wires.description);

        LockstepTimeouts timeouts;
        timeouts.ack = std::chrono::milliseconds(static_cast<long>(spec.timeouts.node_ack_s * 1000));
        auto liveness = [&controller] { return controller->exit_description(); };
        auto wall_bound = [&] {
            if (wall.elapsed_s() > spec.timeouts.case_wall_s) {
                throw NodeFailure("harness", "case exceeded its wall-time bound of " +
                                                 std::to_string(spec.timeouts.case_wall_s) + " s");
            }
        };
        if (spec.mode == RunMode::lockstep) {
            LockstepMaster master(dds, timeouts);
            for (Node* node : local_nodes) master.add_local_node(*node);
            master.add_remote_node("controller", liveness);
            master.set_after_round([&trace](TimeNs t, int round) { trace.drain(t, round); });
            try {
                master.start();
                result.startup_wall_seconds = wall.elapsed_s();
                while (master.advance(end_ns)) wall_bound();
                master.shutdown();
                const std::string ended = stop_controller(std::chrono::milliseconds(3000));
                if (ended != "process exited with status 0") throw NodeFailure("controller", "after shutdown: " + ended);
            } catch (const NodeFailure& failure) {
                master.shutdown();
                stop_controller(std::chrono::milliseconds(500));
                throw std::runtime_error(std::string(failure.what()) + log_tail(controller_log));
            }
        } else {
            result.realtime_scheduling = request_realtime_scheduling(kRealtimePriority).detail;
            RealtimeMaster master(dds, timeouts);
            for (Node* node : local_nodes) master.add_local_node(*node);
            if (controller) master.add_remote_node("controller", liveness);
            if (auto* modbus_wire = dynamic_cast<ModbusSlaveWire*>(wires.board_io.get())) {
                modbus_wire->set_wake([&dds] { dds.notify_data_arrived(); });
            }
            master.set_after_step([&trace](TimeNs t) { trace.drain(t, 0); });
            try {
                master.start();
                result.startup_wall_seconds = wall.elapsed_s();
                master.run_until(end_ns);
                master.shutdown();
                const std::string ended = stop_controller(std::chrono::milliseconds(3000));
                if (ended != "process exited with status 0") throw NodeFailure("controller", "after shutdown: " + ended);
            } catch (const std::exception& failure) {
                master.shutdown();
                stop_controller(std::chrono::milliseconds(500));
                throw std::runtime_error(std::string(failure.what()) + log_tail(controller_log));
            }
            for (const auto& [device, stats] : master.emission_jitter()) {
                // Nodes that only react to inputs (the NMEA serial adapter, a switch
                // never toggled) had no deadline to be late for: nothing to report.
                if (stats.samples == 0) continue;
                result.emission_jitter.push_back(EmissionJitter{device, stats.samples, stats.p50_ms, stats.p99_ms,
                                                                stats.max_ms, stats.step_p99_ms, stats.step_max_ms});
                figures.jitter.push_back(JitterRow{device, stats.p50_ms, stats.p99_ms, stats.max_ms, stats.step_max_ms});
            }
        }
        circuit.advance_to(end_ns);

        trace.record_deposition(circuit.deposition());
        result.trace_sha256 = trace.finish();
        result.trace_path = (case_dir / "trace.sqlite").string();
        result.sim_seconds = ns_to_seconds(end_ns);

        if (!static_test) {
            result.metrics = breakpoint_metrics(trace, plant, spec.breakpoint.along_m);
        }
        if (spec.scenario != Scenario::breakpoint_identification) {
            const double target = spec.controller.target_flow_l_min;
            const TimeNs judged_from_ns =
                static_test ? 0 : seconds_to_ns(plant.vehicle().pass_start_s(plant.vehicle().pass_index_at(1e9)));
            figures.target_flow_l_min = target;
            if (const auto episode = judged_episode(trace, judged_from_ns, end_ns)) {
                for (const auto& [name, value] : flow_metrics(main_flow_samples(trace), *episode, target)) {
                    result.metrics[name] = value;
                }
                const double open_at_m = plant.truth_at(episode->open_command_ns).nozzle_line_along_m();
                if (!static_test) {
                    // Where the flow adjustment began, before the breakpoint (paper: 1.70 / 2.55 / 3.45 m).
                    result.metrics["flow_adjust_start_before_breakpoint_m"] = spec.breakpoint.along_m - open_at_m;
                }
                add_flow_figure(trace, plant, *episode, spec.breakpoint.along_m, figures);
                figures.section_open_command_distance_m = open_at_m - spec.breakpoint.along_m;
                figures.section_open_command_t_s = ns_to_seconds(episode->open_command_ns);
            }
            add_spray_timing_metrics(trace, circuit, result.metrics);
        }
        if (spec.scenario == Scenario::breakpoint_continuation) {
            DepositionJudging judging;
            judging.nominal_dose_ul_cm2 = spec.controller.target_flow_l_min / 60.0 /
                                          (spec.vehicle.speed_km_h / 3.6 * spec.hydraulics.boom_width_m) * 100.0;
            judging.sprayed_fraction = spec.deposition.sprayed_fraction;
            judging.cv_row_m = spec.deposition.cv_row_m;
            judging.cv_window_m = spec.deposition.cv_window_m;
            const DoseProfile profile = dose_profile(circuit.deposition());
            const DepositionResult deposition = deposition_metrics(profile, judging, spec.breakpoint.along_m);
            for (const auto& [name, value] : deposition.metrics) result.metrics[name] = value;
            add_dose_figure(profile, deposition, spec.breakpoint.along_m, spec.deposition.cv_window_m, figures);
        }
    } catch (const std::exception& error) {
        result.error = error.what();
    }
    result.wall_seconds = wall.elapsed_s();
    const CaseVerdict verdict = judge_case(result.metrics, result.limits, spec.expect.fail);
    result.failures = verdict.failures;
    if (!result.error.empty()) result.failures.insert(result.failures.begin(), "error: " + result.error);
    result.expected_failure = verdict.expected_failure;
    result.passed = result.error.empty() && verdict.passed;
    figures.breakpoint_along_m = spec.breakpoint.along_m;
    return run;
}

std::vector<CaseRun> run_cases(const std::vector<CaseSpec>& specs, const RunOptions& options, std::ostream& progress) {
    std::vector<CaseRun> runs(specs.size());
    std::mutex progress_mutex;
    auto run_one = [&](std::size_t i) {
        runs[i] = run_case(specs[i], options);
        const CaseResult& result = runs[i].result;
        std::lock_guard lock(progress_mutex);
        progress << "rig: [" << (result.passed ? "PASS" : "FAIL") << "] " << result.name << " (" << result.wall_seconds
                 << " s wall)\n";
    };
    // Lockstep cases share the machine; a real-time case runs alone, after them,
    // so that other cases' load does not become its scheduling jitter.
    std::vector<std::size_t> lockstep, realtime;
    for (std::size_t i = 0; i < specs.size(); ++i) {
        (specs[i].mode == RunMode::realtime ? realtime : lockstep).push_back(i);
    }
    std::atomic<std::size_t> next{0};
    auto worker = [&] {
        for (std::size_t k = next++; k < lockstep.size(); k = next++) run_one(lockstep[k]);
    };
    const int jobs = std::max(1, std::min<int>(options.jobs, static_cast<int>(lockstep.size())));
    std::vector<std::thread> threads;
    for (int j = 0; j < jobs; ++j) threads.emplace_back(worker);
    for (auto& thread : threads) thread.join();
    for (std::size_t i : realtime) run_one(i);
    return runs;
}

}  // namespace rig::harness
