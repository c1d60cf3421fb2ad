#include "harness/systems/boundary/vision_metrics.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace rig::harness {

double paper_coverage(const CoverageModel& model, double dose_ul_cm2) {
    if (!(dose_ul_cm2 >= 0.0) || !std::isfinite(dose_ul_cm2)) {
        throw std::invalid_argument("paper coverage: dose must be finite and >= 0 uL/cm^2, got " + std::to_string(dose_ul_cm2));
    }
    // Poisson: the chance that no stain covers a point is exp(-stain area per unit area).
    return 1.0 - std::exp(-model.stain_area_cm2_per_ul * dose_ul_cm2);
}

int eq14_level(const Eq14Levels& eq, double density, double speed_m_s) {
    const double q_l_min = eq.eq12_coefficient_l_min_per_m_s * density * speed_m_s / eq.k_max_cover;  // Eq. 12
    const double s_pct = (q_l_min - eq.eq13_intercept_l_min) / eq.eq13_slope_l_min_per_pct;        // Eq. 13 for s
    if (!(s_pct > eq.level0_max_pct)) return 0;
    return s_pct <= eq.level1_max_pct ? 1 : 2;
}

double eq14_level_duty_pct(const Eq14Levels& eq, int level) {
    return level == 0 ? 0.0 : level == 1 ? eq.level1_duty_pct : eq.level2_duty_pct;
}

namespace {

// What went wrong over a set of ROIs (one camera's, or all).
struct RoiTally {
    std::size_t judged = 0, delivered = 0, reported = 0, measured = 0, agree = 0, low = 0, high = 0;
    double error_sum = 0.0, abs_error_sum = 0.0, max_abs_error = 0.0, true_sum = 0.0, measured_sum = 0.0;

    void add(const RoiJudged& roi, const VisionJudging& judging) {
        ++judged;
        true_sum += roi.true_density;
        if (roi.delivered) ++delivered;
        if (roi.delivered && roi.reported) ++reported;
        if (roi.measured) {
            ++measured;
            const double error = roi.measured_density - roi.true_density;
            error_sum += error;
            abs_error_sum += std::abs(error);
            max_abs_error = std::max(max_abs_error, std::abs(error));
            measured_sum += roi.measured_density;
        }
        const double wanted =
            eq14_level_duty_pct(judging.eq14, eq14_level(judging.eq14, roi.true_density, roi.true_speed_m_s));
        // No command yet counts as off: a valve nobody drove is shut.
        const double ran = roi.duty_pct.value_or(0.0);
        if (std::abs(ran - wanted) < 0.5) {
            ++agree;
        } else if (ran < wanted) {
            ++low;
        } else {
            ++high;
        }
    }
    static double pct(std::size_t part, std::size_t whole) {
        return 100.0 * static_cast<double>(part) / static_cast<double>(whole);
    }
    double unmeasured_pct() const { return pct(judged - measured, judged); }
    double mismatch_pct() const { return pct(judged - agree, judged); }
    std::optional<double> error_mean_abs_pct() const {
        if (measured == 0) return std::nullopt;
        return 100.0 * abs_error_sum / static_cast<double>(measured);
    }
};

}  // namespace

