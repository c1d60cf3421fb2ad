#include "controller/controller_config.h"

#include <array>

#include "rig/yaml_fields.h"

namespace rig::controller {

ControllerConfig parse_controller_config(const YamlSection& section) {
    ControllerConfig config;
    section.allow("command");
    static constexpr std::array<EnumChoice<Positioning>, 2> kPositioning{
        {{"fusion", Positioning::fusion}, {"rtk_only", Positioning::rtk_only}}};
    config.positioning = section.optional_enum<Positioning>("positioning", kPositioning, config.positioning);
    config.threshold_m = section.optional_in_range("threshold_m", config.threshold_m, Bounds::open(0.0, 500.0));
    const YamlSection boom = section.section("boom");
    config.l1_m = boom.optional_in_range("l1_m", config.l1_m, Bounds::closed(0.0, 20.0));
    config.l2_m = boom.optional_in_range("l2_m", config.l2_m, Bounds::open_closed(0.0, 20.0));
    config.l3_m = boom.optional_in_range("l3_m", config.l3_m, Bounds::closed(0.0, 20.0));
    config.linkage_rise_m = boom.optional_in_range("linkage_rise_m", config.linkage_rise_m, Bounds::closed(-5.0, 5.0));
    boom.finish();
    const YamlSection odometer = section.section("odometer");
    config.wheel_diameter_m =
        odometer.optional_in_range("wheel_diameter_m", config.wheel_diameter_m, Bounds::open_closed(0.0, 5.0));
    config.pulses_per_rev =
        odometer.optional_in_range<std::uint32_t>("pulses_per_rev", config.pulses_per_rev, Bounds::closed(1, 1e6));
    config.speed_window_s =
        odometer.optional_in_range("speed_window_s", config.speed_window_s, Bounds::open_closed(0.0, 10.0));
    odometer.finish();
    config.gnss_latency_compensation_s = section.optional_in_range(
        "gnss_latency_compensation_s", config.gnss_latency_compensation_s, Bounds::closed_open(0.0, 1.0));
    config.rtk_fixed_only = section.optional<bool>("rtk_fixed_only", config.rtk_fixed_only);
    config.approach_window_m =
        section.optional_in_range("approach_window_m", config.approach_window_m, Bounds::open(0.0, 10'000.0));
    config.arm_distance_m =
        section.optional_in_range("arm_distance_m", config.arm_distance_m, Bounds::closed(0.0, 1'000.0));
    if (config.arm_distance_m >= config.approach_window_m) {
        section.fail("arm_distance_m", "must be less than approach_window_m");
    }
    config.status_rate_hz =
        section.optional_in_range("status_rate_hz", config.status_rate_hz, Bounds::open_closed(0.0, 1000.0));
    config.breakpoint_store_file = section.optional<std::string>("breakpoint_store_file", config.breakpoint_store_file);
    if (config.breakpoint_store_file.empty()) section.fail("breakpoint_store_file", "must not be empty");
    section.finish();
    return config;
}

ControllerConfig load_controller_config(const std::filesystem::path& file) {
    return parse_controller_config(YamlSection::load_file(file));
}

}  // namespace rig::controller
