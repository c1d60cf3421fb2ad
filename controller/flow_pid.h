#pragma once
// Eq. 2 of seed 000, the discretised PID of the flow loop:
//   M(k) = Kp e(k) + Ki sum_{n<=k} e(n) + Kd (e(k) - e(k-1)),
// e = target - measured main flow (L/min), evaluated once per control period.
// The paper's gains (Kp 0.20, Ki 0.18, Kd 0.001, sec. 3.1.2) were found by trial
// on the real sprayer; the paper does not say what M drives. By default the
// reference controller takes M as a flow correction in L/min: the valve is sent
// to the opening the calibration predicts for (target + M), so the loop's gain
// does not change with the steepness of the valve curve (1-4 L/min per % between
// 87 and 95 %). `pid.output` picks the other readings (controller_config.h
// PidOutput); cases/fig12-pid-tuning shows which of them reproduce Fig. 12.
// The integral is clamped (anti-windup) so that |Ki sum e| stays within
// integral_limit_l_min.
namespace rig::controller {

struct PidGains {
    double kp = 0.20;
    double ki = 0.18;
    double kd = 0.001;
};

class FlowPid {
public:
    FlowPid(PidGains gains, double integral_limit_l_min);
    // One control period with error e (L/min); returns M (L/min).
    double update(double error_l_min);
    void reset();
    double last_output() const { return last_output_; }

private:
    PidGains gains_;
    double integral_limit_l_min_;
    double error_sum_ = 0.0;
    double last_error_ = 0.0;
    bool has_last_ = false;
    double last_output_ = 0.0;
};

}  // namespace rig::controller
