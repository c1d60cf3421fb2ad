#pragma once
// Seed 001's vision metrics (Sec. 2, 3.2.2, 5.2; Tables 4-6), as pure
// functions of plain data the judge takes from a recorded trace, so tests can
// hand them frames and duties with a known answer. No DDS.
//
// Per frame and nozzle ROI, from truth (truth/camera_view: the true cover D of
// the nozzle's Sec. 2.1 ROI at the exposure, the true speed) against what the
// controller did:
//   density error   the controller's reported D (controller/vision/density)
//                   minus the true D;
//   level           Eq. 14's level of the TRUE D at the TRUE speed, with the
//                   paper's constants (k as the plan gives it), against the
//                   duty the nozzle was actually commanded
//                   (actuator/nozzle_pwm/duty) decision_delay_s after the
//                   exposure: a controller that measures well but sprays the
//                   wrong level fails here, one whose report lies about D but
//                   sprays right passes it.
// Only ROIs whose true centre lies in the judged zone count, so the run-in
// (no course yet, every nozzle off) and the run-out are not judged.
//
// Coverage (Tables 4-6): the paper laid water-sensitive papers in the crop and
// read their stained share. The rig reads the dose the plant laid at each
// paper's point (uL/cm^2, rebuilt from truth) and turns it into coverage with
//   c = 1 - exp(-a V)
// the share of a surface left stained by drops landing at random (Poisson)
// with a stain area of a cm^2 per uL deposited (a = 1.5 s^2 / d for drops of
// diameter d spreading s times their diameter). The paper gives no drop size:
// a is a FIT (CoverageModel below says to which number), and the other groups
// and tables are the check.
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>
#include "rig/papers/seed001.h"

