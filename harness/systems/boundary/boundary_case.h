#pragma once
// Seed 001's boundary cases (`system: boundary`): the sections of a case file
// besides those every case has. The loader (harness/spec/case_spec.h) reads the
// keys every case has (name, seed(s), domain, mode, wiring, board, controller,
// limits, expect, timeouts) and hands the rest to read_boundary_sections here.
//
//   field:    { origin: { lat_deg, lon_deg, height_m } }   the local ENU frame's origin (plant truth)
//   area:     { name, density, corners: [ { lat_deg, lon_deg } x 4 ] }   the target area (Sec. 4.2.2)
//   route:    { start: { east_m, north_m, heading_deg, speed_m_s },
//               segments: [ { straight: {...} } | { turn: {...} } | { stand: {...} } ] }
//   sprayer:  mounting (antenna, nozzles, Eq. 18's lift) and boom_height: [ { t_s, height_m } ]
//   spray:    fan and deposition step; flow_table: per nozzle [ { duty_pct, flow_ml_min } ] (Table 3 by default)
//   valves:   PWM valves; ad300: the receiver; laser: the L4
//   vision:   the crop truth and the two boom cameras (seed 001's vision half,
//             docs/seed001-vision.md): crop: {CropCoverParams fields,
//             default_cover, patches: [ { cover, corners: [ { east_m, north_m } ] } ]},
//             cameras: {CameraEmulatorParams fields for both}, left: / right:
//             { faults: { pitch_offset_deg, blur_radius_px, colour_cast, dead } }
//   guidance: autosteer over a rough ground instead of the exact route
//             (harness/spec/guidance_section.h, docs/guidance.md); `off`: exact
//   judge:    ground grid, wet threshold, the edges to measure and the metric
//             each gives, flow per duty (Table 3), centre_rule (Sec. 4.2's
//             boom-centre rule, Table 8 "along, boom centre outside"), vision
//             (density and level per frame in a zone) and papers (Tables 4-6's
//             water-sensitive papers: coverage at points)
// Every parameter is declared once, in the emulator's own parameter struct
// (emulators/ad300_receiver.h, l4_laser_sensor.h, pwm_nozzle_valves.h,
// boundary_spray_plant.h, field2d/*), with unit, default and provenance; the
// case file overrides it by the same name, and the emulator's own checks give
// the bounds (reported at the key's section as a rig::ConfigError).
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "emulators/ad300_receiver.h"
#include "emulators/boundary_spray_plant.h"
#include "emulators/field2d/deposition_grid2d.h"
#include "emulators/field2d/local_frame.h"
#include "emulators/field2d/nozzle_flow_table.h"
#include "emulators/field2d/route2d.h"
#include "emulators/field2d/sprayer_kinematics.h"
#include "emulators/l4_laser_sensor.h"
#include "emulators/pwm_nozzle_valves.h"
#include "emulators/vision/camera_emulator.h"
#include "emulators/field2d/crop_cover_map.h"
#include "harness/systems/boundary/boundary_metrics.h"
#include "harness/systems/boundary/vision_metrics.h"
#include "harness/spec/case_spec.h"
#include "harness/spec/guidance_section.h"
#include "rig/config/yaml_fields.h"

