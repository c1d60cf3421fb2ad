#include "harness/systems/breakpoint/breakpoint_judge.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>

#include "emulators/field_frame.h"
#include "harness/judge/guidance_metrics.h"
#include "harness/systems/breakpoint/breakpoint_figures.h"
#include "harness/systems/breakpoint/gnss_wire_faults.h"
#include "idl/topics.h"
#include "rig/text/number_text.h"

namespace rig::harness {

// ---------------------------------------------------------------- the plan

void add_breakpoint_keys(const BreakpointJudgingPlan& plan, nlohmann::json& json) {
    json.update(nlohmann::json{
        {"breakpoint_along_m", plan.breakpoint_along_m},
        {"field",
         {{"origin_lat_deg", plan.field_origin_lat_deg},
          {"origin_lon_deg", plan.field_origin_lon_deg},
          {"origin_height_m", plan.field_origin_height_m},
          {"heading_deg", plan.field_heading_deg}}},
        {"judge_breakpoint", plan.judge_breakpoint},
        {"judge_flow", plan.judge_flow},
        {"judge_deposition", plan.judge_deposition},
    });
    if (plan.judge_guidance) json["judge_guidance"] = true;
    if (plan.judge_flow) {
        json["flow"] = {{"target_l_min", plan.flow.target_l_min},
                        {"band_pct", plan.flow.band_pct},
                        {"settle_by_s", plan.flow.settle_by_s},
                        {"window_from_ns", plan.flow_window.from_ns},
                        {"window_to_ns", plan.flow_window.to_ns},
                        {"kf11_pulses_per_l", plan.kf11_pulses_per_l},
                        {"kf11_window_s", plan.kf11_window_s}};
    }
    if (plan.judge_fig11) {
        json["fig11"] = {{"window_from_ns", plan.flow_window.from_ns}, {"window_to_ns", plan.flow_window.to_ns}};
    }
    if (plan.judge_deposition) {
        json["deposition"] = {{"nominal_dose_ul_cm2", plan.deposition.nominal_dose_ul_cm2},
                              {"sprayed_fraction", plan.deposition.sprayed_fraction},
                              {"cv_row_m", plan.deposition.cv_row_m},
                              {"cv_window_m", plan.deposition.cv_window_m},
                              {"strip_from_m", plan.deposition.strip_from_m},
                              {"strip_to_m", plan.deposition.strip_to_m}};
    }
}


nlohmann::json to_json(const BreakpointJudgingPlan& plan) {
    nlohmann::json json = nlohmann::json::object();
    add_to_json(static_cast<const JudgingPlan&>(plan), json);
    add_breakpoint_keys(plan, json);
    return json;
}

BreakpointJudgingPlan breakpoint_judging_plan_from_json(const nlohmann::json& json) {
    // at("a/b"): the value, or an error naming the key path.
    const auto& at = plan_key;
    try {
        BreakpointJudgingPlan plan;
        static_cast<JudgingPlan&>(plan) = judging_plan_from_json(json);
        plan.breakpoint_along_m = at(json, "breakpoint_along_m", "").get<double>();
        const nlohmann::json& field = at(json, "field", "");
        plan.field_origin_lat_deg = at(field, "origin_lat_deg", "field.").get<double>();
        plan.field_origin_lon_deg = at(field, "origin_lon_deg", "field.").get<double>();
        plan.field_origin_height_m = at(field, "origin_height_m", "field.").get<double>();
        plan.field_heading_deg = at(field, "heading_deg", "field.").get<double>();
        plan.judge_breakpoint = at(json, "judge_breakpoint", "").get<bool>();
        plan.judge_flow = at(json, "judge_flow", "").get<bool>();
        plan.judge_deposition = at(json, "judge_deposition", "").get<bool>();
        plan.judge_guidance = json.contains("judge_guidance") && at(json, "judge_guidance", "").get<bool>();
        if (plan.judge_flow) {
            const nlohmann::json& flow = at(json, "flow", "");
            plan.flow.target_l_min = at(flow, "target_l_min", "flow.").get<double>();
            plan.flow.band_pct = at(flow, "band_pct", "flow.").get<double>();
            plan.flow.settle_by_s = at(flow, "settle_by_s", "flow.").get<double>();
            plan.flow_window.from_ns = at(flow, "window_from_ns", "flow.").get<TimeNs>();
            plan.flow_window.to_ns = at(flow, "window_to_ns", "flow.").get<TimeNs>();
            plan.kf11_pulses_per_l = at(flow, "kf11_pulses_per_l", "flow.").get<double>();
            plan.kf11_window_s = at(flow, "kf11_window_s", "flow.").get<double>();
        }
        // Traces from before the valve_calibration scenario have no fig11 section.
        if (json.contains("fig11")) {
            const nlohmann::json& fig11 = at(json, "fig11", "");
            plan.judge_fig11 = true;
            plan.flow_window.from_ns = at(fig11, "window_from_ns", "fig11.").get<TimeNs>();
            plan.flow_window.to_ns = at(fig11, "window_to_ns", "fig11.").get<TimeNs>();
        }
        if (plan.judge_deposition) {
            const nlohmann::json& deposition = at(json, "deposition", "");
            plan.deposition.nominal_dose_ul_cm2 = at(deposition, "nominal_dose_ul_cm2", "deposition.").get<double>();
            plan.deposition.sprayed_fraction = at(deposition, "sprayed_fraction", "deposition.").get<double>();
            plan.deposition.cv_row_m = at(deposition, "cv_row_m", "deposition.").get<double>();
            plan.deposition.cv_window_m = at(deposition, "cv_window_m", "deposition.").get<double>();
            plan.deposition.strip_from_m = at(deposition, "strip_from_m", "deposition.").get<double>();
            plan.deposition.strip_to_m = at(deposition, "strip_to_m", "deposition.").get<double>();
        }
        return plan;
    } catch (const nlohmann::json::exception& error) {
        throw std::runtime_error(std::string("judging plan: ") + error.what());
    }
}

// ---------------------------------------------------------------- the trace's samples

namespace {

std::vector<VehicleSample> vehicle_samples(const RecordedTrace& trace) {
    std::vector<VehicleSample> samples;
    for (const RecordedSample& sample : trace.samples(topics::kVehicleTruth)) {
        samples.push_back(VehicleSample{sample.t_ns, sample.json.at("nozzle_line_along_m").get<double>(),
                                        sample.json.at("pass_index").get<int>(), sample.json.at("cross_m").get<double>()});
    }
    return samples;
}

// The flow judge reads the main flow and the sections; Fig. 11's also the pump
// and the valve (`with_pump_and_valve`).
std::vector<HydraulicsSample> hydraulics_samples(const RecordedTrace& trace, bool with_pump_and_valve = false) {
    std::vector<HydraulicsSample> samples;
    for (const RecordedSample& sample : trace.samples(topics::kHydraulicsTruth)) {
        HydraulicsSample hydraulics{sample.t_ns, sample.json.at("main_flow_l_min").get<double>(),
                                    sample.json.at("sections_spraying_mask").get<std::uint16_t>()};
        if (with_pump_and_valve) {
            hydraulics.pump_flow_l_min = sample.json.at("pump_flow_l_min").get<double>();
            hydraulics.valve_opening_pct = sample.json.at("valve_opening_pct").get<double>();
        }
        samples.push_back(hydraulics);
    }
    return samples;
}

std::vector<SectionCommand> section_commands(const RecordedTrace& trace) {
    std::vector<SectionCommand> commands;
    for (const RecordedSample& sample : trace.samples(topics::kSectionValves)) {
        commands.push_back(SectionCommand{sample.t_ns, sample.json.at("open_mask").get<std::uint16_t>()});
    }
    return commands;
}

std::vector<FlowMeterCountSample> flow_meter_samples(const RecordedTrace& trace) {
    std::vector<FlowMeterCountSample> samples;
    for (const RecordedSample& sample : trace.samples(topics::kMainFlowMeter)) {
        samples.push_back(FlowMeterCountSample{sample.t_ns, sample.json.at("count_pulses").get<std::uint32_t>(),
                                               sample.json.at("last_edge_capture_us").get<std::uint32_t>()});
    }
    return samples;
}

std::vector<BreakpointEventSample> breakpoint_events(const RecordedTrace& trace) {
    std::vector<BreakpointEventSample> events;
    for (const RecordedSample& sample : trace.samples(topics::kBreakpointEvent)) {
        BreakpointEventSample event;
        event.t_ns = sample.t_ns;
        event.kind = sample.json.at("kind").get<std::string>();
        if (sample.json.at("lat_deg").is_number()) event.lat_deg = sample.json.at("lat_deg").get<double>();
        if (sample.json.at("lon_deg").is_number()) event.lon_deg = sample.json.at("lon_deg").get<double>();
        events.push_back(event);
    }
    return events;
}

// Fig. 14: main flow (truth) and the controller's Eq. 3 reading, against the
// nozzle line's distance to the breakpoint, around the judged opening.
void add_flow_figure(const RecordedTrace& trace, const VehicleTrack& track, TimeNs open_ns, TimeNs window_end_ns,
                     double breakpoint_along_m, BreakpointFigures& figures) {
    const TimeNs from_ns = open_ns - seconds_to_ns(1.0);
    const TimeNs to_ns = std::min(window_end_ns, open_ns + seconds_to_ns(8.0));
    std::map<TimeNs, double> measured;
    for (const RecordedSample& status : trace.samples(topics::kControllerStatus)) {
        if (status.t_ns >= from_ns && status.t_ns <= to_ns && status.json.at("measured_flow_l_min").is_number()) {
            measured[status.t_ns] = status.json.at("measured_flow_l_min").get<double>();
        }
    }
    for (const RecordedSample& sample : trace.samples(topics::kHydraulicsTruth)) {
        if (sample.t_ns < from_ns || sample.t_ns > to_ns) continue;
        FlowSample point;
        point.t_s = ns_to_seconds(sample.t_ns);
        if (const auto along_m = track.nozzle_line_along_m(sample.t_ns)) {
            point.distance_to_breakpoint_m = *along_m - breakpoint_along_m;
        }
        point.main_flow_l_min = sample.json.at("main_flow_l_min").get<double>();
        if (const auto it = measured.find(sample.t_ns); it != measured.end()) point.measured_flow_l_min = it->second;
        figures.flow.push_back(point);
    }
}

// Fig. 15: dose per row across the breakpoint, by pass, with the judged areas.
void add_dose_figure(const DoseProfile& profile, const DepositionResult& deposition, double breakpoint_along_m,
                     double window_m, BreakpointFigures& figures) {
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

std::vector<LandingEdgeSample> landing_edges(const RecordedTrace& trace) {
    std::vector<LandingEdgeSample> edges;
    for (const RecordedLandingEdge& edge : trace.landing_edges) edges.push_back(LandingEdgeSample{edge.t_ns, edge.landing});
    return edges;
}

}  // namespace

DoseProfile dose_profile(const RecordedTrace& trace) {
    DoseProfile profile;
    const auto grid = trace.meta.find("deposition_grid");
    if (grid == trace.meta.end()) return profile;
    nlohmann::json params;
    try {
        params = nlohmann::json::parse(grid->second);
        profile.first_row_centre_m = params.at("first_row_centre_m").get<double>();
        profile.row_m = params.at("cell_along_m").get<double>();
    } catch (const nlohmann::json::exception& parse_error) {
        throw std::runtime_error("trace " + trace.file.string() + ": meta deposition_grid: " + parse_error.what());
    }
    const auto rows = params.at("rows").get<std::size_t>();
    profile.ground_rows = rows;
    const int nozzles = params.at("nozzle_count").get<int>();
    const int passes = params.at("passes").get<int>();
    std::vector<std::vector<double>> sums(static_cast<std::size_t>(std::max(passes, 0)), std::vector<double>(rows, 0.0));
    for (const RecordedDepositionCell& cell : trace.deposition) {
        const auto pass = static_cast<std::size_t>(cell.pass);
        if (pass >= sums.size() || cell.row >= rows) {
            throw std::runtime_error("trace " + trace.file.string() + ": deposition cell (pass " + std::to_string(cell.pass) +
                                     ", row " + std::to_string(cell.row) + ") outside the recorded grid");
        }
        sums[pass][cell.row] += cell.dose_ul_cm2;
    }
    for (auto& layer : sums) {
        for (double& sum : layer) sum /= nozzles;
    }
    if (!sums.empty()) profile.first_pass = std::move(sums[0]);
    if (sums.size() > 1) profile.continuation = std::move(sums[1]);
    return profile;
}

// ---------------------------------------------------------------- judging

SystemJudgement judge_breakpoint_trace(const RecordedTrace& trace, const BreakpointJudgingPlan& plan) {
    auto figures = std::make_shared<BreakpointFigures>();
    figures->breakpoint_along_m = plan.breakpoint_along_m;
    const DoseProfile profile = plan.judge_deposition ? dose_profile(trace) : DoseProfile{};
    MetricSet metrics;
    const VehicleTrack track(vehicle_samples(trace));
    if (plan.judge_breakpoint) {
        const emulators::FieldFrame field(plan.field_origin_lat_deg, plan.field_origin_lon_deg,
                                          plan.field_origin_height_m, plan.field_heading_deg);
        metrics.merge(breakpoint_metrics(breakpoint_events(trace), track, field, plan.breakpoint_along_m));
    }
    if (plan.judge_flow) {
        const std::vector<HydraulicsSample> hydraulics = hydraulics_samples(trace);
        const std::vector<SectionCommand> commands = section_commands(trace);
        const std::vector<FlowReading> kf11 =
            kf11_readings(flow_meter_samples(trace), plan.kf11_pulses_per_l, plan.kf11_window_s);
        const FlowResult flow = flow_metrics(hydraulics, commands, kf11, plan.flow_window, plan.flow);
        metrics.merge(flow.metrics);
        figures->target_flow_l_min = plan.flow.target_l_min;
        if (flow.first_open_ns) {
            const std::optional<double> open_at_m = track.nozzle_line_along_m(*flow.first_open_ns);
            if (plan.judge_breakpoint && open_at_m) {
                // Where the flow adjustment began, before the breakpoint (paper: 1.70 / 2.55 / 3.45 m).
                metrics.values["flow_adjust_start_before_breakpoint_m"] = plan.breakpoint_along_m - *open_at_m;
            } else if (plan.judge_breakpoint) {
                metrics.not_measured["flow_adjust_start_before_breakpoint_m"] =
                    "the sections opened at " + fixed_text(ns_to_seconds(*flow.first_open_ns), 3) +
                    " s, where truth has no position of the nozzle line: " + track.describe_span();
            }
            add_flow_figure(trace, track, *flow.first_open_ns, plan.flow_window.to_ns, plan.breakpoint_along_m,
                            *figures);
            if (open_at_m) figures->section_open_command_distance_m = *open_at_m - plan.breakpoint_along_m;
            figures->section_open_command_t_s = ns_to_seconds(*flow.first_open_ns);
        }
        metrics.merge(spray_timing_metrics(commands, hydraulics, landing_edges(trace)));
    }
    if (plan.judge_fig11) {
        metrics.merge(fig11_metrics(hydraulics_samples(trace, /*with_pump_and_valve=*/true), plan.flow_window).metrics);
    }
    if (plan.judge_deposition) {
        const DepositionResult deposition = deposition_metrics(profile, plan.deposition, plan.breakpoint_along_m);
        metrics.merge(deposition.metrics);
        add_dose_figure(profile, deposition, plan.breakpoint_along_m, plan.deposition.cv_window_m, *figures);
    }
    if (plan.judge_guidance) {
        // Truth's antenna: cross_m is its offset right of the A-B line.
        std::vector<GuidanceErrorSample> errors;
        for (const RecordedSample& sample : trace.samples(topics::kVehicleTruth)) {
            errors.push_back(GuidanceErrorSample{
                sample.t_ns,
                sample.json.at("cross_m").get<double>(),
                std::remainder(sample.json.at("heading_deg").get<double>() - plan.field_heading_deg, 360.0),
                sample.json.at("speed_m_s").get<double>()});
        }
        metrics.merge(guidance_metrics(errors, "antenna"));
    }
    metrics.merge(gnss_wire_fault_metrics(trace));  // cases with gnss.wire_faults only
    return SystemJudgement{std::move(metrics), std::move(figures)};
}

}  // namespace rig::harness