std::map<std::string, double> vision_metrics(const std::vector<RoiJudged>& rois, const VisionJudging& judging,
                                             std::map<std::string, std::string>& not_measured) {
    std::map<std::string, double> out;
    RoiTally all;
    std::map<int, RoiTally> per_camera;
    for (const RoiJudged& roi : rois) {
        all.add(roi, judging);
        per_camera[roi.camera].add(roi, judging);
    }
    out["vision_rois_count"] = static_cast<double>(all.judged);
    if (all.judged == 0) {
        for (const char* name : {"vision_rois_unmeasured_pct", "vision_level_mismatch_pct", "vision_density_error_mean_abs_pct",
                                 "vision_density_error_max_abs_pct", "vision_worst_camera_rois_unmeasured_pct",
                                 "vision_worst_camera_level_mismatch_pct", "vision_worst_camera_density_error_mean_abs_pct"}) {
            not_measured[name] = "no frame's ROI lay in the judged zone";
        }
        return out;
    }
    // Limits are maxima (harness/spec/case_spec.h), so every share is of what went wrong.
    out["vision_frames_missing_pct"] = RoiTally::pct(all.judged - all.delivered, all.judged);
    if (all.delivered > 0) out["vision_reports_missing_pct"] = RoiTally::pct(all.delivered - all.reported, all.delivered);
    out["vision_rois_unmeasured_pct"] = all.unmeasured_pct();
    out["vision_true_density_mean_pct"] = 100.0 * all.true_sum / static_cast<double>(all.judged);
    out["vision_level_mismatch_pct"] = all.mismatch_pct();
    out["vision_level_low_pct"] = RoiTally::pct(all.low, all.judged);
    out["vision_level_high_pct"] = RoiTally::pct(all.high, all.judged);
    // Densities in percentage points of cover.
    if (all.measured > 0) {
        out["vision_density_error_mean_pct"] = 100.0 * all.error_sum / static_cast<double>(all.measured);
        out["vision_density_error_mean_abs_pct"] = *all.error_mean_abs_pct();
        out["vision_density_error_max_abs_pct"] = 100.0 * all.max_abs_error;
        out["vision_measured_density_mean_pct"] = 100.0 * all.measured_sum / static_cast<double>(all.measured);
    } else {
        for (const char* name : {"vision_density_error_mean_pct", "vision_density_error_mean_abs_pct", "vision_density_error_max_abs_pct"}) {
            not_measured[name] = "the controller reported no density for any judged ROI";
        }
    }
    // Per camera, and the worst: one faulty camera of two must not hide behind
    // the healthy one's half of the ROIs.
    double worst_unmeasured = 0.0, worst_mismatch = 0.0;
    std::optional<double> worst_error;
    for (const auto& [camera, tally] : per_camera) {
        const std::string prefix = "vision_camera" + std::to_string(camera) + "_";
        out[prefix + "rois_unmeasured_pct"] = tally.unmeasured_pct();
        out[prefix + "level_mismatch_pct"] = tally.mismatch_pct();
        worst_unmeasured = std::max(worst_unmeasured, tally.unmeasured_pct());
        worst_mismatch = std::max(worst_mismatch, tally.mismatch_pct());
        if (const std::optional<double> error = tally.error_mean_abs_pct()) {
            out[prefix + "density_error_mean_abs_pct"] = *error;
            worst_error = std::max(worst_error.value_or(0.0), *error);
        }
    }
    out["vision_worst_camera_rois_unmeasured_pct"] = worst_unmeasured;
    out["vision_worst_camera_level_mismatch_pct"] = worst_mismatch;
    if (worst_error) {
        out["vision_worst_camera_density_error_mean_abs_pct"] = *worst_error;
    } else {
        not_measured["vision_worst_camera_density_error_mean_abs_pct"] = "the controller reported no density for any judged ROI";
    }
    return out;
}

