#include "harness/boundary_case.h"

#include <stdexcept>

#include "emulators/field2d/polygon.h"

namespace rig::harness {
namespace {

// Values are read finite and unbounded here; the emulators' own checks (run by
// check_boundary_case) hold each to the bounds declared beside its parameter.
const Bounds kFinite = Bounds::closed(-1e9, 1e9);

void read(const YamlSection& s, const char* key, double& value) { value = s.optional_in_range<double>(key, value, kFinite); }

field2d::GeodeticPoint read_corner(const YamlSection& s) {
    return field2d::GeodeticPoint{s.required_in_range<double>("lat_deg", Bounds::closed(-80, 84)),
                                  s.required_in_range<double>("lon_deg", Bounds::closed(-180, 180)), 0.0};
}

field2d::RouteSegment read_segment(const YamlSection& item) {
    const std::vector<std::string> kinds = item.keys();
    if (kinds.size() != 1) item.fail("a segment is one of `straight: {...}`, `turn: {...}`, `stand: {...}`");
    const YamlSection s = item.section(kinds.front());
    if (kinds.front() == "straight") {
        field2d::StraightSegment straight;
        straight.length_m = s.required_in_range<double>("length_m", kFinite);
        straight.speed_m_s = s.required_in_range<double>("speed_m_s", kFinite);
        read(s, "accel_m_s2", straight.accel_m_s2);
        straight.stop_at_end = s.optional<bool>("stop_at_end", straight.stop_at_end);
        return straight;
    }
    if (kinds.front() == "turn") {
        field2d::TurnSegment turn;
        turn.radius_m = s.required_in_range<double>("radius_m", kFinite);
        turn.angle_deg = s.required_in_range<double>("angle_deg", kFinite);
        turn.speed_m_s = s.required_in_range<double>("speed_m_s", kFinite);
        read(s, "accel_m_s2", turn.accel_m_s2);
        turn.stop_at_end = s.optional<bool>("stop_at_end", turn.stop_at_end);
        return turn;
    }
    if (kinds.front() == "stand") return field2d::StandSegment{s.required_in_range<double>("duration_s", kFinite)};
    item.fail(kinds.front(), "a segment is one of straight, turn, stand; got '" + kinds.front() + "'");
}

void read_mounting(const YamlSection& s, BoundaryCaseSpec& spec) {
    field2d::SprayerMounting& m = spec.mounting;
    read(s, "antenna_forward_of_axle_m", m.antenna_forward_of_axle_m);
    read(s, "antenna_right_m", m.antenna_right_m);
    read(s, "antenna_height_m", m.antenna_height_m);
    m.nozzle_count = s.optional_in_range<int>("nozzle_count", m.nozzle_count, Bounds::closed(1, 32));
    read(s, "nozzle_spacing_m", m.nozzle_spacing_m);
    const YamlSection lift = s.section("lift");
    read(lift, "rod_length_m", m.lift.rod_length_m);
    read(lift, "hinge_height_m", m.lift.hinge_height_m);
    read(lift, "antenna_to_o_m", m.lift.antenna_to_o_m);
    read(lift, "hinge_to_boom_centre_m", m.lift.hinge_to_boom_centre_m);
    if (s.has("boom_height")) {
        spec.boom_height.clear();
        for (const YamlSection& knot : s.list("boom_height")) {
            spec.boom_height.push_back(field2d::HeightKnot{knot.required_in_range<double>("t_s", Bounds::closed(0, 86400)),
                                                           knot.required_in_range<double>("height_m", kFinite)});
        }
    }
}

BoundaryEdgeJudging read_edge(const YamlSection& s) {
    BoundaryEdgeJudging edge;
    edge.metric = s.required_enum("metric", kBoundaryEdgeMetrics);
    const YamlSection near = s.required_section("near");
    edge.near = field2d::Vec2{near.required_in_range<double>("east_m", Bounds::closed(-1e5, 1e5)),
                              near.required_in_range<double>("north_m", Bounds::closed(-1e5, 1e5))};
    edge.probe.from_m = s.optional_in_range<double>("from_m", edge.probe.from_m, Bounds::closed(0, 1e5));
    edge.probe.to_m = s.optional_in_range<double>("to_m", edge.probe.to_m, Bounds::closed(-1, 1e5));
    edge.probe.spacing_m = s.optional_in_range<double>("spacing_m", edge.probe.spacing_m, Bounds::open_closed(0, 100));
    edge.probe.search_inside_m =
        s.optional_in_range<double>("search_inside_m", edge.probe.search_inside_m, Bounds::closed(0, 100));
    edge.probe.search_outside_m =
        s.optional_in_range<double>("search_outside_m", edge.probe.search_outside_m, Bounds::closed(0, 100));
    return edge;
}

// A check an emulator's constructor makes, reported at the case's section.
template <class Build>
void checked(const YamlSection& section, Build build) {
    try {
        build();
    } catch (const std::exception& error) {
        section.fail(error.what());
    }
}

}  // namespace

field2d::NozzleFlowTable BoundaryCaseSpec::flow_table_or_paper() const {
    return flow_table.empty() ? field2d::NozzleFlowTable::paper_table3() : field2d::NozzleFlowTable(flow_table);
}

BoundaryCaseSpec read_boundary_case(const YamlSection& root) {
    BoundaryCaseSpec spec;
    const YamlSection origin = root.required_section("field").required_section("origin");
    spec.origin.lat_deg = origin.required_in_range<double>("lat_deg", Bounds::closed(-80, 84));
    spec.origin.lon_deg = origin.required_in_range<double>("lon_deg", Bounds::closed(-180, 180));
    spec.origin.height_m = origin.optional_in_range<double>("height_m", 0.0, Bounds::closed(-1000, 10000));

    const YamlSection area = root.required_section("area");
    spec.area_name = area.optional<std::string>("name", spec.area_name);
    for (const YamlSection& corner : area.list("corners")) spec.corners.push_back(read_corner(corner));
    spec.area_density = area.optional_in_range<double>("density", spec.area_density, Bounds::closed(0, 1));

    const YamlSection route = root.required_section("route");
    const YamlSection start = route.required_section("start");
    spec.route_start.position = field2d::Vec2{start.required_in_range<double>("east_m", Bounds::closed(-1e5, 1e5)),
                                              start.required_in_range<double>("north_m", Bounds::closed(-1e5, 1e5))};
    spec.route_start.heading_deg = start.optional_in_range<double>("heading_deg", 0.0, Bounds::closed_open(0, 360));
    spec.route_start.speed_m_s = start.optional_in_range<double>("speed_m_s", 0.0, Bounds::closed(0, 10));
    for (const YamlSection& segment : route.list("segments")) spec.route_segments.push_back(read_segment(segment));
    if (spec.route_segments.size() > 1000) route.fail("segments", "at most 1000 segments");

    read_mounting(root.section("sprayer"), spec);

    const YamlSection spray = root.section("spray");
    read(spray, "fan_angle_deg", spec.spray.fan_angle_deg);
    read(spray, "band_thickness_m", spec.spray.band_thickness_m);
    read(spray, "step_s", spec.spray.step_s);
    for (const YamlSection& nozzle : spray.list("flow_table")) {
        std::vector<field2d::FlowPoint> points;
        for (const YamlSection& point : nozzle.list("points")) {
            points.push_back(field2d::FlowPoint{point.required_in_range<double>("duty_pct", kFinite),
                                                point.required_in_range<double>("flow_ml_min", kFinite)});
        }
        // Table 3 has 8 duties; a calibration table of more than 100 is no measurement.
        if (points.size() > 100) nozzle.fail("points", "at most 100 points per nozzle");
        spec.flow_table.push_back(std::move(points));
    }
    if (spec.flow_table.size() > 32) spray.fail("flow_table", "at most 32 nozzles (the boom's limit)");

    const YamlSection valves = root.section("valves");
    read(valves, "frequency_hz", spec.valves.frequency_hz);
    read(valves, "response_s", spec.valves.response_s);
    spec.valves.pwm_phase_s = valves.maybe<double>("pwm_phase_s");
    spec.valves.latch_at_period_start = valves.optional<bool>("latch_at_period_start", spec.valves.latch_at_period_start);

    const YamlSection ad300 = root.section("ad300");
    spec.ad300.talker = ad300.optional_enum("talker", {"GP", "GN", "BD", "GB"}, spec.ad300.talker);
    read(ad300, "rate_hz", spec.ad300.rate_hz);
    read(ad300, "latency_s", spec.ad300.latency_s);
    spec.ad300.epoch_phase_s = ad300.maybe<double>("epoch_phase_s");
    read(ad300, "noise_base_m", spec.ad300.noise_base_m);
    read(ad300, "noise_ppm", spec.ad300.noise_ppm);
    read(ad300, "baseline_km", spec.ad300.baseline_km);
    read(ad300, "velocity_noise_m_s", spec.ad300.velocity_noise_m_s);
    read(ad300, "min_course_speed_m_s", spec.ad300.min_course_speed_m_s);

    const YamlSection laser = root.section("laser");
    read(laser, "rate_hz", spec.laser.rate_hz);
    read(laser, "latency_s", spec.laser.latency_s);
    spec.laser.phase_s = laser.maybe<double>("phase_s");
    read(laser, "mount_offset_m", spec.laser.mount_offset_m);
    read(laser, "accuracy_base_m", spec.laser.accuracy_base_m);
    read(laser, "accuracy_per_m", spec.laser.accuracy_per_m);

    const YamlSection judge = root.required_section("judge");
    const YamlSection ground = judge.section("ground");
    read(ground, "east_min_m", spec.ground.east_min_m);
    read(ground, "east_max_m", spec.ground.east_max_m);
    read(ground, "north_min_m", spec.ground.north_min_m);
    read(ground, "north_max_m", spec.ground.north_max_m);
    read(ground, "cell_m", spec.ground.cell_m);
    spec.ground.nozzle_count = spec.mounting.nozzle_count;
    spec.wet_threshold_ul_cm2 =
        judge.optional_in_range<double>("wet_threshold_ul_cm2", spec.wet_threshold_ul_cm2, Bounds::open_closed(0, 1000));
    for (const YamlSection& edge : judge.list("edges")) {
        spec.edges.push_back(read_edge(edge));
        spec.edges.back().probe.wet_threshold_ul_cm2 = spec.wet_threshold_ul_cm2;
    }
    // Each edge is a wet-edge profile over the whole ground: a handful per case.
    if (spec.edges.size() > 16) judge.fail("edges", "at most 16 edges");
    spec.judge_flow_per_duty = judge.optional<bool>("flow_per_duty", spec.judge_flow_per_duty);
    spec.flow_settle_s = judge.optional_in_range<double>("flow_settle_s", spec.flow_settle_s, Bounds::closed(0, 60));
    spec.judge_centre_rule = judge.optional<bool>("centre_rule", spec.judge_centre_rule);
    spec.end_after_route_s =
        judge.optional_in_range<double>("end_after_route_s", spec.end_after_route_s, Bounds::closed(0, 600));
    if (spec.edges.empty() && !spec.judge_flow_per_duty && !spec.judge_centre_rule) {
        judge.fail("judge nothing? give `edges`, `flow_per_duty: true` or `centre_rule: true`");
    }
    return spec;
}

void check_boundary_case(const BoundaryCaseSpec& spec, const YamlSection& root) {
    const field2d::LocalFrame frame = spec.frame();
    checked(root.section("area"), [&] { field2d::Polygon::from_geodetic(frame, spec.corners, spec.area_name); });
    std::optional<field2d::Route2d> route;
    checked(root.section("route"), [&] { route.emplace(spec.route_start, spec.route_segments); });
    if (route->end_time_s() > 3600.0) root.section("route").fail("the route lasts more than an hour");
    std::optional<field2d::SprayerKinematics> kinematics;
    checked(root.section("sprayer"), [&] {
        kinematics.emplace(frame, *route, spec.mounting, field2d::BoomHeightProfile(spec.boom_height));
    });
    checked(root.section("spray"), [&] {
        const field2d::NozzleFlowTable table = spec.flow_table_or_paper();
        if (table.nozzle_count() != spec.mounting.nozzle_count) {
            throw std::invalid_argument("flow_table has " + std::to_string(table.nozzle_count()) + " nozzles, the boom " +
                                        std::to_string(spec.mounting.nozzle_count));
        }
        // A one-cell grid: the plant's checks without the judge's memory.
        field2d::DepositionGrid2dParams one_cell;
        one_cell.east_max_m = one_cell.east_min_m + 1.0;
        one_cell.north_max_m = one_cell.north_min_m + 1.0;
        one_cell.cell_m = 1.0;
        one_cell.nozzle_count = spec.mounting.nozzle_count;
        emulators::BoundarySprayPlant(*kinematics, emulators::PwmNozzleValves(spec.valves, table),
                                      field2d::DepositionGrid2d(one_cell), spec.spray);
    });
    checked(root.section("ad300"), [&] { emulators::Ad300Receiver(*kinematics, spec.ad300); });
    checked(root.section("laser"), [&] { emulators::L4LaserSensor(*kinematics, spec.laser); });
    checked(root.section("judge").section("ground"), [&] { field2d::DepositionGrid2d grid(spec.ground); });
}

RawYaml controller_section_with_area(const RawYaml& controller, const BoundaryCaseSpec& spec) {
    RawYaml out = controller;
    // In place (not a clone): the section's nodes keep their marks, so the
    // controller's own errors still point at the case file's lines.
    if (!(controller.present && controller.node.IsMap())) out.node = YAML::Node(YAML::NodeType::Map);
    out.present = true;
    if (out.node["areas"]) return out;
    YAML::Node area;
    area["name"] = spec.area_name;
    area["density"] = spec.area_density;
    for (const field2d::GeodeticPoint& corner : spec.corners) {
        YAML::Node c;
        c["lat_deg"] = corner.lat_deg;
        c["lon_deg"] = corner.lon_deg;
        area["corners"].push_back(c);
    }
    out.node["areas"].push_back(area);
    return out;
}

}  // namespace rig::harness
