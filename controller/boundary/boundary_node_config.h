#pragma once
// The seed-001 reference controller's configuration as a case gives it: the
// case's `controller:` section (docs/controller-contract.md, --config FILE),
// read strictly (unknown keys, wrong types and out-of-range values are a
// rig::ConfigError naming file, line and key). Keys are the field names of
// BoundaryControllerConfig (boundary_config.h), where each is declared once
// with its unit, default and source; `areas`, `faults` and `calibration` are
// sections.
#include <filesystem>
#include <vector>

#include "controller/boundary/boundary_config.h"
#include "controller/boundary/vision/vision_params.h"
#include "rig/config/yaml_fields.h"

namespace rig::controller::boundary {

// Table 3's measurement (Sec. 5.2): the paper held each duty on every nozzle of
// the standing sprayer for a minute and read a measuring cylinder. With
// `calibration:` the node does the same instead of the boundary logic: from
// start_s each duty of duties_pct for hold_s, then every valve shut.
struct DutySweepConfig {
    std::vector<double> duties_pct;  // each [0, 100]; empty: no sweep (the boundary logic runs)
    double start_s = 1.0;            // [0, 3600]
    double hold_s = 10.0;            // (0, 3600]; the paper: 60 s per point
};

// The vision half (Sec. 2, 4.1): with `vision: { enabled: true }` each
// nozzle's level comes from the density its camera measures in every frame
// (device/camera_left|right/frame), instead of its area's `density`. The two
// cameras are Sec. 1.1's at their design calibration
// (vision::seed001_vision_cameras): left sees the first half of the nozzles.
struct VisionNodeConfig {
    bool enabled = false;
    vision::VisionParams params;
    // The level of a nozzle whose camera gives no density (no frame, a dark
    // frame, its ROI out of the frame). Assumed 2: spray as a sprayer without
    // vision would; a missed weed patch costs more than the chemical. [0, 2]
    int blind_level = 2;
    // A density older than this (no newer frame) is no density: the camera
    // has stopped. Assumed 1 s, five frames at the cases' 5 fps. (0, 60] s
    double density_max_age_s = 1.0;
    // Sec. 2.2.1: frames before this time (s) show the calibration boards;
    // the nozzle points found in them (Eq. 1-4) replace the design points for
    // Eq. 5-8. 0: no calibration, the design points. [0, 600] s
    double calibration_until_s = 0.0;
};

struct BoundaryNodeConfig {
    BoundaryControllerConfig controller;
    DutySweepConfig calibration;
    VisionNodeConfig vision;
};

// Throws rig::ConfigError at the offending key (a bound BoundaryControllerConfig's
// validate() finds is reported at the section).
BoundaryNodeConfig parse_boundary_node_config(const YamlSection& section);
BoundaryNodeConfig load_boundary_node_config(const std::filesystem::path& file);

}  // namespace rig::controller::boundary
