#include "controller/flow_pid.h"

#include <algorithm>

namespace rig::controller {

FlowPid::FlowPid(PidGains gains, double integral_limit_l_min)
    : gains_(gains), integral_limit_l_min_(integral_limit_l_min) {}

void FlowPid::reset() {
    error_sum_ = 0.0;
    last_error_ = 0.0;
    has_last_ = false;
    last_output_ = 0.0;
}

double FlowPid::update(double error_l_min) {
    error_sum_ += error_l_min;
    if (gains_.ki > 0.0) {
        const double sum_limit = integral_limit_l_min_ / gains_.ki;
        error_sum_ = std::clamp(error_sum_, -sum_limit, sum_limit);
    }
    const double derivative = has_last_ ? error_l_min - last_error_ : 0.0;
    last_error_ = error_l_min;
    has_last_ = true;
    last_output_ = gains_.kp * error_l_min + gains_.ki * error_sum_ + gains_.kd * derivative;
    return last_output_;
}

}  // namespace rig::controller
