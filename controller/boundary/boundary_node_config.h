#pragma once
// The seed-001 reference controller's configuration as a case gives it: the
// case's `controller:` section (docs/controller-contract.md, --config FILE),
// read strictly (unknown keys, wrong types and out-of-range values are a
// rig::ConfigError naming file, line and key). Keys are the field names of
// BoundaryControllerConfig (boundary_config.h), where each is declared once
// with its unit, default and source; `areas`, `faults` and `calibration` are
// sections.
//
// Beside it the rig gives a seed-001 controller the job (--job FILE,
// docs/controller-contract.md "The job"): the field, the target areas the
// operator recorded before work (Sec. 4.2.2), the sprayer (nozzles, Eq. 18's
// lift, the laser's mounting, the PWM frequency) and the cameras on the boom.
// The job's areas and sprayer are the controller's where its section does not
// say otherwise; with cameras on the boom and no `vision` section, it measures
// the cover with them (and calibrates from the boards while the job says the
// scene shows them).
#include <filesystem>
#include <optional>
#include <string>
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

// The job file (job.yaml), as the rig writes it (docs/controller-contract.md
// "The job": every key with its frame and unit).
struct BoundaryJob {
    GeoCorner field_origin;               // the case's local east-north frame (the reference projects to UTM instead)
    double field_origin_height_m = 0.0;   // above the WGS84 ellipsoid
    std::vector<TargetAreaConfig> areas;  // at least one
    // The sprayer as it stands (the case's `sprayer:`, `laser:` and `valves:`):
    // the reference controller's own keys of the same meaning, unless its
    // section sets them.
    int nozzle_count = papers::seed001::kNozzleCount;
    double nozzle_spacing_m = papers::seed001::kNozzleSpacingM;
    double lift_rod_length_m = papers::seed001::kLiftRodLengthM;                 // I
    double lift_hinge_height_m = papers::seed001::kLiftHingeHeightM;             // Hp
    double antenna_to_o_m = papers::seed001::kLiftAntennaToOM;                   // M
    double hinge_to_boom_centre_m = papers::seed001::kLiftHingeToBoomCentreM;    // L
    double laser_mount_offset_m = 0.0;    // the laser reads D = H + this
    double pwm_frequency_hz = papers::seed001::kPwmFrequencyHz;
    bool cameras = false;  // the two boom cameras publish frames, on these topics:
    std::string left_camera_topic;
    std::string right_camera_topic;
    // While the cameras see Sec. 2.2.1's calibration boards, s from t = 0; 0: never.
    double calibration_scene_until_s = 0.0;
};
// Throws rig::ConfigError naming file, line and key.
BoundaryJob load_boundary_job(const std::filesystem::path& file);

// Throws rig::ConfigError at the offending key (a bound BoundaryControllerConfig's
// validate() finds is reported at the section). With a job, what the section
// does not say is the job's (above); without one, the section alone must name
// the areas.
BoundaryNodeConfig parse_boundary_node_config(const YamlSection& section, const std::optional<BoundaryJob>& job = std::nullopt);
BoundaryNodeConfig load_boundary_node_config(const std::filesystem::path& file,
                                             const std::optional<std::filesystem::path>& job_file = std::nullopt);

// The section's own keys and bounds, as `rig-boundary-controller --check-config`
// checks them before a run: the areas may come from a job, so none is required.
// Throws rig::ConfigError at the offending key.
void check_boundary_node_config(const YamlSection& section);

}  // namespace rig::controller::boundary
