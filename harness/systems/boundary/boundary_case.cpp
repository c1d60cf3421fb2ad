#include "harness/systems/boundary/boundary_case.h"

#include <stdexcept>

#include "emulators/field2d/polygon.h"
#include "rig/text/number_text.h"
#include "rig/wire/hid_board_protocol.h"

namespace rig::harness {
namespace {

// Values are read finite and unbounded here; the emulators' own checks (run by
// BoundarySections::check_with) hold each to the bounds declared beside its parameter.
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

void read_mounting(const YamlSection& s, BoundarySections& spec) {
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

field2d::CoverClass read_cover(const YamlSection& s, const char* key, field2d::CoverClass fallback) {
    const std::string name = s.optional_enum(key, {"bare", "sparse", "normal"}, field2d::cover_class_name(fallback));
    return name == "bare" ? field2d::CoverClass::bare : name == "sparse" ? field2d::CoverClass::sparse : field2d::CoverClass::normal;
}

void read_gains(const YamlSection& s, emulators::vision::ChannelGains& gains) {
    read(s, "red", gains.red);
    read(s, "green", gains.green);
    read(s, "blue", gains.blue);
}

// The fields of CameraEmulatorParams a case may set for both cameras (the
// geometry stays Sec. 1.1's; a knocked camera is a fault, not a new mounting).
void read_camera_common(const YamlSection& s, emulators::vision::CameraEmulatorParams& camera) {
    read(s, "noise_sd_dn", camera.noise_sd_dn);
    read(s, "lighting_gain", camera.lighting_gain);
    read_gains(s.section("lighting_cast"), camera.lighting_cast);
    camera.samples_per_axis = s.optional_in_range<int>("samples_per_axis", camera.samples_per_axis, Bounds::closed(1, 8));
    read(s, "frame_rate_hz", camera.frame_rate_hz);
    const int width = s.optional_in_range<int>("width_px", camera.camera.intrinsics.width_px, Bounds::closed(16, 1920));
    const int height = s.optional_in_range<int>("height_px", camera.camera.intrinsics.height_px, Bounds::closed(16, 1080));
    if (width != camera.camera.intrinsics.width_px || height != camera.camera.intrinsics.height_px) {
        // Another resolution is another sensor: the principal point moves to its centre, the focal length scales.
        const double scale = static_cast<double>(width) / camera.camera.intrinsics.width_px;
        camera.camera.intrinsics.fx_px *= scale;
        camera.camera.intrinsics.fy_px *= scale;
        camera.camera.intrinsics.cx_px = width / 2.0;
        camera.camera.intrinsics.cy_px = height / 2.0;
        camera.camera.intrinsics.width_px = width;
        camera.camera.intrinsics.height_px = height;
    }
}

// How the camera truly sits (the controller keeps Sec. 1.1's design as its
// belief): turned on its mount, it is what the board calibration corrects.
void read_camera_mounting(const YamlSection& s, rig::camera::CameraMounting& mounting) {
    read(s, "yaw_deg", mounting.yaw_deg);
    read(s, "roll_deg", mounting.roll_deg);
}

void read_camera_faults(const YamlSection& s, emulators::vision::CameraFaults& faults) {
    read(s, "pitch_offset_deg", faults.pitch_offset_deg);
    faults.blur_radius_px = s.optional_in_range<int>("blur_radius_px", faults.blur_radius_px, Bounds::closed(0, 50));
    read_gains(s.section("colour_cast"), faults.colour_cast);
    const std::string dead = s.optional_enum("dead", {"none", "black_frame", "no_frame"}, "none");
    faults.dead = dead == "black_frame" ? emulators::vision::DeadCamera::black_frame
                  : dead == "no_frame"  ? emulators::vision::DeadCamera::no_frame
                                        : emulators::vision::DeadCamera::none;
}

BoundaryVisionSpec read_vision(const YamlSection& s) {
    BoundaryVisionSpec vision;
    const YamlSection crop = s.section("crop");
    field2d::CropCoverParams& c = vision.crop;
    read(crop, "row_spacing_m", c.row_spacing_m);
    read(crop, "row_bearing_deg", c.row_bearing_deg);
    read(crop, "row_offset_m", c.row_offset_m);
    read(crop, "row_scatter_m", c.row_scatter_m);
    read(crop, "normal_plants_per_m", c.normal_plants_per_m);
    read(crop, "sparse_plants_per_m", c.sparse_plants_per_m);
    read(crop, "plant_height_min_m", c.plant_height_min_m);
    read(crop, "plant_height_max_m", c.plant_height_max_m);
    c.leaves_min = crop.optional_in_range<int>("leaves_min", c.leaves_min, Bounds::closed(1, 20));
    c.leaves_max = crop.optional_in_range<int>("leaves_max", c.leaves_max, Bounds::closed(1, 20));
    read(crop, "leaf_length_per_height_min", c.leaf_length_per_height_min);
    read(crop, "leaf_length_per_height_max", c.leaf_length_per_height_max);
    read(crop, "leaf_width_m", c.leaf_width_m);
    c.default_cover = read_cover(crop, "default_cover", c.default_cover);
    for (const YamlSection& patch : crop.list("patches")) {
        std::vector<field2d::Vec2> corners;
        for (const YamlSection& corner : patch.list("corners")) {
            corners.push_back(field2d::Vec2{corner.required_in_range<double>("east_m", Bounds::closed(-1e5, 1e5)),
                                            corner.required_in_range<double>("north_m", Bounds::closed(-1e5, 1e5))});
        }
        if (corners.size() < 3 || corners.size() > 64) patch.fail("corners", "a patch has 3 to 64 corners");
        const field2d::CoverClass cover = read_cover(patch, "cover", field2d::CoverClass::normal);
        checked(patch, [&] { c.patches.push_back(field2d::CoverPatch{field2d::Polygon(corners, "patch"), cover}); });
    }
    if (c.patches.size() > 64) crop.fail("patches", "at most 64 patches");
    const YamlSection cameras = s.section("cameras");
    read_camera_common(cameras, vision.left);
    read_camera_common(cameras, vision.right);
    read_camera_faults(s.section("left").section("faults"), vision.left.faults);
    read_camera_faults(s.section("right").section("faults"), vision.right.faults);
    read_camera_mounting(s.section("left").section("mounting"), vision.left.camera.mounting);
    read_camera_mounting(s.section("right").section("mounting"), vision.right.camera.mounting);
    vision.calibration_until_s = s.section("calibration").optional_in_range<double>("until_s", vision.calibration_until_s,
                                                                                      Bounds::closed(0, 600));
    return vision;
}

}  // namespace

field2d::NozzleFlowTable BoundarySections::flow_table_or_paper() const {
    return flow_table.empty() ? field2d::NozzleFlowTable::paper_table3() : field2d::NozzleFlowTable(flow_table);
}

std::shared_ptr<const BoundarySections> read_boundary_sections(const YamlSection& root) {
    auto own = std::make_shared<BoundarySections>();
    BoundarySections& spec = *own;
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
    spec.guidance = read_guidance_section(root);

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

    if (root.has("vision")) spec.vision = read_vision(root.section("vision"));

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
    if (spec.vision) {
        VisionJudging& v = spec.vision_judging;
        v.enabled = true;
        const YamlSection zone = judge.section("vision").section("zone");
        read(zone, "east_min_m", v.east_min_m);
        read(zone, "east_max_m", v.east_max_m);
        read(zone, "north_min_m", v.north_min_m);
        read(zone, "north_max_m", v.north_max_m);
        if (!(v.east_min_m < v.east_max_m && v.north_min_m < v.north_max_m)) zone.fail("the zone's min must be below its max");
        v.decision_delay_s = judge.section("vision").optional_in_range<double>("decision_delay_s", v.decision_delay_s,
                                                                                Bounds::closed(0, 10));
        v.eq14.k_max_cover = judge.section("vision").optional_in_range<double>("k_max_cover", v.eq14.k_max_cover,
                                                                               Bounds::open_closed(0, 1));
    } else if (judge.has("vision")) {
        judge.fail("vision", "judging vision needs the case's `vision:` section (the cameras)");
    }
    for (const YamlSection& paper : judge.list("papers")) {
        spec.papers.push_back(field2d::Vec2{paper.required_in_range<double>("east_m", Bounds::closed(-1e5, 1e5)),
                                            paper.required_in_range<double>("north_m", Bounds::closed(-1e5, 1e5))});
    }
    if (spec.papers.size() > 64) judge.fail("papers", "at most 64 papers");
    if (judge.has("dose_strip")) {
        const YamlSection strip = judge.section("dose_strip");
        GroundRect r;
        r.east_min_m = strip.required_in_range<double>("east_min_m", Bounds::closed(-1e5, 1e5));
        r.east_max_m = strip.required_in_range<double>("east_max_m", Bounds::closed(-1e5, 1e5));
        r.north_min_m = strip.required_in_range<double>("north_min_m", Bounds::closed(-1e5, 1e5));
        r.north_max_m = strip.required_in_range<double>("north_max_m", Bounds::closed(-1e5, 1e5));
        if (!(r.east_min_m < r.east_max_m && r.north_min_m < r.north_max_m)) strip.fail("the strip's min must be below its max");
        spec.dose_strip = r;
    }
    spec.coverage.stain_area_cm2_per_ul = judge.optional_in_range<double>(
        "stain_area_cm2_per_ul", spec.coverage.stain_area_cm2_per_ul, Bounds::open_closed(0, 100));
    if (spec.edges.empty() && !spec.judge_flow_per_duty && !spec.judge_centre_rule && !spec.vision && spec.papers.empty() &&
        !spec.dose_strip) {
        judge.fail("judge nothing? give `edges`, `flow_per_duty: true`, `centre_rule: true`, `papers`, `dose_strip` or a `vision:` section");
    }
    return own;
}

const BoundarySections& boundary_sections(const CaseSpec& spec) {
    const auto* own = dynamic_cast<const BoundarySections*>(spec.system.get());
    if (own == nullptr) throw std::logic_error(spec.source_path.string() + ": not a seed-001 (boundary) case");
    return *own;
}

void BoundarySections::check_with(const CaseSpec& common, const YamlSection& root) const {
    // The controller runs as a program (its reference has no plugin).
    if (common.controller.in_process.value_or(false) || !common.controller.plugin.empty()) {
        YamlSection(common.controller.params)
            .fail(common.controller.plugin.empty() ? "in_process" : "plugin",
                  "seed 001's boundary cases run their controller as a program (no in-process mode yet)");
    }
    // The Pi's outputs are six PWM lines, measured by the HID board's capture
    // (docs/hid-io-board.md), or its duties on DDS: it has no Modbus I/O.
    const WiringSpec& wiring = common.wiring;
    if (wiring.board_io == BoardIoWireKind::modbus_rtu || wiring.board_io == BoardIoWireKind::modbus_tcp) {
        root.section("wiring").fail("board_io", "seed 001's nozzle PWM comes on DDS or through the HID board's capture: "
                                                "dds or hid");
    }
    // The capture publishes actuator/nozzle_pwm/duty for the wired board: a
    // controller process beside it would be a second writer of that topic.
    if (wiring.board_io == BoardIoWireKind::hid && !wiring.external_controller) {
        root.section("wiring").fail("board_io", "the HID board captures a wired controller's PWM: needs `controller: external`");
    }
    if (wiring.board_io == BoardIoWireKind::hid) {
        // rig/wire/wire_adapters.h NozzlePwmCaptureAdapter: six capture inputs, read at most at 1 kHz.
        if (wiring.board_update_hz > 1000.0) {
            root.section("wiring").fail("board_update_hz", "the PWM capture is read at most 1000 times a second, got " +
                                                               shortest_text(wiring.board_update_hz));
        }
        const int nozzles = flow_table_or_paper().nozzle_count();
        if (nozzles > hid::kPwmCaptureInputs) {
            root.section("wiring").fail("board_io", "the HID board captures " + std::to_string(hid::kPwmCaptureInputs) +
                                                        " PWM inputs; this sprayer has " + std::to_string(nozzles) +
                                                        " nozzles");
        }
    }
    const BoundarySections& spec = *this;
    const field2d::LocalFrame frame = spec.frame();
    checked(root.section("area"), [&] { field2d::Polygon::from_geodetic(frame, spec.corners, spec.area_name); });
    std::optional<field2d::Route2d> route;
    checked(root.section("route"), [&] { route.emplace(spec.route_start, spec.route_segments); });
    if (route->end_time_s() > 3600.0) root.section("route").fail("the route lasts more than an hour");
    std::optional<field2d::SprayerKinematics> kinematics;
    checked(root.section("sprayer"), [&] {
        kinematics.emplace(frame, *route, spec.mounting, field2d::BoomHeightProfile(spec.boom_height), spec.guidance,
                           common.seed);
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
    if (spec.vision) {
        checked(root.section("vision").section("crop"), [&] { field2d::validate(spec.vision->crop); });
        checked(root.section("vision").section("left"), [&] { emulators::vision::validate(spec.vision->left, "vision.left"); });
        checked(root.section("vision").section("right"), [&] { emulators::vision::validate(spec.vision->right, "vision.right"); });
        if (spec.mounting.nozzle_count % 2 != 0) {
            root.section("sprayer").fail("nozzle_count", "two cameras see half the boom each: an even nozzle count");
        }
    }
}

}  // namespace rig::harness
