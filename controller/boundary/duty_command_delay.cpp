#include "controller/boundary/duty_command_delay.h"

#include <stdexcept>
#include <string>

namespace rig::controller::boundary {

DutyCommandDelay::DutyCommandDelay(TimeNs delay_ns) : delay_ns_(delay_ns) {
    if (delay_ns < 0) {
        throw std::invalid_argument("duty command delay: must be >= 0 ns, got " + std::to_string(delay_ns));
    }
}

void DutyCommandDelay::decide(const std::vector<double>& duty_pct, TimeNs now_ns) {
    if (last_decided_ && *last_decided_ == duty_pct) return;
    queued_.push_back(Queued{now_ns + delay_ns_, duty_pct});
    last_decided_ = duty_pct;
}

std::vector<std::vector<double>> DutyCommandDelay::take_due(TimeNs now_ns) {
    std::vector<std::vector<double>> due;
    while (!queued_.empty() && queued_.front().due_ns <= now_ns) {
        due.push_back(std::move(queued_.front().duty_pct));
        queued_.pop_front();
    }
    return due;
}

TimeNs DutyCommandDelay::next_due_ns() const { return queued_.empty() ? kNever : queued_.front().due_ns; }

}  // namespace rig::controller::boundary
