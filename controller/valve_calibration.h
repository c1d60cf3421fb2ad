#pragma once
// What the controller believes about its valve: the calibration of seed 000 sec.
// 3.1.2 (Fig. 11), one straight line main = slope x pump + intercept per
// calibrated opening, measured once on the bench. Between calibrated openings it
// interpolates linearly; the real valve (emulators/flow_map.h) is not obliged to
// agree, which is what the PID is for.
//
// Pre-adjustment (sec. 2.2.2): before the nozzles open, drive the valve to the
// opening this calibration predicts for the target at the measured pump flow.
#include <vector>

namespace rig::controller {

struct CalibratedOpening {
    double opening_pct = 0.0;
    double slope = 0.0;
    double intercept_l_min = 0.0;
};

// The lines the reference controller ships with: those its calibration run
// measured on the rig (controller/valve_calibration_procedure.h,
// cases/fig11-calibration), not the plant's own (emulators/flow_map.h).
std::vector<CalibratedOpening> default_calibration();

class ValveCalibration {
public:
    // Throws std::invalid_argument unless sorted by opening (at least two) with a
    // flow rising with opening at pump flows 30-81 L/min.
    explicit ValveCalibration(std::vector<CalibratedOpening> lines);

    // Predicted main flow; outside the calibrated range the end segments are extended.
    double predicted_flow_l_min(double opening_pct, double pump_flow_l_min) const;
    // The opening predicted to give `flow_l_min`, in [0, 100].
    double opening_for(double flow_l_min, double pump_flow_l_min) const;
    double lowest_opening_pct() const { return lines_.front().opening_pct; }
    double highest_opening_pct() const { return lines_.back().opening_pct; }

private:
    std::vector<CalibratedOpening> lines_;
};

}  // namespace rig::controller
