#include "harness/systems/boundary/boundary_judge.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "emulators/field2d/polygon.h"
#include "harness/judge/guidance_metrics.h"
#include "harness/systems/boundary/boundary_figures.h"
#include "idl/topics.h"
#include "rig/text/number_text.h"

namespace rig::harness {
namespace {

BoundaryEdge nearest_edge(const field2d::Polygon& area, field2d::Vec2 near) {
    const std::vector<field2d::Vec2>& v = area.vertices();
    std::size_t best = 0;
    double best_d = INFINITY;
    for (std::size_t i = 0; i < v.size(); ++i) {
        const field2d::Vec2 a = v[i];
        const field2d::Vec2 b = v[(i + 1) % v.size()];
        const double d = std::hypot(near.east_m - 0.5 * (a.east_m + b.east_m), near.north_m - 0.5 * (a.north_m + b.north_m));
        if (d < best_d) {
            best_d = d;
            best = i;
        }
    }
    const field2d::Vec2 a = v[best];
    const field2d::Vec2 b = v[(best + 1) % v.size()];
    return BoundaryEdge{a.east_m, a.north_m, b.east_m, b.north_m};
}

// delivered_l is what each nozzle delivered since the start: it never goes
// back. Steps in which it does cannot say what was laid: an error naming the
// sample, never a step's volume clamped to 0.
void check_volumes_grow(const std::vector<NozzleStepTruth>& steps) {
    for (std::size_t i = 0; i < steps.size(); ++i) {
        const NozzleStepTruth& step = steps[i];
        for (std::size_t n = 0; n < step.delivered_l.size(); ++n) {
            const double before = i == 0 || n >= steps[i - 1].delivered_l.size() ? 0.0 : steps[i - 1].delivered_l[n];
            if (!std::isfinite(step.delivered_l[n]) || step.delivered_l[n] < before) {
                throw std::runtime_error("truth/nozzles at t_ns " + std::to_string(step.t_ns) + ": nozzle " + std::to_string(n) +
                                         " delivered_l " + shortest_text(step.delivered_l[n]) + " L after " +
                                         shortest_text(before) + " L (it only grows)");
            }
        }
    }
}

// A key of seed 001's part of the plan (meta `judging`, key `boundary`).
const nlohmann::json& at(const nlohmann::json& node, const char* key, const std::string& path) {
    return plan_key(node, key, "boundary." + path);
}

}  // namespace

BoundaryJudgingPlan plan_boundary_judging(const BoundarySections& spec) {
    BoundaryJudgingPlan plan;
    plan.ground = spec.ground;
    plan.fan_angle_deg = spec.spray.fan_angle_deg;
    plan.band_thickness_m = spec.spray.band_thickness_m;
    const field2d::Polygon area = field2d::Polygon::from_geodetic(spec.frame(), spec.corners, spec.area_name);
    for (const BoundaryEdgeJudging& edge : spec.edges) {
        plan.edges.push_back(BoundaryEdgePlan{edge.metric, nearest_edge(area, edge.near), edge.probe});
    }
    plan.flow_per_duty = spec.judge_flow_per_duty;
    plan.flow_settle_s = spec.flow_settle_s;
    plan.pwm_period_s = 1.0 / spec.valves.frequency_hz;
    const field2d::NozzleFlowTable table = spec.flow_table_or_paper();
    for (int n = 0; n < table.nozzle_count(); ++n) plan.flow_table.push_back(table.points(n));
    plan.centre_rule = spec.judge_centre_rule;
    plan.area = area.vertices();
    plan.vision = spec.vision_judging;
    plan.papers = spec.papers;
    plan.dose_strip = spec.dose_strip;
    plan.coverage = spec.coverage;
    if (spec.guidance) {
        const field2d::Route2d route(spec.route_start, spec.route_segments);
        const emulators::guidance::ReferencePath path = field2d::reference_path_of(route);
        const double length_m = route.total_distance_m();
        const double spacing_m = std::max(kGuidanceRouteSpacingM, length_m / static_cast<double>(kGuidanceRouteMaxPoints - 1));
        for (double d = 0.0;; d += spacing_m) {
            const emulators::guidance::PathPose at = path(std::min(d, length_m));
            plan.guidance_route.push_back({at.position.east_m, at.position.north_m, at.heading_deg});
            if (d >= length_m) break;
        }
    }
    return plan;
}

nlohmann::json to_json(const BoundaryJudgingPlan& plan) {
    nlohmann::json edges = nlohmann::json::array();
    for (const BoundaryEdgePlan& e : plan.edges) {
        edges.push_back({{"metric", e.metric},
                         {"edge", {e.edge.from_east_m, e.edge.from_north_m, e.edge.to_east_m, e.edge.to_north_m}},
                         {"from_m", e.probe.from_m},
                         {"to_m", e.probe.to_m},
                         {"spacing_m", e.probe.spacing_m},
                         {"wet_threshold_ul_cm2", e.probe.wet_threshold_ul_cm2}});
    }
    nlohmann::json table = nlohmann::json::array();
    for (const auto& nozzle : plan.flow_table) {
        nlohmann::json points = nlohmann::json::array();
        for (const field2d::FlowPoint& p : nozzle) points.push_back({p.duty_pct, p.flow_ml_min});
        table.push_back(std::move(points));
    }
    nlohmann::json area = nlohmann::json::array();
    for (const field2d::Vec2& v : plan.area) area.push_back({v.east_m, v.north_m});
    nlohmann::json json = {{"ground",
             {{"east_min_m", plan.ground.east_min_m},
              {"east_max_m", plan.ground.east_max_m},
              {"north_min_m", plan.ground.north_min_m},
              {"north_max_m", plan.ground.north_max_m},
              {"cell_m", plan.ground.cell_m},
              {"nozzle_count", plan.ground.nozzle_count}}},
            {"fan_angle_deg", plan.fan_angle_deg},
            {"band_thickness_m", plan.band_thickness_m},
            {"edges", std::move(edges)},
            {"flow_per_duty", plan.flow_per_duty},
            {"flow_settle_s", plan.flow_settle_s},
            {"pwm_period_s", plan.pwm_period_s},
            {"flow_table_ml_min", std::move(table)},
            {"centre_rule", plan.centre_rule},
            {"area", std::move(area)}};
    // Only cases that judge vision or papers carry these keys (older plans stay byte for byte).
    if (plan.vision.enabled) {
        const VisionJudging& v = plan.vision;
        const Eq14Levels& e = v.eq14;
        json["vision"] = {{"zone", {v.east_min_m, v.east_max_m, v.north_min_m, v.north_max_m}},
                          {"decision_delay_s", v.decision_delay_s},
                          {"eq14", {e.k_max_cover, e.eq12_coefficient_l_min_per_m_s, e.eq13_slope_l_min_per_pct,
                                    e.eq13_intercept_l_min, e.level0_max_pct, e.level1_max_pct, e.level1_duty_pct,
                                    e.level2_duty_pct}}};
    }
    if (!plan.guidance_route.empty()) json["guidance_route"] = plan.guidance_route;
    if (!plan.papers.empty() || plan.dose_strip) {
        nlohmann::json papers = nlohmann::json::array();
        for (const field2d::Vec2& p : plan.papers) papers.push_back({p.east_m, p.north_m});
        json["papers"] = std::move(papers);
        json["stain_area_cm2_per_ul"] = plan.coverage.stain_area_cm2_per_ul;
        if (plan.dose_strip) {
            const GroundRect& r = *plan.dose_strip;
            json["dose_strip"] = {r.east_min_m, r.east_max_m, r.north_min_m, r.north_max_m};
        }
    }
    return json;
}

BoundaryJudgingPlan boundary_judging_plan_from_json(const nlohmann::json& json) {
    try {
        BoundaryJudgingPlan plan;
        const nlohmann::json& ground = at(json, "ground", "");
        plan.ground.east_min_m = at(ground, "east_min_m", "ground.").get<double>();
        plan.ground.east_max_m = at(ground, "east_max_m", "ground.").get<double>();
        plan.ground.north_min_m = at(ground, "north_min_m", "ground.").get<double>();
        plan.ground.north_max_m = at(ground, "north_max_m", "ground.").get<double>();
        plan.ground.cell_m = at(ground, "cell_m", "ground.").get<double>();
        plan.ground.nozzle_count = at(ground, "nozzle_count", "ground.").get<int>();
        plan.fan_angle_deg = at(json, "fan_angle_deg", "").get<double>();
        plan.band_thickness_m = at(json, "band_thickness_m", "").get<double>();
        for (const nlohmann::json& e : at(json, "edges", "")) {
            BoundaryEdgePlan edge;
            edge.metric = at(e, "metric", "edges[].").get<std::string>();
            const std::vector<double> xy = at(e, "edge", "edges[].").get<std::vector<double>>();
            if (xy.size() != 4) throw std::runtime_error("boundary judging plan: edges[].edge needs 4 numbers");
            edge.edge = BoundaryEdge{xy[0], xy[1], xy[2], xy[3]};
            edge.probe.from_m = at(e, "from_m", "edges[].").get<double>();
            edge.probe.to_m = at(e, "to_m", "edges[].").get<double>();
            edge.probe.spacing_m = at(e, "spacing_m", "edges[].").get<double>();
            // Plans written while the probe searched a +-2 m window carry
            // search_inside_m and search_outside_m: the probe now spans the ground.
            edge.probe.wet_threshold_ul_cm2 = at(e, "wet_threshold_ul_cm2", "edges[].").get<double>();
            plan.edges.push_back(std::move(edge));
        }
        plan.flow_per_duty = at(json, "flow_per_duty", "").get<bool>();
        plan.flow_settle_s = at(json, "flow_settle_s", "").get<double>();
        plan.pwm_period_s = at(json, "pwm_period_s", "").get<double>();
        for (const nlohmann::json& nozzle : at(json, "flow_table_ml_min", "")) {
            std::vector<field2d::FlowPoint> points;
            for (const nlohmann::json& p : nozzle) points.push_back({p.at(0).get<double>(), p.at(1).get<double>()});
            plan.flow_table.push_back(std::move(points));
        }
        // Plans written before the centre rule was judged have neither key.
        if (json.contains("centre_rule")) plan.centre_rule = json.at("centre_rule").get<bool>();
        if (json.contains("area")) {
            for (const nlohmann::json& v : json.at("area")) plan.area.push_back({v.at(0).get<double>(), v.at(1).get<double>()});
        }
        if (json.contains("vision")) {
            const nlohmann::json& v = json.at("vision");
            const std::vector<double> zone = at(v, "zone", "vision.").get<std::vector<double>>();
            const std::vector<double> eq = at(v, "eq14", "vision.").get<std::vector<double>>();
            if (zone.size() != 4 || eq.size() != 8) throw std::runtime_error("boundary judging plan: vision.zone needs 4 numbers, vision.eq14 8");
            plan.vision.enabled = true;
            plan.vision.east_min_m = zone[0];
            plan.vision.east_max_m = zone[1];
            plan.vision.north_min_m = zone[2];
            plan.vision.north_max_m = zone[3];
            plan.vision.decision_delay_s = at(v, "decision_delay_s", "vision.").get<double>();
            plan.vision.eq14 = Eq14Levels{eq[0], eq[1], eq[2], eq[3], eq[4], eq[5], eq[6], eq[7]};
        }
        if (json.contains("papers")) {
            for (const nlohmann::json& p : json.at("papers")) plan.papers.push_back({p.at(0).get<double>(), p.at(1).get<double>()});
            plan.coverage.stain_area_cm2_per_ul = at(json, "stain_area_cm2_per_ul", "").get<double>();
        }
        if (json.contains("dose_strip")) {
            const std::vector<double> r = json.at("dose_strip").get<std::vector<double>>();
            if (r.size() != 4) throw std::runtime_error("boundary judging plan: dose_strip needs 4 numbers");
            plan.dose_strip = GroundRect{r[0], r[1], r[2], r[3]};
        }
        if (json.contains("guidance_route")) {
            plan.guidance_route = json.at("guidance_route").get<std::vector<std::array<double, 3>>>();
            if (plan.guidance_route.size() > kGuidanceRouteMaxPoints) {
                throw std::runtime_error("boundary judging plan: guidance_route has more than " +
                                         std::to_string(kGuidanceRouteMaxPoints) + " points");
            }
        }
        if (plan.centre_rule && plan.area.size() < 3) {
            throw std::runtime_error("boundary judging plan: centre_rule needs `area` with at least 3 corners");
        }
        return plan;
    } catch (const nlohmann::json::exception& error) {
        throw std::runtime_error(std::string("boundary judging plan: ") + error.what());
    }
}

std::vector<NozzleStepTruth> nozzle_step_truth(const RecordedTrace& trace) {
    // The plant publishes a vehicle2d and a nozzles sample for each instant it reports.
    std::map<TimeNs, std::pair<double, double>> vehicle;  // t -> heading, boom height
    for (const RecordedSample& s : trace.samples(topics::kVehicle2dTruth)) {
        vehicle[s.json.at("time_ns").get<TimeNs>()] = {s.json.at("heading_deg").get<double>(),
                                                       s.json.at("boom_height_m").get<double>()};
    }
    std::vector<NozzleStepTruth> steps;
    for (const RecordedSample& s : trace.samples(topics::kNozzlesTruth)) {
        NozzleStepTruth step;
        step.t_ns = s.json.at("time_ns").get<TimeNs>();
        const auto v = vehicle.find(step.t_ns);
        if (v == vehicle.end()) {
            throw std::runtime_error("truth/nozzles at t_ns " + std::to_string(step.t_ns) +
                                     " has no truth/vehicle2d sample of the same instant");
        }
        step.heading_deg = v->second.first;
        step.boom_height_m = v->second.second;
        for (const nlohmann::json& n : s.json.at("nozzles")) {
            step.position.push_back(field2d::Vec2{n.at("east_m").get<double>(), n.at("north_m").get<double>()});
            step.duty_pct.push_back(n.at("duty_pct").get<double>());
            step.delivered_l.push_back(n.at("delivered_l").get<double>());
        }
        steps.push_back(std::move(step));
    }
    std::stable_sort(steps.begin(), steps.end(), [](const NozzleStepTruth& a, const NozzleStepTruth& b) { return a.t_ns < b.t_ns; });
    check_volumes_grow(steps);
    return steps;
}

std::vector<DoseRaster> ground_from_truth(const std::vector<NozzleStepTruth>& steps, const BoundaryJudgingPlan& plan) {
    check_volumes_grow(steps);
    field2d::DepositionGrid2d grid(plan.ground);
    std::vector<double> previous(static_cast<std::size_t>(plan.ground.nozzle_count), 0.0);
    for (const NozzleStepTruth& step : steps) {
        if (step.delivered_l.size() != previous.size()) {
            throw std::runtime_error("truth/nozzles at t_ns " + std::to_string(step.t_ns) + " has " +
                                     std::to_string(step.delivered_l.size()) + " nozzles, the plan " +
                                     std::to_string(previous.size()));
        }
        const double width_m = field2d::fan_width_m(step.boom_height_m, plan.fan_angle_deg);
        for (std::size_t n = 0; n < previous.size(); ++n) {
            const double litres = step.delivered_l[n] - previous[n];
            previous[n] = step.delivered_l[n];
            if (litres > 0.0) {
                grid.deposit_band(static_cast<int>(n), step.position[n], step.heading_deg, width_m,
                                  plan.band_thickness_m, litres);
            }
        }
    }
    std::vector<DoseRaster> layers;
    for (int n = 0; n < plan.ground.nozzle_count; ++n) layers.push_back(raster_of(grid, n));
    return layers;
}

std::vector<FlowRecord> flow_records_from_truth(const std::vector<NozzleStepTruth>& steps, const BoundaryJudgingPlan& plan) {
    std::vector<FlowRecord> records;
    const TimeNs settle = seconds_to_ns(plan.flow_settle_s);
    const double period_s = plan.pwm_period_s;
    const std::size_t nozzles = steps.empty() ? 0 : steps.front().duty_pct.size();
    for (std::size_t n = 0; n < nozzles; ++n) {
        // Runs of samples at one (non-zero) duty.
        std::size_t begin = 0;
        while (begin < steps.size()) {
            const double duty = steps[begin].duty_pct[n];
            std::size_t end = begin;
            while (end < steps.size() && steps[end].duty_pct[n] == duty) ++end;
            if (duty > 0.0) {
                std::size_t a = begin;
                while (a < end && steps[a].t_ns < steps[begin].t_ns + settle) ++a;
                // The end sample that makes the window closest to a whole number of PWM periods.
                std::size_t best = end;
                double best_miss = INFINITY;
                for (std::size_t b = end; b-- > a + 1;) {
                    const double span_s = ns_to_seconds(steps[b].t_ns - steps[a].t_ns);
                    if (span_s < period_s) break;
                    if (ns_to_seconds(steps[end - 1].t_ns - steps[b].t_ns) > period_s) break;
                    const double miss = std::abs(span_s / period_s - std::round(span_s / period_s));
                    if (miss < best_miss) {
                        best_miss = miss;
                        best = b;
                    }
                }
                if (best < end) {
                    records.push_back(FlowRecord{static_cast<int>(n), duty,
                                                 steps[best].delivered_l[n] - steps[a].delivered_l[n],
                                                 ns_to_seconds(steps[best].t_ns - steps[a].t_ns)});
                }
            }
            begin = end;
        }
    }
    return records;
}

std::vector<RoiJudged> rois_from_trace(const RecordedTrace& trace, const VisionJudging& judging) {
    const auto samples = [&](const char* topic) -> const std::vector<RecordedSample>& { return trace.samples(topic); };
    // The controller's reports by (camera, frame number); the first one counts.
    std::map<std::pair<int, long>, const nlohmann::json*> reports;
    for (const RecordedSample& s : samples(topics::kVisionReport)) {
        reports.emplace(std::make_pair(s.json.at("camera").get<int>(), s.json.at("frame_number").get<long>()), &s.json);
    }
    // The duties commanded, in time order (the trace's round time is when the plant could take them).
    std::vector<std::pair<TimeNs, std::vector<double>>> duties;
    for (const RecordedSample& s : samples(topics::kNozzlePwm)) {
        duties.emplace_back(s.t_ns, s.json.at("duty_pct").get<std::vector<double>>());
    }
    std::stable_sort(duties.begin(), duties.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    const TimeNs delay = seconds_to_ns(judging.decision_delay_s);
    std::vector<RoiJudged> rois;
    for (const RecordedSample& s : samples(topics::kCameraViewTruth)) {
        const nlohmann::json& view = s.json;
        const TimeNs t_ns = view.at("time_ns").get<TimeNs>();
        const int camera = view.at("camera").get<int>();
        const long frame = view.at("frame_number").get<long>();
        const auto report = reports.find({camera, frame});
        // The last command at or before the decision instant.
        const auto after = std::upper_bound(duties.begin(), duties.end(), t_ns + delay,
                                            [](TimeNs t, const auto& d) { return t < d.first; });
        for (const nlohmann::json& n : view.at("nozzles")) {
            const double east = n.at("roi_centre_east_m").get<double>();
            const double north = n.at("roi_centre_north_m").get<double>();
            if (!(east >= judging.east_min_m && east <= judging.east_max_m && north >= judging.north_min_m &&
                  north <= judging.north_max_m)) {
                continue;
            }
            RoiJudged roi;
            roi.t_s = ns_to_seconds(t_ns);
            roi.camera = camera;
            roi.frame_number = frame;
            roi.nozzle = n.at("nozzle").get<int>();
            roi.centre_east_m = east;
            roi.centre_north_m = north;
            roi.true_density = n.at("density").get<double>();
            roi.true_speed_m_s = view.at("speed_m_s").get<double>();
            roi.delivered = view.at("delivered").get<bool>();
            if (report != reports.end()) {
                roi.reported = true;
                for (const nlohmann::json& r : report->second->at("nozzles")) {
                    if (r.at("nozzle").get<int>() != roi.nozzle || !r.at("measured").get<bool>()) continue;
                    roi.measured = true;
                    roi.measured_density = r.at("density").get<double>();
                }
            }
            if (after != duties.begin()) {
                const std::vector<double>& duty = std::prev(after)->second;
                if (static_cast<std::size_t>(roi.nozzle) < duty.size()) roi.duty_pct = duty[static_cast<std::size_t>(roi.nozzle)];
            }
            rois.push_back(roi);
        }
    }
    return rois;
}

DoseCells dose_cells(const DoseRaster& total, const GroundRect& rect, const std::string& what) {
    const double east_max = total.east0_m + total.cell_m * static_cast<double>(total.nx);
    const double north_max = total.north0_m + total.cell_m * static_cast<double>(total.ny);
    if (!(rect.east_min_m >= total.east0_m && rect.east_max_m <= east_max && rect.north_min_m >= total.north0_m &&
          rect.north_max_m <= north_max)) {
        throw std::runtime_error(what + " (east " + std::to_string(rect.east_min_m) + " .. " + std::to_string(rect.east_max_m) +
                                 " m, north " + std::to_string(rect.north_min_m) + " .. " + std::to_string(rect.north_max_m) +
                                 " m) reaches off the judge's ground grid");
    }
    DoseCells cells;
    for (std::size_t iy = 0; iy < total.ny; ++iy) {
        const double north = total.north0_m + (static_cast<double>(iy) + 0.5) * total.cell_m;
        if (north < rect.north_min_m || north > rect.north_max_m) continue;
        for (std::size_t ix = 0; ix < total.nx; ++ix) {
            const double east = total.east0_m + (static_cast<double>(ix) + 0.5) * total.cell_m;
            if (east < rect.east_min_m || east > rect.east_max_m) continue;
            cells.dose_ul_cm2.push_back(total.dose_ul_cm2[iy * total.nx + ix]);
        }
    }
    return cells;
}

namespace {

// The rear axle's offset from the route and its heading error, per truth/vehicle2d
// sample: against the nearest route point (searched near the last one, the
// samples coming in time order), along that point's normal.
std::vector<GuidanceErrorSample> guidance_errors(const RecordedTrace& trace,
                                                 const std::vector<std::array<double, 3>>& route) {
    std::vector<GuidanceErrorSample> errors;
    std::size_t nearest = 0;
    bool first = true;
    for (const RecordedSample& s : trace.samples(topics::kVehicle2dTruth)) {
        const field2d::Vec2 axle{s.json.at("east_m").get<double>(), s.json.at("north_m").get<double>()};
        const auto distance_sq = [&](std::size_t i) {
            const field2d::Vec2 d = axle - field2d::Vec2{route[i][0], route[i][1]};
            return field2d::dot(d, d);
        };
        // The first sample searches the whole route, the rest a stretch around the last match.
        const std::size_t window = 400;
        const std::size_t from = first ? 0 : (nearest > window ? nearest - window : 0);
        const std::size_t to = first ? route.size() : std::min(route.size(), nearest + window + 1);
        first = false;
        for (std::size_t i = from; i < to; ++i) {
            if (distance_sq(i) < distance_sq(nearest)) nearest = i;
        }
        const std::array<double, 3>& at = route[nearest];
        GuidanceErrorSample error;
        error.t_ns = s.t_ns;
        error.cross_track_m = field2d::dot(axle - field2d::Vec2{at[0], at[1]}, field2d::right_of(at[2]));
        error.heading_error_deg = field2d::heading_difference_deg(s.json.at("heading_deg").get<double>(), at[2]);
        error.speed_m_s = s.json.at("speed_m_s").get<double>();
        errors.push_back(error);
    }
    return errors;
}

}  // namespace

MetricSet boundary_trace_metrics(const RecordedTrace& trace, const BoundaryJudgingPlan& plan) {
    MetricSet metrics;
    if (!plan.guidance_route.empty()) metrics.merge(guidance_metrics(guidance_errors(trace, plan.guidance_route), "axle"));
    const std::vector<NozzleStepTruth> steps = nozzle_step_truth(trace);
    std::optional<DoseRaster> total;  // the ground, when something below needs it
    if (plan.vision.enabled || !plan.papers.empty() || plan.dose_strip) total = sum_rasters(ground_from_truth(steps, plan));
    if (plan.vision.enabled) {
        const std::vector<RoiJudged> rois = rois_from_trace(trace, plan.vision);
        for (const auto& [name, value] : vision_metrics(rois, plan.vision, metrics.not_measured)) metrics.values[name] = value;
        // The dose around each ROI's centre: a 0.2 m square, whatever the heading.
        std::vector<double> doses;
        for (const RoiJudged& roi : rois) {
            const GroundRect square{roi.centre_east_m - 0.1, roi.centre_east_m + 0.1, roi.centre_north_m - 0.1,
                                    roi.centre_north_m + 0.1};
            try {
                const DoseCells cells = dose_cells(*total, square, "ROI");
                double sum = 0.0;
                for (const double d : cells.dose_ul_cm2) sum += d;
                doses.push_back(cells.dose_ul_cm2.empty() ? NAN : sum / static_cast<double>(cells.dose_ul_cm2.size()));
            } catch (const std::runtime_error&) {
                doses.push_back(NAN);  // off the judge's ground grid
            }
        }
        for (const auto& [name, value] : dose_by_cover_metrics(rois, doses, metrics.not_measured)) metrics.values[name] = value;
    }
    if (!plan.papers.empty() || plan.dose_strip) {
        std::vector<DoseCells> papers;
        for (std::size_t i = 0; i < plan.papers.size(); ++i) {
            papers.push_back(dose_cells(*total, paper_at(plan.papers[i].east_m, plan.papers[i].north_m),
                                        "papers[" + std::to_string(i) + "]"));
        }
        for (const auto& [name, value] : paper_metrics(papers, plan.coverage)) metrics.values[name] = value;
        if (plan.dose_strip) {
            for (const auto& [name, value] :
                 strip_metrics(dose_cells(*total, *plan.dose_strip, "dose_strip"), plan.coverage, metrics.not_measured)) {
                metrics.values[name] = value;
            }
        }
    }
    if (!plan.edges.empty()) {
        const std::vector<DoseRaster> layers = ground_from_truth(steps, plan);
        const DoseRaster ground = sum_rasters(layers);
        for (const BoundaryEdgePlan& e : plan.edges) {
            for (const auto& [name, value] : excess_metrics(e.metric, wet_edge_profile(ground, e.edge, e.probe), metrics.not_measured)) {
                metrics.values[name] = value;
            }
            std::vector<EdgeProfile> per_nozzle;
            for (const DoseRaster& layer : layers) per_nozzle.push_back(wet_edge_profile(layer, e.edge, e.probe));
            for (const auto& [name, value] : per_nozzle_excess_metrics(e.metric, per_nozzle, metrics.not_measured)) {
                metrics.values[name] = value;
            }
        }
    }
    if (plan.centre_rule) {
        // The boom centre is the nozzles' midpoint (they sit symmetric about it).
        std::vector<CentreRuleSample> samples;
        std::vector<double> previous;
        for (const NozzleStepTruth& step : steps) {
            if (step.position.empty()) continue;
            CentreRuleSample sample;
            sample.t_s = ns_to_seconds(step.t_ns);
            for (const field2d::Vec2& p : step.position) {
                sample.centre.east_m += p.east_m / static_cast<double>(step.position.size());
                sample.centre.north_m += p.north_m / static_cast<double>(step.position.size());
            }
            previous.resize(step.delivered_l.size(), 0.0);
            for (std::size_t n = 0; n < step.delivered_l.size(); ++n) {
                sample.volume_l += step.delivered_l[n] - previous[n];  // >= 0: nozzle_step_truth checked
                previous[n] = step.delivered_l[n];
            }
            samples.push_back(sample);
        }
        for (const auto& [name, value] :
             centre_rule_metrics(samples, field2d::Polygon(plan.area, "target area"), metrics.not_measured)) {
            metrics.values[name] = value;
        }
    }
    if (plan.flow_per_duty) {
        const field2d::NozzleFlowTable table(plan.flow_table);
        const std::vector<FlowCheckRow> rows = flow_against_table(flow_records_from_truth(steps, plan), table);
        for (const FlowCheckRow& row : rows) {
            const std::string key = "flow_nozzle" + std::to_string(row.nozzle) + "_duty" +
                                    std::to_string(static_cast<int>(std::lround(row.duty_pct)));
            metrics.values[key + "_l_min"] = row.delivered_ml_min / 1000.0;
        }
        for (const auto& [name, value] : flow_table_metrics(rows)) metrics.values[name] = value;
        if (rows.size() >= 2) {
            for (const auto& [name, value] : eq13_fit_metrics(rows)) metrics.values[name] = value;
        } else {
            metrics.not_measured["flow_table_max_abs_error_pct"] = "fewer than two duties held";
        }
    }
    return metrics;
}

namespace {

// Seed 001's vision: every ROI's true and measured cover, and the frames the
// run kept for the report (meta vision_report_frames, PNGs beside the trace).
void add_vision_figures(const RecordedTrace& trace, BoundaryFigures& figures) {
    const std::vector<RecordedSample>& views = trace.samples(topics::kCameraViewTruth);
    if (views.empty()) return;
    std::map<std::pair<int, long>, std::map<int, double>> measured;  // (camera, frame) -> nozzle -> D
    {
        for (const RecordedSample& s : trace.samples(topics::kVisionReport)) {
            std::map<int, double>& by_nozzle =
                measured[{s.json.at("camera").get<int>(), s.json.at("frame_number").get<long>()}];
            for (const nlohmann::json& n : s.json.at("nozzles")) {
                if (n.at("measured").get<bool>()) by_nozzle.emplace(n.at("nozzle").get<int>(), n.at("density").get<double>());
            }
        }
    }
    std::map<std::pair<int, long>, std::vector<VisionRoiSample>> by_frame;
    for (const RecordedSample& s : views) {
        const int camera = s.json.at("camera").get<int>();
        const long frame = s.json.at("frame_number").get<long>();
        const auto found = measured.find({camera, frame});
        for (const nlohmann::json& n : s.json.at("nozzles")) {
            VisionRoiSample roi;
            roi.camera = camera;
            roi.nozzle = n.at("nozzle").get<int>();
            roi.east_m = n.at("roi_centre_east_m").get<double>();
            roi.north_m = n.at("roi_centre_north_m").get<double>();
            roi.true_pct = 100.0 * n.at("density").get<double>();
            if (found != measured.end()) {
                if (const auto d = found->second.find(roi.nozzle); d != found->second.end()) roi.measured_pct = 100.0 * d->second;
            }
            figures.rois.push_back(roi);
            by_frame[{camera, frame}].push_back(roi);
        }
    }
    const nlohmann::json kept = nlohmann::json::parse(trace.meta_or("vision_report_frames", "[]"));
    for (const nlohmann::json& k : kept) {
        VisionFrameImage image;
        image.camera = k.at("camera").get<int>();
        image.frame_number = k.at("frame_number").get<long>();
        image.file = trace.file.parent_path() / k.at("file").get<std::string>();
        image.rois = by_frame[{image.camera, image.frame_number}];
        figures.frames.push_back(std::move(image));
    }
}

}  // namespace

SystemJudgement judge_boundary_trace(const RecordedTrace& trace, const BoundaryJudgingPlan& plan) {
    SystemJudgement judged;
    judged.metrics = boundary_trace_metrics(trace, plan);
    auto figures = std::make_shared<BoundaryFigures>();
    add_vision_figures(trace, *figures);
    judged.figures = std::move(figures);
    return judged;
}

}  // namespace rig::harness