namespace rig::harness {

// How a dose becomes paper coverage.
struct CoverageModel {
    // a, cm^2 of stain per uL deposited. FIT: -ln(1 - 0.3109) / 1.3648 =
    // 0.2728, Table 4's control mean (31.09 %) at the dose of one nozzle at
    // 100 % duty (Table 3's mean 614.17 mL/min) over the 0.5 m spacing at
    // 1.5 m/s (1.3648 uL/cm^2). Not fitted to Tables 5-6 nor to the sparse or
    // slow groups: those are the check. Read as drops, a = 0.2728 is a 250 um
    // drop spreading 2.1 times its diameter on the paper (spread factors of
    // about 2 are usual for water-sensitive paper).
    double stain_area_cm2_per_ul = 0.2728;   // (0, 100]
};

// Coverage (0..1) of a dose in uL/cm^2 (>= 0; a negative or NaN dose throws).
double paper_coverage(const CoverageModel& model, double dose_ul_cm2);

// The judge's Eq. 14 (Sec. 3.2.2), from the paper's constants
// (rig/papers/seed001.h, where k's assumed value is explained).
struct Eq14Levels {
    double k_max_cover = papers::seed001::kEq14MaxCover;  // (0, 1]
    double eq12_coefficient_l_min_per_m_s = papers::seed001::kEq12CoefficientLMinPerMS;
    double eq13_slope_l_min_per_pct = papers::seed001::kEq13SlopeLMinPerPct;
    double eq13_intercept_l_min = papers::seed001::kEq13InterceptLMin;
    double level0_max_pct = papers::seed001::kLevel0MaxPct;
    double level1_max_pct = papers::seed001::kLevel1MaxPct;
    double level1_duty_pct = papers::seed001::kLevel1DutyPct;
    double level2_duty_pct = papers::seed001::kLevel2DutyPct;
};
int eq14_level(const Eq14Levels& eq, double density, double speed_m_s);
double eq14_level_duty_pct(const Eq14Levels& eq, int level);

struct VisionJudging {
    bool enabled = false;                // a case with `vision:`
    // The ground whose ROIs are judged (local frame, m): a ROI counts when its
    // true centre lies inside. Default: everything.
    double east_min_m = -1e9;
    double east_max_m = 1e9;
    double north_min_m = -1e9;
    double north_max_m = 1e9;
    // The duty judged for a frame is the one commanded this long after its
    // exposure (the controller's processing and the PWM latch; assumed 0.1 s,
    // under the frame period of the cases' 5 fps).
    double decision_delay_s = 0.1;       // [0, 10]
    Eq14Levels eq14;
};

// One ROI of one frame: truth and what the controller made of it.
struct RoiJudged {
    double t_s = 0.0;
    int camera = 0;
    long frame_number = 0;
    int nozzle = 0;
    double centre_east_m = 0.0;          // the true ROI's centre, local frame
    double centre_north_m = 0.0;
    double true_density = 0.0;
    double true_speed_m_s = 0.0;
    bool delivered = true;               // the camera sent the frame
    bool reported = false;               // the controller published a report for this frame
    bool measured = false;               // ... with a density for this nozzle
    double measured_density = 0.0;
    std::optional<double> duty_pct;      // commanded decision_delay_s after the exposure; none before any command
};

// Limits are maxima, so each share counts what went wrong (percent of the
// judged ROIs unless said): vision_rois_count, vision_frames_missing_pct (the
// camera sent none), vision_reports_missing_pct (of delivered frames, no
// report), vision_rois_unmeasured_pct (no density reported),
// vision_density_error_mean_pct / _mean_abs_pct / _max_abs_pct (measured
// minus true D, in points of cover, over measured ROIs),
// vision_true_density_mean_pct, vision_measured_density_mean_pct,
// vision_level_mismatch_pct (the duty commanded is not the duty of Eq. 14's
// level on the true D at the true speed), of which vision_level_low_pct and
// vision_level_high_pct sprayed less / more. Per camera c (0 left, 1 right):
// vision_camera<c>_rois_unmeasured_pct, _level_mismatch_pct,
// _density_error_mean_abs_pct; and the worst camera's of each,
// vision_worst_camera_*: the cases limit those, so one faulty camera is not
// averaged away by the healthy one.
// Metrics over an empty set are absent and named in `not_measured`.
std::map<std::string, double> vision_metrics(const std::vector<RoiJudged>& rois, const VisionJudging& judging,
                                             std::map<std::string, std::string>& not_measured);

// Dose per area against cover (Sec. 3: the rate follows the plants): the
// dose the plant laid around each judged ROI's centre (`dose_ul_cm2[i]` for
// rois[i]; NaN where the ground grid has none), averaged over the ROIs whose
// true cover is below Sec. 5.2's 40 % split (sparse) and at or above it
// (normal): vision_dose_sparse_rois_ul_cm2, vision_dose_normal_rois_ul_cm2,
// and their counts vision_sparse_rois_count, vision_normal_rois_count. A
// class with a ROI off the ground (NaN) has its mean not measured. The
// ground under a ROI is sprayed after the frame that saw it (0.13-0.4 s at
// 1.5 m/s), by whatever level the frames then in force chose: across a cover
// edge the two differ, the spatial offset S7 asks to report.
std::map<std::string, double> dose_by_cover_metrics(const std::vector<RoiJudged>& rois,
                                                    const std::vector<double>& dose_ul_cm2,
                                                    std::map<std::string, std::string>& not_measured);

// A ground rectangle (local frame, m): a water-sensitive paper or the strip
// whose dose per area is judged.
struct GroundRect {
    double east_min_m = 0.0;
    double east_max_m = 0.0;
    double north_min_m = 0.0;
    double north_max_m = 0.0;
};
// A paper centred on a point. Size: the common 26 x 76 mm card (the paper does
// not say which it used), laid with its long side across the rows (east-west
// in the cases, whose rows run north); assumed.
GroundRect paper_at(double east_m, double north_m);

// The dose cells (their centres) inside a rectangle of a dose raster, row-major.
struct DoseCells {
    std::vector<double> dose_ul_cm2;
};

// What the papers read: per paper, its mean coverage over its cells (coverage
// is not linear in dose, so not the coverage of its mean dose) and its mean
// dose: coverage_paper<i>_pct, dose_paper<i>_ul_cm2; over the papers
// coverage_mean_pct and dose_mean_ul_cm2. A paper with no cell throws
// std::invalid_argument naming it.
std::map<std::string, double> paper_metrics(const std::vector<DoseCells>& papers, const CoverageModel& model);
// Dose per area over a strip (Sec. 3's u, the dose the levels aim at):
// strip_dose_mean_ul_cm2, strip_dose_cv_pct (the spread along and across
// travel: PWM pulses at 9 Hz lay stripes every v / 9 m; not measured over a
// strip with nothing laid or a single cell), strip_coverage_mean_pct.
std::map<std::string, double> strip_metrics(const DoseCells& strip, const CoverageModel& model,
                                            std::map<std::string, std::string>& not_measured);

}  // namespace rig::harness