std::map<std::string, double> dose_by_cover_metrics(const std::vector<RoiJudged>& rois,
                                                    const std::vector<double>& dose_ul_cm2,
                                                    std::map<std::string, std::string>& not_measured) {
    if (dose_ul_cm2.size() != rois.size()) throw std::invalid_argument("dose by cover: one dose per ROI");
    // Sec. 5.2 classes areas by the computed density: sparse below 40 %, normal above.
    constexpr double kSparseBelow = 0.40;
    struct CoverClass {
        const char* name;
        double sum = 0.0;
        std::size_t rois = 0;
        std::size_t off_ground = 0;
    };
    CoverClass sparse{"sparse"};
    CoverClass normal{"normal"};
    for (std::size_t i = 0; i < rois.size(); ++i) {
        CoverClass& of = rois[i].true_density < kSparseBelow ? sparse : normal;
        ++of.rois;
        if (std::isfinite(dose_ul_cm2[i])) {
            of.sum += dose_ul_cm2[i];
        } else {
            ++of.off_ground;
        }
    }
    std::map<std::string, double> out;
    for (const CoverClass& of : {sparse, normal}) {
        const std::string prefix = std::string("vision_") + of.name;
        out[prefix + "_rois_count"] = static_cast<double>(of.rois);
        const std::string mean = "vision_dose_" + std::string(of.name) + "_rois_ul_cm2";
        if (of.off_ground > 0) {
            // A mean over the others would be another set's mean, passed off as this one's.
            not_measured[mean] = std::to_string(of.off_ground) + " of the " + std::to_string(of.rois) + " " + of.name +
                                     " ROIs' squares reach off the judged ground (judge.ground): their dose is unknown";
        } else if (of.rois > 0) {
            out[mean] = of.sum / static_cast<double>(of.rois);
        }
    }
    return out;
}

GroundRect paper_at(double east_m, double north_m) {
    constexpr double kAcrossM = 0.076;  // long side, east-west
    constexpr double kAlongM = 0.026;
    return GroundRect{east_m - kAcrossM / 2, east_m + kAcrossM / 2, north_m - kAlongM / 2, north_m + kAlongM / 2};
}

std::map<std::string, double> paper_metrics(const std::vector<DoseCells>& papers, const CoverageModel& model) {
    std::map<std::string, double> out;
    if (papers.empty()) return out;
    double coverage_sum = 0.0, dose_sum = 0.0;
    for (std::size_t i = 0; i < papers.size(); ++i) {
        const std::vector<double>& cells = papers[i].dose_ul_cm2;
        if (cells.empty()) throw std::invalid_argument("papers[" + std::to_string(i) + "]: no ground cell lies under it");
        double coverage = 0.0, dose = 0.0;
        for (const double d : cells) {
            coverage += paper_coverage(model, d);
            dose += d;
        }
        coverage /= static_cast<double>(cells.size());
        dose /= static_cast<double>(cells.size());
        out["coverage_paper" + std::to_string(i) + "_pct"] = 100.0 * coverage;
        out["dose_paper" + std::to_string(i) + "_ul_cm2"] = dose;
        coverage_sum += coverage;
        dose_sum += dose;
    }
    const auto n = static_cast<double>(papers.size());
    out["coverage_mean_pct"] = 100.0 * coverage_sum / n;
    out["dose_mean_ul_cm2"] = dose_sum / n;
    return out;
}

std::map<std::string, double> strip_metrics(const DoseCells& strip, const CoverageModel& model,
                                            std::map<std::string, std::string>& not_measured) {
    std::map<std::string, double> out;
    const std::vector<double>& cells = strip.dose_ul_cm2;
    if (cells.empty()) throw std::invalid_argument("dose strip: no ground cell lies inside it");
    double sum = 0.0, coverage = 0.0;
    for (const double d : cells) {
        sum += d;
        coverage += paper_coverage(model, d);
    }
    const auto n = static_cast<double>(cells.size());
    const double mean = sum / n;
    double squares = 0.0;
    for (const double d : cells) squares += (d - mean) * (d - mean);
    out["strip_dose_mean_ul_cm2"] = mean;
    // A spread over nothing laid, or over one cell, is no evenness: not a CV of 0.
    if (!(mean > 0.0)) {
        not_measured["strip_dose_cv_pct"] = "nothing was laid on the strip";
    } else if (cells.size() < 2) {
        not_measured["strip_dose_cv_pct"] = "the strip holds one ground cell: no spread to measure";
    } else {
        out["strip_dose_cv_pct"] = 100.0 * std::sqrt(squares / (n - 1.0)) / mean;
    }
    out["strip_coverage_mean_pct"] = 100.0 * coverage / n;
    return out;
}

}  // namespace rig::harness
