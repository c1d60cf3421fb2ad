#pragma once
// The reference controller's parameters: the case file's `controller:` section,
// handed to the controller as a YAML file by the harness. Defaults are the
// paper's (seed 000).
#include <cstdint>
#include <filesystem>
#include <string>

namespace rig {
class YamlSection;
}

namespace rig::controller {

enum class Positioning { rtk_only, fusion };

struct ControllerConfig {
    Positioning positioning = Positioning::fusion;
    double threshold_m = 5.0;              // odometer takes over inside this (sec. 3.2.1)
    // Boom geometry the controller believes (Eq. 6); the plant has its own truth.
    double l1_m = 0.50;
    double l2_m = 0.80;
    double l3_m = 0.45;
    double linkage_rise_m = 0.50;
    // Land-wheel odometer (Eq. 5).
    double wheel_diameter_m = 1.0;
    std::uint32_t pulses_per_rev = 1000;
    double speed_window_s = 0.2;           // t1 of Eq. 5
    double gnss_latency_compensation_s = 0.0;
    // GGA quality is a code, not a scale (4 RTK fixed, 5 RTK float, 2 DGPS, 1 GPS):
    // either any fix with a position is used, or RTK fixed only.
    bool rtk_fixed_only = false;
    double approach_window_m = 60.0;       // a stored breakpoint is armed when this close ahead...
    double arm_distance_m = 1.0;           // ...and the nozzle line is at least this far behind it
    double status_rate_hz = 10.0;
    std::string breakpoint_store_file = "breakpoints.txt";  // relative to the state dir
};

// Reads and validates the section; throws rig::ConfigError (file:line:col: key: ...).
// The key `command` is the harness's (which executable to start) and is ignored.
ControllerConfig parse_controller_config(const YamlSection& section);
ControllerConfig load_controller_config(const std::filesystem::path& file);

}  // namespace rig::controller
