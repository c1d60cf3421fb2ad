#include "harness/spec/guidance_section.h"

#include <stdexcept>
#include <utility>

namespace rig::harness {

std::optional<emulators::guidance::GuidanceParams> read_guidance_section(const YamlSection& root) {
    if (root.has("guidance")) {
        const RawYaml written = root.raw("guidance");
        if (written.node.IsScalar() && written.node.Scalar() == "off") return std::nullopt;
        if (!written.node.IsMap() && !written.node.IsNull()) {
            root.fail("guidance", "expected off (the route driven exactly) or a mapping of the guidance's keys "
                                  "(no section: every default); got " + describe_node(written.node));
        }
    }
    using Params = emulators::guidance::GuidanceParams;
    static constexpr std::pair<const char*, double Params::*> kFields[] = {
        {"wheelbase_m", &Params::wheelbase_m},
        {"lookahead_min_m", &Params::lookahead_min_m},
        {"lookahead_time_s", &Params::lookahead_time_s},
        {"steer_time_constant_s", &Params::steer_time_constant_s},
        {"steer_rate_max_deg_s", &Params::steer_rate_max_deg_s},
        {"steer_angle_max_deg", &Params::steer_angle_max_deg},
        {"terrain_compensation", &Params::terrain_compensation},
        {"roll_sd_deg", &Params::roll_sd_deg},
        {"pitch_sd_deg", &Params::pitch_sd_deg},
        {"yaw_disturbance_sd_deg_m", &Params::yaw_disturbance_sd_deg_m},
        {"roughness_length_m", &Params::roughness_length_m},
        {"start_cross_track_m", &Params::start_cross_track_m},
        {"start_heading_error_deg", &Params::start_heading_error_deg},
        {"step_s", &Params::step_s},
    };
    const YamlSection section = root.section("guidance");
    Params params;
    // Read finite here; the bounds are the parameters' own (validate below), one place.
    for (const auto& [key, field] : kFields) {
        params.*field = section.optional_in_range<double>(key, params.*field, Bounds::closed(-1e9, 1e9));
    }
    try {
        emulators::guidance::validate(params, "guidance");
    } catch (const std::invalid_argument& error) {
        section.fail(error.what());
    }
    return params;
}

}  // namespace rig::harness
