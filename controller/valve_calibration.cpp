#include "controller/valve_calibration.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace rig::controller {

std::vector<CalibratedOpening> default_calibration() {
    // Measured on the rig by the controller's own calibration run, as the paper
    // measured its valve (sec. 2.4.2): `rig run cases/fig11-calibration`, then
    // OUT/cases/fig11-valve-calibration/controller-state/valve-calibration.yaml
    // (R^2 1.0000 for each, 12-14 points over 31.1-57.3 L/min of pump flow).
    // tests/valve_calibration_run_test.cpp fails when they no longer agree.
    return {{87.0, 0.3502, 3.326}, {90.0, 0.3803, 4.164}, {93.0, 0.4201, 5.932}, {94.0, 0.4604, 7.676},
            {95.0, 0.5006, 9.920}};
}

ValveCalibration::ValveCalibration(std::vector<CalibratedOpening> lines) : lines_(std::move(lines)) {
    if (lines_.size() < 2) throw std::invalid_argument("valve calibration: at least two calibrated openings");
    for (std::size_t i = 1; i < lines_.size(); ++i) {
        if (!(lines_[i].opening_pct > lines_[i - 1].opening_pct)) {
            throw std::invalid_argument("valve calibration: openings must rise strictly (entry " + std::to_string(i) + ")");
        }
        for (double pump : {30.0, 81.0}) {
            if (!(lines_[i].slope * pump + lines_[i].intercept_l_min >
                  lines_[i - 1].slope * pump + lines_[i - 1].intercept_l_min)) {
                throw std::invalid_argument("valve calibration: flow must rise with opening (entry " +
                                            std::to_string(i) + ")");
            }
        }
    }
}

double ValveCalibration::predicted_flow_l_min(double opening_pct, double pump_flow_l_min) const {
    // Outside the calibrated range the end segments are extended.
    const double opening = opening_pct;
    auto upper = std::upper_bound(lines_.begin(), lines_.end(), opening,
                                  [](double value, const CalibratedOpening& line) { return value < line.opening_pct; });
    if (upper == lines_.end()) upper = std::prev(lines_.end());
    if (upper == lines_.begin()) upper = std::next(lines_.begin());
    const CalibratedOpening& high = *upper;
    const CalibratedOpening& low = *std::prev(upper);
    const double low_flow = low.slope * pump_flow_l_min + low.intercept_l_min;
    const double high_flow = high.slope * pump_flow_l_min + high.intercept_l_min;
    return low_flow + (opening - low.opening_pct) / (high.opening_pct - low.opening_pct) * (high_flow - low_flow);
}

double ValveCalibration::opening_for(double flow_l_min, double pump_flow_l_min) const {
    // Piecewise linear and rising: find the segment, then solve it.
    // (Below the first segment the loop's first pass extends it, above the last the last pass does.)
    for (std::size_t i = 1; i < lines_.size(); ++i) {
        const double high_flow = predicted_flow_l_min(lines_[i].opening_pct, pump_flow_l_min);
        if (flow_l_min <= high_flow || i + 1 == lines_.size()) {
            const double low_flow = predicted_flow_l_min(lines_[i - 1].opening_pct, pump_flow_l_min);
            const double fraction = (flow_l_min - low_flow) / (high_flow - low_flow);
            const double opening =
                lines_[i - 1].opening_pct + fraction * (lines_[i].opening_pct - lines_[i - 1].opening_pct);
            return std::clamp(opening, 0.0, 100.0);
        }
    }
    return 100.0;
}

}  // namespace rig::controller
