// Seed 001's vision metrics (harness/systems/boundary/vision_metrics.h) on hand-made ROIs and
// dose cells with known answers: the coverage model and its fit, Eq. 14's
// levels as the judge computes them, what counts as a level mismatch, and the
// worst camera not averaged away by the healthy one. No DDS.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "harness/systems/boundary/vision_metrics.h"

namespace {

using namespace rig::harness;

TEST(VisionMetrics, TheCoverageFitGivesTable4sControlAtItsDoseAndIsPoissonElsewhere) {
    const CoverageModel model;
    // The fit: one nozzle at 100 % (Table 3's mean, 614.17 mL/min) over 0.5 m at
    // 1.5 m/s is 1.3648 uL/cm^2, which reads Table 4's control mean, 31.09 %.
    const double control_dose = 0.61417 / 60.0 / (0.5 * 1.5) * 100.0;  // L/m^2; x 100 = uL/cm^2
    EXPECT_NEAR(control_dose, 1.3648, 1e-4);
    EXPECT_NEAR(100.0 * paper_coverage(model, control_dose), 31.09, 0.01);
    EXPECT_EQ(paper_coverage(model, 0.0), 0.0);
    // Doubling the dose squares the uncovered share (Poisson).
    const double once = 1.0 - paper_coverage(model, 1.0);
    EXPECT_NEAR(1.0 - paper_coverage(model, 2.0), once * once, 1e-12);
    EXPECT_THROW(paper_coverage(model, -0.1), std::invalid_argument);
    EXPECT_THROW(paper_coverage(model, std::nan("")), std::invalid_argument);
}

TEST(VisionMetrics, Eq14LevelsAreThePapersAtBothSpeeds) {
    const Eq14Levels eq;
    // Sec. 5.2: normal cover (> 40 %) at 1.5 m/s is level 2, sparse level 1;
    // at 0.75 m/s level 2 needs D / k above 1 (S3), so normal cover is level 1.
    EXPECT_EQ(eq14_level(eq, 0.56, 1.5), 2);
    EXPECT_EQ(eq14_level(eq, 0.26, 1.5), 1);
    EXPECT_EQ(eq14_level(eq, 0.56, 0.75), 1);
    // k = 0.78 puts the level 1/2 split at D = 0.3995 at 1.5 m/s.
    EXPECT_EQ(eq14_level(eq, 0.398, 1.5), 1);
    EXPECT_EQ(eq14_level(eq, 0.401, 1.5), 2);
    // Level 0 below s = -55 %: bare ground, and a standing sprayer.
    EXPECT_EQ(eq14_level(eq, 0.0, 1.5), 0);
    EXPECT_EQ(eq14_level(eq, 0.56, 0.0), 0);
    EXPECT_EQ(eq14_level_duty_pct(eq, 0), 0.0);
    EXPECT_EQ(eq14_level_duty_pct(eq, 1), 40.0);
    EXPECT_EQ(eq14_level_duty_pct(eq, 2), 100.0);
}

RoiJudged roi(int camera, double true_d, double measured_d, std::optional<double> duty, bool measured = true) {
    RoiJudged r;
    r.camera = camera;
    r.true_density = true_d;
    r.true_speed_m_s = 1.5;
    r.reported = true;
    r.measured = measured;
    r.measured_density = measured_d;
    r.duty_pct = duty;
    return r;
}

TEST(VisionMetrics, MismatchIsTheDutyRunAgainstTheLevelOfTheTrueCover) {
    const VisionJudging judging;
    std::map<std::string, std::string> not_measured;
    // Right camera healthy: four ROIs measured within a point, levels right.
    std::vector<RoiJudged> rois = {roi(1, 0.56, 0.565, 100.0), roi(1, 0.26, 0.255, 40.0), roi(1, 0.56, 0.56, 100.0),
                                   roi(1, 0.26, 0.26, 40.0)};
    // Left camera: reads sparse as normal (sprays 100 where 40 is wanted), a
    // ROI it could not measure (sprayed at its blind level, 100), and a normal
    // ROI measured right but never commanded (no duty yet: off, too little).
    rois.push_back(roi(0, 0.26, 0.45, 100.0));
    rois.push_back(roi(0, 0.26, 0.0, 100.0, /*measured=*/false));
    rois.push_back(roi(0, 0.56, 0.56, std::nullopt));
    rois.push_back(roi(0, 0.56, 0.56, 100.0));
    const std::map<std::string, double> m = vision_metrics(rois, judging, not_measured);
    EXPECT_EQ(m.at("vision_rois_count"), 8.0);
    EXPECT_DOUBLE_EQ(m.at("vision_level_mismatch_pct"), 100.0 * 3 / 8);
    EXPECT_DOUBLE_EQ(m.at("vision_level_high_pct"), 100.0 * 2 / 8);
    EXPECT_DOUBLE_EQ(m.at("vision_level_low_pct"), 100.0 * 1 / 8);
    EXPECT_DOUBLE_EQ(m.at("vision_rois_unmeasured_pct"), 100.0 * 1 / 8);
    // Per camera and the worst: the left camera's 3 of 4 is not averaged with
    // the right camera's none.
    EXPECT_DOUBLE_EQ(m.at("vision_camera0_level_mismatch_pct"), 75.0);
    EXPECT_DOUBLE_EQ(m.at("vision_camera1_level_mismatch_pct"), 0.0);
    EXPECT_DOUBLE_EQ(m.at("vision_worst_camera_level_mismatch_pct"), 75.0);
    EXPECT_DOUBLE_EQ(m.at("vision_worst_camera_rois_unmeasured_pct"), 25.0);
    // Density error in points over the measured ROIs only: left (19 + 0 + 0) / 3.
    EXPECT_NEAR(m.at("vision_camera0_density_error_mean_abs_pct"), 19.0 / 3.0, 1e-9);
    EXPECT_NEAR(m.at("vision_camera1_density_error_mean_abs_pct"), 0.25, 1e-9);
    EXPECT_NEAR(m.at("vision_worst_camera_density_error_mean_abs_pct"), 19.0 / 3.0, 1e-9);
    EXPECT_NEAR(m.at("vision_density_error_max_abs_pct"), 19.0, 1e-9);
    EXPECT_TRUE(not_measured.empty());
}

TEST(VisionMetrics, NothingJudgedOrNothingMeasuredIsNamedNotZero) {
    const VisionJudging judging;
    std::map<std::string, std::string> not_measured;
    std::map<std::string, double> m = vision_metrics({}, judging, not_measured);
    EXPECT_EQ(m.at("vision_rois_count"), 0.0);
    EXPECT_EQ(m.count("vision_worst_camera_level_mismatch_pct"), 0u);
    EXPECT_EQ(not_measured.count("vision_worst_camera_level_mismatch_pct"), 1u);

    // A dead camera: frames never delivered, nothing measured, a density error
    // that cannot be 0 because nothing was measured.
    not_measured.clear();
    RoiJudged dead = roi(0, 0.3, 0.0, 100.0, false);
    dead.delivered = false;
    dead.reported = false;
    m = vision_metrics({dead, dead}, judging, not_measured);
    EXPECT_EQ(m.at("vision_frames_missing_pct"), 100.0);
    EXPECT_EQ(m.at("vision_worst_camera_rois_unmeasured_pct"), 100.0);
    EXPECT_EQ(m.count("vision_worst_camera_density_error_mean_abs_pct"), 0u);
    EXPECT_EQ(not_measured.count("vision_worst_camera_density_error_mean_abs_pct"), 1u);
    EXPECT_EQ(m.count("vision_reports_missing_pct"), 0u);  // of delivered frames: none
}

TEST(VisionMetrics, DoseByCoverSplitsAtSec52s40Percent) {
    const std::vector<RoiJudged> rois = {roi(0, 0.26, 0.26, 40.0), roi(0, 0.399, 0.4, 40.0), roi(1, 0.40, 0.4, 100.0),
                                         roi(1, 0.56, 0.56, 100.0), roi(1, 0.56, 0.56, 100.0)};
    std::map<std::string, std::string> not_measured;
    const std::map<std::string, double> m = dose_by_cover_metrics(rois, {1.0, 0.5, 2.0, 1.5, 3.0}, not_measured);
    EXPECT_TRUE(not_measured.empty());
    EXPECT_EQ(m.at("vision_sparse_rois_count"), 2.0);
    EXPECT_EQ(m.at("vision_normal_rois_count"), 3.0);
    EXPECT_DOUBLE_EQ(m.at("vision_dose_sparse_rois_ul_cm2"), 0.75);
    EXPECT_DOUBLE_EQ(m.at("vision_dose_normal_rois_ul_cm2"), 6.5 / 3.0);
    EXPECT_EQ(dose_by_cover_metrics({}, {}, not_measured).count("vision_dose_sparse_rois_ul_cm2"), 0u);
    EXPECT_THROW(dose_by_cover_metrics(rois, {1.0}, not_measured), std::invalid_argument);
}

TEST(VisionMetrics, AClassWithARoiOffTheJudgedGroundHasNoMeanDose) {
    // The last normal ROI's square reaches off the ground (NaN): the normal
    // mean over the other two would be another set's mean; the sparse one stands.
    const std::vector<RoiJudged> rois = {roi(0, 0.26, 0.26, 40.0), roi(0, 0.399, 0.4, 40.0), roi(1, 0.40, 0.4, 100.0),
                                         roi(1, 0.56, 0.56, 100.0), roi(1, 0.56, 0.56, 100.0)};
    std::map<std::string, std::string> not_measured;
    const std::map<std::string, double> m = dose_by_cover_metrics(rois, {1.0, 0.5, 2.0, 1.5, std::nan("")}, not_measured);
    EXPECT_DOUBLE_EQ(m.at("vision_dose_sparse_rois_ul_cm2"), 0.75);
    EXPECT_EQ(m.count("vision_dose_normal_rois_ul_cm2"), 0u);
    EXPECT_EQ(not_measured.at("vision_dose_normal_rois_ul_cm2"),
              "1 of the 3 normal ROIs' squares reach off the judged ground (judge.ground): their dose is unknown");
    EXPECT_EQ(not_measured.count("vision_dose_sparse_rois_ul_cm2"), 0u);
    EXPECT_EQ(m.at("vision_normal_rois_count"), 3.0);
}

TEST(VisionMetrics, PapersAverageCoverageOverTheirCellsAndTheStripItsDose) {
    const CoverageModel model;
    // A paper half on a stripe (dose 2) and half off (0): its coverage is the
    // mean of the cells' coverages, not the coverage of the mean dose.
    const std::vector<DoseCells> papers = {DoseCells{{2.0, 2.0, 0.0, 0.0}}, DoseCells{{1.0, 1.0, 1.0, 1.0}}};
    const std::map<std::string, double> m = paper_metrics(papers, model);
    EXPECT_NEAR(m.at("coverage_paper0_pct"), 50.0 * paper_coverage(model, 2.0), 1e-9);
    EXPECT_LT(m.at("coverage_paper0_pct"), m.at("coverage_paper1_pct"));  // same mean dose, less coverage
    EXPECT_EQ(m.at("dose_paper0_ul_cm2"), 1.0);
    EXPECT_EQ(m.at("dose_mean_ul_cm2"), 1.0);
    EXPECT_THROW(paper_metrics({DoseCells{}}, model), std::invalid_argument);

    std::map<std::string, std::string> not_measured;
    const std::map<std::string, double> strip = strip_metrics(DoseCells{{2.0, 0.0, 2.0, 0.0}}, model, not_measured);
    EXPECT_EQ(strip.at("strip_dose_mean_ul_cm2"), 1.0);
    EXPECT_NEAR(strip.at("strip_dose_cv_pct"), 100.0 * std::sqrt(4.0 / 3.0), 1e-9);
    EXPECT_TRUE(not_measured.empty());
    EXPECT_THROW(strip_metrics(DoseCells{}, model, not_measured), std::invalid_argument);
    // Nothing laid, or one cell: no spread to measure, never a CV of 0 (perfectly even).
    const std::map<std::string, double> bare = strip_metrics(DoseCells{{0.0, 0.0, 0.0}}, model, not_measured);
    EXPECT_EQ(bare.at("strip_dose_mean_ul_cm2"), 0.0);
    EXPECT_EQ(bare.count("strip_dose_cv_pct"), 0u);
    EXPECT_EQ(not_measured.at("strip_dose_cv_pct"), "nothing was laid on the strip");
    not_measured.clear();
    EXPECT_EQ(strip_metrics(DoseCells{{2.0}}, model, not_measured).count("strip_dose_cv_pct"), 0u);
    EXPECT_EQ(not_measured.at("strip_dose_cv_pct"), "the strip holds one ground cell: no spread to measure");

    const GroundRect card = paper_at(1.0, -2.0);
    EXPECT_NEAR(card.east_max_m - card.east_min_m, 0.076, 1e-12);
    EXPECT_NEAR(card.north_max_m - card.north_min_m, 0.026, 1e-12);
}

}  // namespace
