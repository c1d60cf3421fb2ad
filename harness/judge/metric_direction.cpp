#include "harness/judge/metric_direction.h"

#include <cctype>
#include <cmath>

namespace rig::harness {

namespace {

using W = WorseDirection;

// Minimum effects: a deposition row is 0.05 m (docs/metrics.md "Deposition"),
// the judge's time resolution 10 ms (the plant's truth samples), a point of a
// percentage 0.05-0.5 depending on how finely the metric resolves; a count
// moves by whole runs' events.
const std::vector<MetricDeclaration> kDeclarations = {
    // Seed 000: breakpoint identification (Tables 3, 4)
    {"breakpoint_error_m", W::up, 0.01, "distance of the nozzle line from the breakpoint when declared (limited)"},
    {"breakpoint_error_signed_m", W::away_from_zero, 0.01, "the same, signed (+ declared late)"},
    {"breakpoint_store_error_m", W::up, 0.01, "distance of the stored position from the true breakpoint"},
    {"breakpoint_reached_at_s", W::none, 0.0, "when the breakpoint was declared: the route decides it"},
    {"breakpoint_reached_count", W::none, 0.0, "reached events; the error metrics judge a wrong count"},
    // Seed 000: flow control (Tables 1, 2, 5, Fig. 12, 14)
    {"flow_adjust_time_s", W::up, 0.05, "nozzle start to settled within +-3 % (limited)"},
    {"flow_adjust_time_from_command_s", W::up, 0.05, "the same from the section-open command"},
    {"flow_error_pct", W::up, 0.05, "mean absolute flow error over the target once due to be steady (limited)"},
    {"flow_error_kf11_signed_pct", W::away_from_zero, 0.05, "the paper's signed KF11 error (Table 5)"},
    {"flow_error_kf11_settled_signed_pct", W::away_from_zero, 0.05, "the same over the settled stretch"},
    {"flow_oscillation_pct", W::up, 0.1, "peak-to-peak of the flow over the last 3 s (Fig. 12)"},
    {"flow_band_exits_count", W::up, 1.0, "times the flow left the +-3 % band after entering it"},
    {"flow_settled", W::down, 1.0, "1 settled, 0 never"},
    {"flow_mean_l_min", W::none, 0.0, "the mean flow: the target decides it"},
    {"flow_nozzle_starts_count", W::none, 0.0, "nozzle starts: the route decides them"},
    {"flow_adjust_start_before_breakpoint_m", W::none, 0.0, "where the pre-adjustment began: a strategy, not a quality"},
    {"section_valve_open_delay_s", W::up, 0.01, "first open command to the valves open (Table 1, limited there)"},
    {"spray_landing_delay_s", W::up, 0.01, "first open command to droplets landing (Table 1, limited there)"},
    // Seed 000: valve calibration (Fig. 11)
    {"fig11_unexplained_pct", W::up, 0.1, "100 x (1 - R^2) of the worst line (limited in its case)"},
    {"fig11_lines_missing_count", W::up, 1.0, "openings of the paper's five without a line (limited in its case)"},
    {"fig11_lines_count", W::down, 1.0, "openings calibrated"},
    {"fig11_main_flow_min_l_min", W::none, 0.0, "the calibration's range: the plant's"},
    {"fig11_main_flow_max_l_min", W::none, 0.0, "the calibration's range: the plant's"},
    {"fig11_pump_span_l_min", W::none, 0.0, "the pump flows the points span: the case's"},
    // Seed 000: deposition (Table 6, Eq. 9-12)
    {"missed_m", W::up, 0.05, "strip sprayed by neither pass (limited)"},
    {"overlap_m", W::up, 0.05, "strip sprayed by both passes (limited)"},
    {"cv_operational_pct", W::up, 0.5, "deposition CV over the operational area (Eq. 10)"},
    {"cv_repeated_pct", W::up, 0.5, "deposition CV over the repeated area (Eq. 11)"},
    {"cv_continuation_pct", W::up, 0.5, "deposition CV over the continuation area (Eq. 12)"},
    {"strip_length_m", W::none, 0.0, "the strip: the route's"},
    {"repeated_from_m", W::none, 0.0, "where the repeated stretch begins: overlap_m judges its length"},
    {"repeated_to_m", W::none, 0.0, "where the repeated stretch ends: overlap_m judges its length"},
    // Seed 000: the GNSS wire's faults, set by the case
    {"gnss_*_count", W::none, 0.0, "sentences the case's wire faults damaged: the case's input"},
    {"controller_nmea_rejected_count", W::none, 0.0, "sentences the controller says it refused: its own report"},
    // Both seeds with `guidance:` (docs/guidance.md): the autosteer's error from truth.
    {"guidance_*_cross_track_rms_m", W::up, 0.002, "RMS offset of the vehicle point from the route"},
    {"guidance_*_cross_track_peak_m", W::up, 0.005, "the largest offset"},
    {"guidance_heading_error_rms_deg", W::up, 0.05, "RMS heading error against the route"},
    {"guidance_moving_samples", W::none, 0.0, "truth samples judged: the route's"},
    // Seed 001: boundary shut-off (Tables 7, 8). The wet edge's signed
    // distance past the boundary: + sprays outside the area, - leaves its edge
    // dry. The cases limit the mean from above (the paper's concern is spray
    // outside), so the mean is worse upwards; a dry edge is what _min_m and
    // _stations_dry judge.
    {"*_excess_mean_m", W::up, 0.01, "mean wet edge past the boundary (Table 8)"},
    {"*_excess_nozzle*_mean_m", W::up, 0.01, "the same per nozzle"},
    {"boundary_overrun_mean_m", W::up, 0.01, "mean wet edge past the edge driven along (Table 7)"},
    {"boundary_overrun_nozzle*_mean_m", W::up, 0.01, "the same per nozzle"},
    {"*_max_m", W::up, 0.01, "the furthest station outside"},
    {"*_min_m", W::down, 0.01, "the furthest station short of the edge"},
    {"*_sd_m", W::up, 0.01, "the edge's spread along the stations (n-1 SD)"},
    {"*_stations_dry", W::up, 1.0, "stations where the edge was never wet"},
    {"*_stations", W::none, 0.0, "stations judged: the route's"},
    {"centre_out_spray_ml", W::up, 0.1, "volume delivered with the boom centre outside (Sec. 4.2)"},
    {"centre_out_close_s", W::up, 0.02, "longest leaving-to-last-delivery time"},
    {"centre_out_close_m", W::up, 0.02, "the centre's travel in it"},
    {"centre_out_crossings", W::none, 0.0, "spells outside: the route's"},
    {"centre_out_samples", W::none, 0.0, "truth samples judged"},
    // Seed 001: flow per duty (Table 3, Eq. 13): the plant's chain
    {"flow_nozzle*_duty*_l_min", W::none, 0.0, "what a nozzle delivered at a duty: the plant's"},
    {"flow_table_max_abs_error_pct", W::up, 0.1, "the chain against the case's flow table"},
    {"flow_table_mean_abs_error_pct", W::up, 0.1, "the same, mean"},
    {"flow_table_points", W::none, 0.0, "points measured"},
    {"eq13_r2", W::down, 0.001, "Eq. 13's fit"},
    {"eq13_slope_l_min_per_pct", W::none, 0.0, "Eq. 13's slope: the plant's"},
    {"eq13_intercept_l_min", W::none, 0.0, "Eq. 13's intercept: the plant's"},
    {"eq13_points", W::none, 0.0, "points fitted"},
    // Seed 001: vision (Tables 4-6, Eq. 14-17)
    {"vision_frames_missing_pct", W::none, 0.0, "frames the camera never sent: the case's fault"},
    {"vision_reports_missing_pct", W::up, 0.5, "delivered frames without a report"},
    {"vision_rois_unmeasured_pct", W::up, 0.5, "judged ROIs without a density"},
    {"vision_density_error_mean_pct", W::away_from_zero, 0.5, "reported minus true cover (Eq. 15-17)"},
    {"vision_density_error_mean_abs_pct", W::up, 0.5, "the same, absolute"},
    {"vision_density_error_max_abs_pct", W::up, 0.5, "the worst ROI's"},
    {"vision_level_mismatch_pct", W::up, 0.5, "duty not Eq. 14's level on the true cover"},
    {"vision_level_low_pct", W::up, 0.5, "duty below it"},
    {"vision_level_high_pct", W::up, 0.5, "duty above it"},
    {"vision_camera*_rois_unmeasured_pct", W::up, 0.5, "per camera"},
    {"vision_camera*_level_mismatch_pct", W::up, 0.5, "per camera"},
    {"vision_camera*_density_error_mean_abs_pct", W::up, 0.5, "per camera"},
    {"vision_worst_camera_rois_unmeasured_pct", W::up, 0.5, "the worse camera's (limited)"},
    {"vision_worst_camera_level_mismatch_pct", W::up, 0.5, "the worse camera's (limited)"},
    {"vision_worst_camera_density_error_mean_abs_pct", W::up, 0.5, "the worse camera's (limited)"},
    {"vision_true_density_mean_pct", W::none, 0.0, "the field's cover: the case's"},
    {"vision_measured_density_mean_pct", W::none, 0.0, "what the controller saw: vision_density_error_* judge it"},
    {"vision_rois_count", W::none, 0.0, "ROIs judged"},
    {"vision_sparse_rois_count", W::none, 0.0, "ROIs below 40 % cover: the field's"},
    {"vision_normal_rois_count", W::none, 0.0, "ROIs at or above it: the field's"},
    {"vision_dose_*", W::none, 0.0, "dose against cover: a rate, the level metrics judge it"},
    // Seed 001: deposition and coverage (Tables 5, 6)
    {"strip_dose_cv_pct", W::up, 0.5, "deposition CV along the strip"},
    {"strip_coverage_mean_pct", W::none, 0.0, "cover of the cards: the rate decides it"},
    {"strip_dose_mean_ul_cm2", W::none, 0.0, "dose: the rate decides it"},
    {"coverage_*", W::none, 0.0, "cover of the cards: the rate decides it"},
    {"dose_*", W::none, 0.0, "dose: the rate decides it"},
};

// '*' stands for one or more characters up to the pattern's next literal:
// numbered families ("nozzle3", "camera0") and the families of one stem.
bool matches(std::string_view pattern, std::string_view name) {
    if (pattern.empty()) return name.empty();
    if (pattern.front() == '*') {
        for (std::size_t skip = 1; skip <= name.size(); ++skip) {
            if (matches(pattern.substr(1), name.substr(skip))) return true;
        }
        return false;
    }
    return !name.empty() && pattern.front() == name.front() && matches(pattern.substr(1), name.substr(1));
}

}  // namespace

std::string_view worse_direction_name(WorseDirection direction) {
    switch (direction) {
        case WorseDirection::up: return "up";
        case WorseDirection::down: return "down";
        case WorseDirection::away_from_zero: return "away_from_zero";
        case WorseDirection::none: return "none";
    }
    return "none";
}

const std::vector<MetricDeclaration>& metric_declarations() { return kDeclarations; }

std::optional<MetricDeclaration> declared_metric(std::string_view metric) {
    for (const MetricDeclaration& declaration : kDeclarations) {
        if (matches(declaration.pattern, metric)) return declaration;
    }
    return std::nullopt;
}

bool is_worse(WorseDirection direction, double base, double value) {
    switch (direction) {
        case WorseDirection::up: return value > base;
        case WorseDirection::down: return value < base;
        case WorseDirection::away_from_zero: return std::fabs(value) > std::fabs(base);
        case WorseDirection::none: return false;
    }
    return false;
}

}  // namespace rig::harness
