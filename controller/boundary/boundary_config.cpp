#include "controller/boundary/boundary_config.h"

#include <cmath>
#include <stdexcept>

namespace rig::controller::boundary {
namespace {

void in_range(const std::string& key, double value, double lo, double hi, bool lo_open = false) {
    const bool ok = std::isfinite(value) && (lo_open ? value > lo : value >= lo) && value <= hi;
    if (!ok) {
        throw std::invalid_argument("boundary." + key + ": must be in " + (lo_open ? "(" : "[") + std::to_string(lo) +
                                    ", " + std::to_string(hi) + "], got " + std::to_string(value));
    }
}

}  // namespace

void validate(const BoundaryControllerConfig& c) {
    validate_areas(c.areas);
    validate_settings(c);
}

void validate_areas(const std::vector<TargetAreaConfig>& areas) {
    if (areas.empty()) throw std::invalid_argument("boundary.areas: at least one target area is needed");
    for (std::size_t i = 0; i < areas.size(); ++i) {
        const TargetAreaConfig& area = areas[i];
        const std::string key = "areas[" + std::to_string(i) + "]";
        if (area.name.empty()) throw std::invalid_argument("boundary." + key + ".name: must not be empty");
        const std::string named = key + " '" + area.name + "'";
        if (area.corners.size() < 3) {
            throw std::invalid_argument("boundary." + named + ".corners: needs at least 3 corners (the paper records 4), got " +
                                        std::to_string(area.corners.size()));
        }
        for (std::size_t k = 0; k < area.corners.size(); ++k) {
            const std::string corner = named + ".corners[" + std::to_string(k) + "]";
            in_range(corner + ".lat_deg", area.corners[k].lat_deg, -80.0, 84.0);
            in_range(corner + ".lon_deg", area.corners[k].lon_deg, -180.0, 180.0);
        }
        in_range(named + ".density", area.density, 0.0, 1.0);
    }
}

void validate_settings(const BoundaryControllerConfig& c) {
    if (c.nozzle_count < 1 || c.nozzle_count > 32) {
        throw std::invalid_argument("boundary.nozzle_count: must be in [1, 32], got " + std::to_string(c.nozzle_count));
    }
    in_range("nozzle_spacing_m", c.nozzle_spacing_m, 0.0, 5.0, true);
    in_range("lift_rod_length_m", c.lift_rod_length_m, 0.0, 5.0, true);
    in_range("lift_hinge_height_m", c.lift_hinge_height_m, 0.0, 5.0, true);
    in_range("antenna_to_o_m", c.antenna_to_o_m, -10.0, 10.0);
    in_range("hinge_to_boom_centre_m", c.hinge_to_boom_centre_m, -10.0, 10.0);
    in_range("boom_centre_right_of_antenna_m", c.boom_centre_right_of_antenna_m, -5.0, 5.0);
    in_range("laser_mount_offset_m", c.laser_mount_offset_m, -1.0, 2.0);
    in_range("default_boom_height_m", c.default_boom_height_m, c.lift_hinge_height_m - c.lift_rod_length_m,
             c.lift_hinge_height_m + c.lift_rod_length_m);
    in_range("k_max_cover", c.k_max_cover, 0.0, 1.0, true);
    in_range("eq12_coefficient_l_min_per_m_s", c.eq12_coefficient_l_min_per_m_s, 0.0, 10.0, true);
    in_range("eq13_slope_l_min_per_pct", c.eq13_slope_l_min_per_pct, 0.0, 1.0, true);
    in_range("eq13_intercept_l_min", c.eq13_intercept_l_min, -10.0, 10.0);
    in_range("level0_max_pct", c.level0_max_pct, -1000.0, 1000.0);
    if (!(c.level1_max_pct > c.level0_max_pct) || !std::isfinite(c.level1_max_pct)) {
        throw std::invalid_argument("boundary.level1_max_pct: must be finite and > level0_max_pct (" +
                                    std::to_string(c.level0_max_pct) + "), got " + std::to_string(c.level1_max_pct));
    }
    in_range("level1_duty_pct", c.level1_duty_pct, 0.0, 100.0);
    in_range("level2_duty_pct", c.level2_duty_pct, 0.0, 100.0);
    in_range("pwm_frequency_hz", c.pwm_frequency_hz, 0.0, 1000.0, true);
    in_range("lookahead_on_s", c.lookahead_on_s, 0.0, 10.0);
    in_range("lookahead_off_s", c.lookahead_off_s, 0.0, 10.0);
    if (c.lookahead_on_s < c.lookahead_off_s) {
        throw std::invalid_argument("boundary.lookahead_on_s: must be >= lookahead_off_s (the on-point leads)");
    }
    in_range("course_hold_speed_m_s", c.course_hold_speed_m_s, 0.0, 5.0);
    in_range("fix_timeout_s", c.fix_timeout_s, 0.0, 10.0, true);
    in_range("faults.antenna_offset_error_m", c.faults.antenna_offset_error_m, -5.0, 5.0);
    in_range("faults.command_delay_s", c.faults.command_delay_s, 0.0, 2.0);
}

}  // namespace rig::controller::boundary
