#include "controller/boundary/boundary_node_config.h"

#include <stdexcept>

namespace rig::controller::boundary {
namespace {

// Every numeric key is read unbounded here (finite) and held to the bounds
// declared beside the field by validate(): the bounds live in one place.
const Bounds kFinite = Bounds::closed(-1e9, 1e9);

void read_double(const YamlSection& s, const char* key, double& value) {
    value = s.optional_in_range<double>(key, value, kFinite);
}

TargetAreaConfig read_area(const YamlSection& s) {
    TargetAreaConfig area;
    area.name = s.required<std::string>("name");
    for (const YamlSection& corner : s.list("corners")) {
        area.corners.push_back(GeoCorner{corner.required_in_range<double>("lat_deg", Bounds::closed(-80, 84)),
                                         corner.required_in_range<double>("lon_deg", Bounds::closed(-180, 180))});
    }
    area.density = s.optional_in_range<double>("density", area.density, Bounds::closed(0, 1));
    return area;
}

}  // namespace

namespace {

BoundaryNodeConfig parse_section(const YamlSection& section, const std::optional<BoundaryJob>& job, bool require_areas) {
    BoundaryNodeConfig node;
    BoundaryControllerConfig& c = node.controller;
    section.allow("command");  // the rig's key (kControllerRigKeys)
    for (const YamlSection& area : section.list("areas")) c.areas.push_back(read_area(area));
    if (c.areas.empty() && job) c.areas = job->areas;
    // The sprayer as the job gives it, unless the section says otherwise (read below).
    if (job) {
        c.nozzle_count = job->nozzle_count;
        c.nozzle_spacing_m = job->nozzle_spacing_m;
        c.lift_rod_length_m = job->lift_rod_length_m;
        c.lift_hinge_height_m = job->lift_hinge_height_m;
        c.antenna_to_o_m = job->antenna_to_o_m;
        c.hinge_to_boom_centre_m = job->hinge_to_boom_centre_m;
        c.laser_mount_offset_m = job->laser_mount_offset_m;
        c.pwm_frequency_hz = job->pwm_frequency_hz;
    }
    c.nozzle_count = section.optional_in_range<int>("nozzle_count", c.nozzle_count, Bounds::closed(1, 32));
    read_double(section, "nozzle_spacing_m", c.nozzle_spacing_m);
    read_double(section, "lift_rod_length_m", c.lift_rod_length_m);
    read_double(section, "lift_hinge_height_m", c.lift_hinge_height_m);
    read_double(section, "antenna_to_o_m", c.antenna_to_o_m);
    read_double(section, "hinge_to_boom_centre_m", c.hinge_to_boom_centre_m);
    read_double(section, "boom_centre_right_of_antenna_m", c.boom_centre_right_of_antenna_m);
    read_double(section, "laser_mount_offset_m", c.laser_mount_offset_m);
    read_double(section, "default_boom_height_m", c.default_boom_height_m);
    read_double(section, "k_max_cover", c.k_max_cover);
    read_double(section, "eq12_coefficient_l_min_per_m_s", c.eq12_coefficient_l_min_per_m_s);
    read_double(section, "eq13_slope_l_min_per_pct", c.eq13_slope_l_min_per_pct);
    read_double(section, "eq13_intercept_l_min", c.eq13_intercept_l_min);
    read_double(section, "level0_max_pct", c.level0_max_pct);
    read_double(section, "level1_max_pct", c.level1_max_pct);
    read_double(section, "level1_duty_pct", c.level1_duty_pct);
    read_double(section, "level2_duty_pct", c.level2_duty_pct);
    read_double(section, "pwm_frequency_hz", c.pwm_frequency_hz);
    c.lookahead_enabled = section.optional<bool>("lookahead_enabled", c.lookahead_enabled);
    read_double(section, "lookahead_on_s", c.lookahead_on_s);
    read_double(section, "lookahead_off_s", c.lookahead_off_s);
    read_double(section, "course_hold_speed_m_s", c.course_hold_speed_m_s);
    read_double(section, "fix_timeout_s", c.fix_timeout_s);
    c.correct_grid_convergence = section.optional<bool>("correct_grid_convergence", c.correct_grid_convergence);

    const YamlSection faults = section.section("faults");
    read_double(faults, "antenna_offset_error_m", c.faults.antenna_offset_error_m);
    c.faults.no_course_rotation = faults.optional<bool>("no_course_rotation", false);
    c.faults.ignore_boom_height = faults.optional<bool>("ignore_boom_height", false);
    c.faults.lookahead_sign_flipped = faults.optional<bool>("lookahead_sign_flipped", false);
    c.faults.ignore_centre_rule = faults.optional<bool>("ignore_centre_rule", false);
    c.faults.extra_duty_entry = faults.optional<bool>("extra_duty_entry", false);
    read_double(faults, "command_delay_s", c.faults.command_delay_s);

    // The cameras on the boom are used unless the section says how (or not).
    const bool vision_from_job = job && job->cameras && !section.has("vision");
    const YamlSection vision = section.section("vision");
    VisionNodeConfig& v = node.vision;
    v.enabled = vision.optional<bool>("enabled", v.enabled);
    read_double(vision, "roi_width_m", v.params.roi_width_m);
    read_double(vision, "roi_near_m", v.params.roi_near_m);
    read_double(vision, "roi_depth_m", v.params.roi_depth_m);
    read_double(vision, "warp_mm_per_px", v.params.warp_mm_per_px);
    v.params.exg_floor = vision.optional_in_range<int>("exg_floor", v.params.exg_floor, Bounds::closed(0, 255));
    read_double(vision, "dark_frame_mean_max_dn", v.params.dark_frame_mean_max_dn);
    read_double(vision, "min_roi_share_in_frame", v.params.min_roi_share_in_frame);
    v.blind_level = vision.optional_in_range<int>("blind_level", v.blind_level, Bounds::closed(0, 2));
    v.density_max_age_s = vision.optional_in_range<double>("density_max_age_s", v.density_max_age_s, Bounds::open_closed(0, 60));
    v.calibration_until_s =
        vision.optional_in_range<double>("calibration_until_s", v.calibration_until_s, Bounds::closed(0, 600));
    if (vision_from_job) {
        v.enabled = true;
        v.calibration_until_s = job->calibration_scene_until_s;
    }
    try {
        vision::validate(v.params);
    } catch (const std::invalid_argument& error) {
        vision.fail(error.what());
    }

    const YamlSection sweep = section.section("calibration");
    const std::vector<std::string> duties = sweep.string_list("duties_pct");
    for (std::size_t i = 0; i < duties.size(); ++i) {
        const std::string& text = duties[i];
        double duty = 0.0;
        try {
            std::size_t used = 0;
            duty = std::stod(text, &used);
            if (used != text.size()) throw std::invalid_argument(text);
        } catch (const std::exception&) {
            throw ConfigError(sweep.item_location("duties_pct", i), "a duty in %, got '" + text + "'");
        }
        if (!(duty >= 0.0 && duty <= 100.0)) {
            throw ConfigError(sweep.item_location("duties_pct", i), "a duty must be in [0, 100] %, got " + text);
        }
        node.calibration.duties_pct.push_back(duty);
    }
    node.calibration.start_s = sweep.optional_in_range<double>("start_s", node.calibration.start_s, Bounds::closed(0, 3600));
    node.calibration.hold_s = sweep.optional_in_range<double>("hold_s", node.calibration.hold_s, Bounds::open_closed(0, 3600));
    section.finish();
    try {
        if (require_areas || !c.areas.empty()) validate_areas(c.areas);
        validate_settings(c);
    } catch (const std::invalid_argument& error) {
        section.fail(error.what());
    }
    return node;
}

}  // namespace

BoundaryNodeConfig parse_boundary_node_config(const YamlSection& section, const std::optional<BoundaryJob>& job) {
    return parse_section(section, job, /*require_areas=*/true);
}

void check_boundary_node_config(const YamlSection& section) { parse_section(section, std::nullopt, /*require_areas=*/false); }

BoundaryNodeConfig load_boundary_node_config(const std::filesystem::path& file,
                                             const std::optional<std::filesystem::path>& job_file) {
    std::optional<BoundaryJob> job;
    if (job_file) job = load_boundary_job(*job_file);
    return parse_boundary_node_config(YamlSection::load_file(file), job);
}

BoundaryJob load_boundary_job(const std::filesystem::path& file) {
    const YamlSection root = YamlSection::load_file(file);
    BoundaryJob job;
    const YamlSection origin = root.required_section("field").required_section("origin");
    job.field_origin = GeoCorner{origin.required_in_range<double>("lat_deg", Bounds::closed(-80, 84)),
                                 origin.required_in_range<double>("lon_deg", Bounds::closed(-180, 180))};
    job.field_origin_height_m = origin.required_in_range<double>("height_m", Bounds::closed(-1000, 10000));
    for (const YamlSection& area : root.list("areas")) job.areas.push_back(read_area(area));
    if (job.areas.empty()) root.fail("areas", "a job names at least one target area");
    // Bounds as the reference's own keys have them (validate() holds the
    // configuration they go into to the same ones).
    const YamlSection sprayer = root.required_section("sprayer");
    job.nozzle_count = sprayer.required_in_range<int>("nozzle_count", Bounds::closed(1, 32));
    job.nozzle_spacing_m = sprayer.required_in_range<double>("nozzle_spacing_m", kFinite);
    const YamlSection lift = sprayer.required_section("lift");
    job.lift_rod_length_m = lift.required_in_range<double>("rod_length_m", kFinite);
    job.lift_hinge_height_m = lift.required_in_range<double>("hinge_height_m", kFinite);
    job.antenna_to_o_m = lift.required_in_range<double>("antenna_to_o_m", kFinite);
    job.hinge_to_boom_centre_m = lift.required_in_range<double>("hinge_to_boom_centre_m", kFinite);
    job.laser_mount_offset_m = root.required_section("laser").required_in_range<double>("mount_offset_m", kFinite);
    job.pwm_frequency_hz = root.required_section("valves").required_in_range<double>("frequency_hz", kFinite);
    if (root.has("cameras")) {
        const YamlSection cameras = root.section("cameras");
        job.cameras = true;
        job.left_camera_topic = cameras.optional<std::string>("left", "");
        job.right_camera_topic = cameras.optional<std::string>("right", "");
        job.calibration_scene_until_s =
            cameras.optional_in_range<double>("calibration_scene_until_s", 0.0, Bounds::closed(0, 600));
    }
    root.finish();
    return job;
}

}  // namespace rig::controller::boundary
