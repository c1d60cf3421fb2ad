#pragma once
// The valve calibration of seed 000 sec. 2.4.2 (Fig. 11), run by the controller
// on the rig as the paper ran it on the sprayer: with the sections open, hold
// the proportional valve at each calibrated opening in turn while the operator
// sets the pump's throttle to several flows (31.10-57.30 L/min in the paper,
// three repeats), record the pump-outlet reading (Eq. 8) against the main
// pipeline's (Eq. 3), and fit main = slope x pump + intercept per opening.
// The result is the controller's own data (ValveCalibration's lines), written
// to its state directory with each line's R^2 and point count.
//
// The procedure does not know when the throttle moves: it cycles through the
// openings for as long as the switch is on, and keeps a measurement only if
// the pump reading stayed steady through it (a throttle moving mid-measurement
// spoils that point, not the calibration).
#include <optional>
#include <string>
#include <vector>

#include "controller/valve_calibration.h"
#include "rig/runtime/clock.h"

namespace rig::controller {

struct CalibrationRunConfig {
    bool enabled = false;
    std::vector<double> openings_pct = {87.0, 90.0, 93.0, 94.0, 95.0};  // sec. 2.4.3 / Fig. 11
    // After the valve stops: the pipeline fills (its lag is tenths of a second)
    // and the meter's window (0.25 s) holds only the new flow.
    double settle_s = 2.0;
    double measure_s = 2.0;
    // The pump reading may move this much (of its mean) within a measurement.
    double steady_pump_pct = 1.0;
    // A line needs this many points spanning this much pump flow.
    int min_points = 3;
    double min_span_l_min = 5.0;
    std::string output_file = "valve-calibration.yaml";  // in the state directory
};

class ValveCalibrationProcedure {
public:
    explicit ValveCalibrationProcedure(CalibrationRunConfig config);

    // One control period with the sections open: the readings now (either may
    // be missing), whether the valve has finished its last move. Returns the
    // opening to send the valve to.
    double update(TimeNs now_ns, bool valve_idle, std::optional<double> pump_l_min, std::optional<double> main_l_min);
    // The switch went off: the next update starts a new hold at the current opening.
    void pause();

    struct Point {
        double opening_pct = 0.0;
        double pump_l_min = 0.0;
        double main_l_min = 0.0;
    };
    struct Line {
        CalibratedOpening line;
        double r2 = 0.0;
        int points = 0;
        double pump_min_l_min = 0.0;
        double pump_max_l_min = 0.0;
    };
    const std::vector<Point>& points() const { return points_; }
    // A line per opening with enough points (least squares), in opening order.
    std::vector<Line> fit() const;
    // The calibration file: the lines as the controller config's
    // `valve.calibration` takes them, with r2 and points beside each.
    std::string yaml() const;

private:
    enum class Step { move, settle, measure };
    void start_hold(TimeNs now_ns);

    CalibrationRunConfig config_;
    std::size_t opening_index_ = 0;
    Step step_ = Step::move;
    bool commanded_ = false;
    TimeNs step_since_ns_ = 0;
    std::vector<double> pump_samples_;
    std::vector<double> main_samples_;
    std::vector<Point> points_;
};

}  // namespace rig::controller
