#include "emulators/guidance/guidance_params.h"

#include "emulators/param_check.h"

namespace rig::emulators::guidance {

void validate(const GuidanceParams& p, std::string_view section) {
    check_range(section, "wheelbase_m", p.wheelbase_m, 0.5, 10.0);
    check_range(section, "lookahead_min_m", p.lookahead_min_m, 0.3, 50.0);
    check_range(section, "lookahead_time_s", p.lookahead_time_s, 0.0, 10.0);
    check_range(section, "steer_time_constant_s", p.steer_time_constant_s, 0.0, 5.0);
    check_range(section, "steer_rate_max_deg_s", p.steer_rate_max_deg_s, 0.1, 360.0);
    check_range(section, "steer_angle_max_deg", p.steer_angle_max_deg, 1.0, 60.0);
    check_range(section, "terrain_compensation", p.terrain_compensation, 0.0, 1.0);
    check_range(section, "roll_sd_deg", p.roll_sd_deg, 0.0, 15.0);
    check_range(section, "pitch_sd_deg", p.pitch_sd_deg, 0.0, 15.0);
    check_range(section, "yaw_disturbance_sd_deg_m", p.yaw_disturbance_sd_deg_m, 0.0, 20.0);
    check_range(section, "roughness_length_m", p.roughness_length_m, 0.1, 100.0);
    check_range(section, "start_cross_track_m", p.start_cross_track_m, -5.0, 5.0);
    check_range(section, "start_heading_error_deg", p.start_heading_error_deg, -30.0, 30.0);
    check_range(section, "step_s", p.step_s, 1e-4, 0.05);
}

void validate(const AntennaMount& antenna, std::string_view section) {
    check_range(section, "antenna_forward_of_axle_m", antenna.forward_of_rear_axle_m, -10.0, 10.0);
    check_range(section, "antenna_height_m", antenna.height_m, 0.1, 10.0);
}

}  // namespace rig::emulators::guidance
