#pragma once
// Every parameter of the seed-001 reference controller's positioning and
// boundary half, with its unit (in the name), default and where the value
// comes from: a paper equation or table, or "assumed" where the paper gives
// none. validate() checks the bounds given beside each.
//
// Seed 001 = Yang et al., "Design of Wheat Variable Spray System Based on
// Machine Vision and Beidou Positioning", Trans. CSAM 2022, 53(7).
#include <string>
#include <vector>
#include "rig/papers/seed001.h"

namespace rig::controller::boundary {

struct GeoCorner {
    double lat_deg = 0.0;  // WGS84, [-80, 84] (UTM's range)
    double lon_deg = 0.0;  // [-180, 180]
};

// A target spraying area: four corners recorded with the receiver before work
// (Sec. 4.2.2), in order around the area.
struct TargetAreaConfig {
    std::string name;                  // non-empty, for messages
    std::vector<GeoCorner> corners;    // >= 3 (the paper records 4)
    // Plant cover D in [0, 1] (Eq. 17) for the whole area. The vision half
    // (Sec. 2, 4.1) will measure it per nozzle; until then a case gives it here.
    double density = 0.5;
};

// TEST-ONLY faults (the catalogue of faulty seed-001 controllers, cases/
// seed001-faulty-controllers/): each is a mistake a real implementation of
// Sec. 4.2 could make, so the rig must catch it on its named metric. All off
// by default; the reference controller never sets them.
struct BoundaryControllerFaults {
    // Added to Eq. 18's Y1 (boom centre ahead of the antenna): an antenna
    // mounted elsewhere than the controller believes. [-5, 5] m.
    double antenna_offset_error_m = 0.0;
    // Eq. 19 without the rotation by the course: the boom taken as if the
    // vehicle always headed grid north.
    bool no_course_rotation = false;
    // The L4 laser's readings dropped: Eq. 18 at default_boom_height_m always.
    bool ignore_boom_height = false;
    // The look-ahead points taken behind the antenna instead of ahead.
    bool lookahead_sign_flipped = false;
    // Sec. 4.2's second rule dropped: each nozzle judged on its own position
    // only, so nozzles inside spray while the boom centre is outside (the
    // headland double spray of spraying environment 2).
    bool ignore_centre_rule = false;
    // A duty message that turns any nozzle on carries one entry more than the
    // boom has nozzles (a fill loop that runs to <= nozzle_count): 7 duties
    // for 6 nozzles, which the plant refuses (malformed_command).
    bool extra_duty_entry = false;
    // Every duty command goes out this long after the logic decided it (case
    // time): a controller that acts late, e.g. an output task fed through a
    // queue (controller/boundary/duty_command_delay.h). [0, 2] s.
    double command_delay_s = 0.0;
};

struct BoundaryControllerConfig {
    std::vector<TargetAreaConfig> areas;  // >= 1; the UTM zone is that of the corners' mean

    // Boom (Table 1, Sec. 5.1): nozzles numbered 0.. left to right facing travel (assumed).
    int nozzle_count = papers::seed001::kNozzleCount;                 // [1, 32]
    double nozzle_spacing_m = papers::seed001::kNozzleSpacingM;       // (0, 5]
    // Eq. 18, the controller's belief of the lift (the plant has its own truth).
    // The paper gives none of these: assumed, boom centre 1.00 m ahead of the
    // antenna at H = 0.5 m (see emulators/field2d/boom_lift.h).
    double lift_rod_length_m = papers::seed001::kLiftRodLengthM;      // I, (0, 5]
    double lift_hinge_height_m = papers::seed001::kLiftHingeHeightM;  // Hp, (0, 5]
    double antenna_to_o_m = papers::seed001::kLiftAntennaToOM;        // M, [-10, 10]
    double hinge_to_boom_centre_m = papers::seed001::kLiftHingeToBoomCentreM;  // L, [-10, 10]
    double boom_centre_right_of_antenna_m = 0.0;  // [-5, 5]; Sec. 1.1: antenna on the centre line

    // L4 laser (Sec. 1.1): H = D - laser_mount_offset_m.
    double laser_mount_offset_m = 0.0;    // [-1, 2]; assumed, sensor level with the nozzles
    double default_boom_height_m = 0.50;  // within the lift's reach; Sec. 5.1, used until the first reading

    // Eq. 9-14: q = eq12 D v / k (L/min), s = (q - b) / A (%), levels.
    double k_max_cover = papers::seed001::kEq14MaxCover;  // (0, 1]
    double eq12_coefficient_l_min_per_m_s = papers::seed001::kEq12CoefficientLMinPerMS;  // (0, 10]
    double eq13_slope_l_min_per_pct = papers::seed001::kEq13SlopeLMinPerPct;  // A, (0, 1]
    double eq13_intercept_l_min = papers::seed001::kEq13InterceptLMin;  // b, [-10, 10]
    double level0_max_pct = papers::seed001::kLevel0MaxPct;  // s <= this: level 0, valve closed
    double level1_max_pct = papers::seed001::kLevel1MaxPct;  // > level0_max_pct; level 1 up to here
    double level1_duty_pct = papers::seed001::kLevel1DutyPct;  // [0, 100]
    double level2_duty_pct = papers::seed001::kLevel2DutyPct;  // [0, 100]
    double pwm_frequency_hz = papers::seed001::kPwmFrequencyHz;  // (0, 1000]

    // AgOpenGPS-style anticipation (not in the paper, off by default): a nozzle
    // (and the boom-centre rule) switches on when its point lookahead_on_s ahead
    // (straight on along the course at the current speed) is inside, and off
    // when both that point and the one lookahead_off_s ahead are outside.
    // Defaults are AgOpenGPS's setVehicle_toolLookAheadOn / Off (1.0 / 0.5 s).
    bool lookahead_enabled = false;
    double lookahead_on_s = 1.0;          // [0, 10], >= lookahead_off_s
    double lookahead_off_s = 0.5;         // [0, 10]

    // GNSS handling (assumed; the paper says nothing).
    double course_hold_speed_m_s = 0.2;   // [0, 5]; below this the RMC course is not used, the last one is held
    double fix_timeout_s = 0.5;           // (0, 10]; no valid RMC for this long: every nozzle off (5 epochs at 10 Hz)
    // The paper uses the RMC course (true north) as the bearing in UTM (Eq. 19),
    // ignoring the grid convergence (about 1.3 deg at Wuzhi): false reproduces that.
    bool correct_grid_convergence = false;

    BoundaryControllerFaults faults;
};

// Throws std::invalid_argument "boundary.<key>: <what>" for the first value
// out of its bounds (areas are named as areas[i] 'name').
void validate(const BoundaryControllerConfig& config);
// The same in two parts: the target areas (at least one), and everything else.
void validate_areas(const std::vector<TargetAreaConfig>& areas);
void validate_settings(const BoundaryControllerConfig& config);

}  // namespace rig::controller::boundary
