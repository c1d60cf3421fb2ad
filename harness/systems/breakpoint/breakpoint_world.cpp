#include "harness/systems/breakpoint/breakpoint_world.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

#include "emulators/seeded_random.h"
#include "harness/systems/breakpoint/gnss_wire_faults.h"

namespace rig::harness {

namespace {

// How the case's scenario becomes a route (seed 000 sec. 2.5.1, 2.5.2):
//   breakpoint_*: the first pass drives first_pass_m up to the breakpoint and
//   stops with the nozzle line on it; the operator presses the button; the
//   sprayer turns at the headland (not simulated: it reappears at start_m) and
//   approaches the breakpoint again, driving overrun_m past it.
//   static_flow, valve_calibration: the sprayer stands at the breakpoint; the
//   spray switch goes on at spray_on_at_s for spray_for_s (sec. 2.4's static tests).
constexpr double kStandAfterButtonS = 1.0;
constexpr double kStandBeforeApproachS = 2.0;
constexpr double kStandAfterStaticS = 3.0;
constexpr double kForeverS = 1e6;


ScenarioPlan build_scenario(const BreakpointSections& spec, const emulators::BoomGeometry& boom) {
    const double bp = spec.breakpoint.along_m;
    ScenarioPlan scenario;
    if (stands_still(spec.scenario_kind)) {
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
    if (spec.scenario_kind == Scenario::breakpoint_continuation) scenario.spray_switch.push_back({0.0, kForeverS});
    return scenario;
}

emulators::SprayCircuitParams circuit_params(const HydraulicsSpec& h, const DepositionSpec& deposition,
                                             double grid_from_m, double grid_to_m) {
    emulators::SprayCircuitParams params;
    params.pump_flow_l_min = h.pump_flow_l_min;
    for (const ThrottleStepSpec& step : h.pump_throttle) {
        params.throttle_steps.push_back(emulators::ThrottleStep{step.at_s, step.flow_l_min});
    }
    params.throttle_ramp_s = h.throttle_ramp_s;
    params.pump_pulsation_pct = h.pump_pulsation_pct;
    params.pump_pulsation_hz = h.pump_pulsation_hz;
    params.valve = emulators::BallValveParams{h.valve_travel_s, h.valve_motor_start_delay_s, h.valve_backlash_pct,
                                              h.valve_initial_opening_pct};
    params.flow_map.interpolation_bulge_pct = h.interpolation_bulge_pct;
    params.flow_map.calibration_drift_pct = h.calibration_drift_pct;
    params.pipeline_time_constant_s = h.pipeline_time_constant_s;
    params.pipeline_air_l = h.pipeline_air_l;
    params.nozzle_rated_flow_l_min = h.nozzle_rated_flow_l_min;
    params.nozzle_rated_pressure_mpa = h.nozzle_rated_pressure_mpa;
    params.section_nozzles = h.section_nozzles;
    params.boom_width_m = h.boom_width_m;
    params.section_valve_open_s = h.section_valve_open_s;
    params.section_valve_close_s = h.section_valve_close_s;
    params.droplet_fall_s = h.droplet_fall_s;
    params.min_nozzle_flow_l_min = h.min_nozzle_flow_l_min;
    params.deposition.from_along_m = grid_from_m;
    params.deposition.to_along_m = grid_to_m;
    params.deposition.cell_along_m = deposition.cell_m;
    params.deposition.footprint_along_m = deposition.footprint_m;
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

emulators::G970Params gnss_params(const GnssSpec& gnss, std::chrono::sys_time<std::chrono::nanoseconds> utc_start,
                                  std::uint64_t seed, double breakpoint_crossing_s) {
    emulators::G970Params params;
    std::string talker(to_string(gnss.talker));
    std::transform(talker.begin(), talker.end(), talker.begin(), [](unsigned char c) { return std::toupper(c); });
    params.talker = talker;
    params.rate_hz = gnss.rate_hz;
    params.latency_s = gnss.latency_s;
    params.epoch_phase_s =
        gnss.epoch_phase_s.value_or(emulators::SeededRandom(seed, "gnss_g970.epoch_phase").uniform01() /
                                         gnss.rate_hz);
    params.fix = to_fix_kind(gnss.fix);
    params.noise_base_m = gnss.noise.base_m;
    params.noise_ppm = gnss.noise.ppm;
    params.baseline_km = gnss.noise.baseline_km;
    for (const GnssDropout& dropout : gnss.dropouts) {
        const double at_s =
            dropout.before_breakpoint_s ? breakpoint_crossing_s - *dropout.before_breakpoint_s : dropout.at_s;
        params.dropouts.push_back(emulators::GnssEpisode{at_s, dropout.for_s});
    }
    for (const GnssDegraded& degraded : gnss.degraded) {
        params.degraded.push_back(
            emulators::GnssEpisode{degraded.at_s, degraded.for_s, to_fix_kind(degraded.fix), degraded.sigma_m});
    }
    // UTC of sim time 0, from the case's utc_start.
    const auto start_day = std::chrono::floor<std::chrono::days>(utc_start);
    const std::chrono::year_month_day ymd{start_day};
    params.utc_year = static_cast<int>(ymd.year());
    params.utc_month = static_cast<int>(static_cast<unsigned>(ymd.month()));
    params.utc_day = static_cast<int>(static_cast<unsigned>(ymd.day()));
    params.utc_start_seconds_of_day =
        std::chrono::duration<double>(utc_start - std::chrono::sys_time<std::chrono::nanoseconds>(start_day))
            .count();
    params.wire_faults = nmea_wire_fault_rates(gnss.wire_faults);
    params.seed = seed;
    return params;
}

}  // namespace

BreakpointWorld build_case_world(const BreakpointSections& spec, std::uint64_t seed) {
    emulators::PlantParams plant_params;
    plant_params.origin_lat_deg = spec.field.origin.lat_deg;
    plant_params.origin_lon_deg = spec.field.origin.lon_deg;
    plant_params.origin_height_m = spec.field.origin.height_m;
    plant_params.heading_deg = spec.field.heading_deg;
    plant_params.boom =
        emulators::BoomGeometry{spec.boom.l1_m, spec.boom.l2_m, spec.boom.l3_m, spec.boom.linkage_rise_m};
    ScenarioPlan scenario = build_scenario(spec, plant_params.boom);
    for (const BoomLiftSpec& lift : spec.boom.lifts) {
        plant_params.boom_lifts.push_back(emulators::BoomLift{lift.at_s, lift.to_m, lift.rate_m_s});
    }
    plant_params.route = scenario.route;
    plant_params.start_nozzle_line_along_m = scenario.start_along_m;
    plant_params.wheel.slip_pct = spec.encoder.slip_pct;
    plant_params.wheel.slip_sd_pct = spec.encoder.slip_sd_pct;
    plant_params.wheel.deflection_pct = spec.encoder.deflection_pct;
    plant_params.wheel.terrain_sd_m_per_sqrt_m = spec.encoder.terrain_sd_m_per_sqrt_m;
    plant_params.seed = seed;
    plant_params.guidance = spec.guidance;
    plant_params.antenna = spec.antenna;
    emulators::Plant plant(plant_params);
    const double breakpoint_along_m =
        scenario.button.empty() ? spec.breakpoint.along_m
                                : plant.vehicle().state_at(scenario.button.front().at_s).nozzle_line_along_m;
    const double crossing_s = stands_still(spec.scenario_kind)
                                  ? std::numeric_limits<double>::quiet_NaN()
                                  : plant.vehicle().time_when_nozzle_line_reaches(breakpoint_along_m,
                                                                                  scenario.approach_starts_s);
    const TimeNs end_ns = seconds_to_ns(plant.vehicle().end_time_s() + 1.0);
    emulators::G970Params gnss = gnss_params(spec.gnss, spec.utc_start, seed, crossing_s);
    // The deposition grid spans everything the boom can reach, with a margin.
    const double grid_from_m = std::min(scenario.start_along_m, spec.vehicle.start_m) - 5.0;
    const double grid_to_m = spec.breakpoint.along_m + spec.vehicle.overrun_m + 5.0;
    emulators::SprayCircuitParams circuit = circuit_params(spec.hydraulics, spec.deposition, grid_from_m, grid_to_m);
    return BreakpointWorld{std::move(plant),   std::move(scenario), std::move(gnss), std::move(circuit),
                     crossing_s,         breakpoint_along_m,  end_ns};
}

BreakpointJudgingPlan plan_judging(const BreakpointSections& spec, const BreakpointWorld& world,
                                   const std::map<std::string, double>& limits) {
    BreakpointJudgingPlan plan;
    plan.breakpoint_along_m = world.breakpoint_along_m;
    plan.field_origin_lat_deg = spec.field.origin.lat_deg;
    plan.field_origin_lon_deg = spec.field.origin.lon_deg;
    plan.field_origin_height_m = spec.field.origin.height_m;
    plan.field_heading_deg = spec.field.heading_deg;
    plan.judge_breakpoint = !stands_still(spec.scenario_kind);
    plan.judge_flow = spec.scenario_kind != Scenario::breakpoint_identification && spec.scenario_kind != Scenario::valve_calibration;
    plan.judge_fig11 = spec.scenario_kind == Scenario::valve_calibration;
    if (plan.judge_fig11) {
        // While the switch is on (the procedure runs; the throttle moves).
        plan.flow_window.from_ns = seconds_to_ns(spec.static_flow.spray_on_at_s);
        plan.flow_window.to_ns = seconds_to_ns(spec.static_flow.spray_on_at_s + spec.static_flow.spray_for_s);
    }
    plan.judge_deposition = spec.scenario_kind == Scenario::breakpoint_continuation;
    plan.judge_guidance = spec.guidance.has_value();
    const emulators::VehiclePlant& vehicle = world.plant.vehicle();
    // The strip that must be sprayed: the first pass's start to the end of the
    // continuation, less the allowances at either end (breakpoint_case.h DepositionSpec).
    plan.deposition.strip_from_m =
        spec.breakpoint.along_m - spec.vehicle.first_pass_m + spec.deposition.strip_start_allowance_m;
    plan.deposition.strip_to_m = spec.breakpoint.along_m + spec.vehicle.overrun_m - spec.deposition.strip_end_allowance_m;
    if (plan.judge_flow) {
        plan.flow.target_l_min = spec.target_flow_l_min;
        plan.flow.band_pct = 3.0;  // sec. 3.1.2 / Table 2: "adjusted" = within +-3 % of the target
        if (const auto limit = limits.find("flow_adjust_time_s"); limit != limits.end()) {
            plan.flow.settle_by_s = limit->second;
        }
        plan.kf11_pulses_per_l = spec.flow_meter.pulses_per_l;
        if (spec.scenario_kind == Scenario::static_flow) {
            // From the spray switch going on to it going off (sec. 2.4's static tests).
            plan.flow_window.from_ns = seconds_to_ns(spec.static_flow.spray_on_at_s);
            plan.flow_window.to_ns = seconds_to_ns(spec.static_flow.spray_on_at_s + spec.static_flow.spray_for_s);
        } else {
            // The continuation pass, from the headland turn until the nozzle line
            // reaches the strip's end: the flow must be settled then.
            const double pass_start_s = vehicle.pass_start_s(1);
            double to_s = vehicle.time_when_nozzle_line_reaches(plan.deposition.strip_to_m, pass_start_s);
            if (!std::isfinite(to_s)) to_s = vehicle.end_time_s();
            plan.flow_window.from_ns = seconds_to_ns(pass_start_s);
            plan.flow_window.to_ns = seconds_to_ns(to_s);
        }
    }
    if (plan.judge_deposition) {
        // 1 uL/cm^2 = 100 L/ha: target flow over the swath the boom covers at cruise speed.
        plan.deposition.nominal_dose_ul_cm2 = spec.target_flow_l_min / 60.0 /
                                              (spec.vehicle.speed_km_h / 3.6 * spec.hydraulics.boom_width_m) * 100.0;
        plan.deposition.sprayed_fraction = spec.deposition.sprayed_fraction;
        plan.deposition.cv_row_m = spec.deposition.cv_row_m;
        plan.deposition.cv_window_m = spec.deposition.cv_window_m;
    }
    return plan;
}


void record_deposition(TraceFile& trace, const emulators::DepositionGrid& grid) {
    const auto& params = grid.params();
    const DepositionLayout layout{grid.row_centre_m(0), params.cell_along_m, grid.row_count(), params.nozzle_count,
                                  grid.pass_count()};
    std::vector<DepositionCell> cells;
    for (int pass = 0; pass < grid.pass_count(); ++pass) {
        for (std::size_t row = 0; row < grid.row_count(); ++row) {
            for (int nozzle = 0; nozzle < params.nozzle_count; ++nozzle) {
                const double dose = grid.dose_ul_cm2(pass, row, nozzle);
                if (dose <= 0.0) continue;
                cells.push_back(DepositionCell{pass, row, grid.row_centre_m(row), nozzle, dose});
            }
        }
    }
    trace.record_deposition(layout, cells);
}

}  // namespace rig::harness