namespace rig::harness {

// The metric families a boundary edge can be judged for (harness/systems/boundary/boundary_metrics.h).
inline constexpr std::string_view kBoundaryEdgeMetrics[] = {"boundary_overrun", "drive_out_excess", "drive_in_excess"};

// One edge of the target area measured every spacing_m, its excess named `metric`.
struct BoundaryEdgeJudging {
    std::string metric;                    // one of kBoundaryEdgeMetrics
    field2d::Vec2 near;                    // the area edge whose midpoint is nearest this point (local frame, m)
    EdgeProbe probe;                       // stations along the edge from its first corner (counter-clockwise)
};

// Seed 001's vision half: the crop the cameras see and the cameras themselves.
struct BoundaryVisionSpec {
    field2d::CropCoverParams crop;         // seed: the run's; patches in the local frame
    // Left (index 0, nozzles 0 .. n/2 - 1) and right (the rest): Sec. 1.1's
    // two cameras, seed001_camera_params() unless the case says otherwise.
    emulators::vision::CameraEmulatorParams left = emulators::vision::seed001_camera_params(false);
    emulators::vision::CameraEmulatorParams right = emulators::vision::seed001_camera_params(true);
    // Sec. 2.2.1's calibration scene: until this time (s from t = 0) the
    // cameras see the boards on the boom (a green board in front of each
    // camera, a red board over each nozzle) instead of the bare crop, as while
    // the operator calibrates standing at the headland. 0: no calibration. [0, 600] s
    double calibration_until_s = 0.0;
};

class BoundarySections final : public SystemSections {
public:
    std::string_view system_name() const override { return "boundary"; }
    std::string scenario() const override { return "boundary"; }
    // No default limits: each case file gives its own.
    std::map<std::string, double> default_limits() const override { return {}; }
    // The L4 laser's serial line (wiring.laser).
    bool reads_laser_line() const override { return true; }
    // Builds the route, the sprayer, the devices and the area as the run will,
    // so that a value their own checks refuse is an error at load time, at its
    // section; and the wires and the controller seed 001 can take.
    void check_with(const CaseSpec& spec, const YamlSection& root) const override;

    field2d::GeodeticPoint origin;         // ENU origin; lat [-80, 84], lon [-180, 180], height [-1000, 10000] m
    std::string area_name = "target";
    std::vector<field2d::GeodeticPoint> corners;  // >= 3 (the paper records 4)
    double area_density = 0.5;             // plant cover D in [0, 1] the controller is told (Eq. 17); until the vision half
    field2d::RouteStart route_start;
    std::vector<field2d::RouteSegment> route_segments;
    field2d::SprayerMounting mounting;
    std::optional<emulators::guidance::GuidanceParams> guidance;  // nullopt (`guidance: off`): the route driven exactly
    std::vector<field2d::HeightKnot> boom_height{field2d::HeightKnot{0.0, 0.5}};
    emulators::SprayDepositionParams spray;
    std::vector<std::vector<field2d::FlowPoint>> flow_table;  // empty: Table 3 as printed
    emulators::PwmValveParams valves;      // seed: the run's
    emulators::Ad300Params ad300;          // seed: the run's
    emulators::L4LaserParams laser;        // seed: the run's
    std::optional<BoundaryVisionSpec> vision;  // absent: no cameras (the area's density is the controller's)
    // Judging.
    field2d::DepositionGrid2dParams ground;  // the judge's grid, rebuilt from the trace
    double wet_threshold_ul_cm2 = EdgeProbe{}.wet_threshold_ul_cm2;
    std::vector<BoundaryEdgeJudging> edges;
    bool judge_flow_per_duty = false;      // Table 3: flow per duty per nozzle from the delivered volumes
    // Flow per duty skips this long after each duty change (the first PWM periods).
    double flow_settle_s = 0.5;            // [0, 60]
    // Sec. 4.2's boom-centre rule from truth (centre_out_* metrics, harness/systems/boundary/boundary_metrics.h).
    bool judge_centre_rule = false;
    double end_after_route_s = 1.0;        // the run ends this long after the route does, [0, 600]
    VisionJudging vision_judging;          // with `vision:`: the density and level checks (harness/systems/boundary/vision_metrics.h)
    std::vector<field2d::Vec2> papers;     // water-sensitive papers (Tables 4-6), their centres, local frame
    std::optional<GroundRect> dose_strip;  // dose per area over this rectangle (local frame)
    CoverageModel coverage;                // how a dose becomes paper coverage (harness/systems/boundary/vision_metrics.h)

    field2d::NozzleFlowTable flow_table_or_paper() const;
    field2d::LocalFrame frame() const { return field2d::LocalFrame(origin.lat_deg, origin.lon_deg, origin.height_m); }
};

// Reads the boundary sections of `root` (not finish()ed here). Throws
// rig::ConfigError naming file, line and key.
std::shared_ptr<const BoundarySections> read_boundary_sections(const YamlSection& root);

// A seed-001 case's own sections; throws std::logic_error when the case is another system's.
const BoundarySections& boundary_sections(const CaseSpec& spec);

}  // namespace rig::harness
