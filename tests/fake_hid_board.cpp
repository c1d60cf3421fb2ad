#include "tests/fake_hid_board.h"

#include <algorithm>

namespace rig::testing {
namespace {
constexpr std::uint64_t kMicrosecondsPerSecond = 1'000'000;
}

std::uint32_t FakeHidBoard::PulseOutput::emitted_at(std::uint64_t time_us) const {
    if (to_emit == 0 || time_us <= command_time_us) return count_at_command;
    const std::uint64_t elapsed = time_us - command_time_us;
    // Spacing is max(interval / n, 1 / max rate): the count is the smaller of
    // what each spacing allows.
    const std::uint64_t due = elapsed >= interval_us ? to_emit : to_emit * elapsed / interval_us;
    const std::uint64_t allowed = std::min<std::uint64_t>(elapsed, 1ull << 40) * hid::kMaxPulseRateHz /
                                  kMicrosecondsPerSecond;
    const auto emitted = static_cast<std::uint32_t>(std::min({due, allowed, std::uint64_t{to_emit}}));
    return count_at_command + emitted;  // wraps at 2^32 like the counter it is
}

bool FakeHidBoard::PulseOutput::rate_limited() const {
    return std::uint64_t{to_emit} * kMicrosecondsPerSecond > std::uint64_t{hid::kMaxPulseRateHz} * interval_us;
}

void FakeHidBoard::PulseOutput::command(std::uint32_t target, std::uint32_t interval, bool rebase,
                                        std::uint64_t time_us) {
    const std::uint32_t current = emitted_at(time_us);
    command_time_us = time_us;
    interval_us = interval;
    behind = false;
    to_emit = 0;
    if (rebase) {
        count_at_command = target;
        return;
    }
    count_at_command = current;
    const std::int64_t ahead = hid::counter_ahead(current, target);
    if (ahead < 0) {
        behind = true;  // held: a pulse output cannot take pulses back
        return;
    }
    to_emit = static_cast<std::uint32_t>(ahead);
}

void FakeHidBoard::write_report(std::span<const std::uint8_t> report) {
    const auto decoded = hid::decode_command(report);
    if (!decoded.ok()) {
        // Firmware keeps its state and says why in the next status report.
        last_problem_ = decoded.error.problem;
        ++commands_refused_;
        queue_status(now_us_);
        return;
    }
    const hid::BoardCommand& command = *decoded.value;
    wheel_.command(command.signals.wheel_encoder_count, command.spread_interval_us, command.rebase_counters, now_us_);
    flow_.command(command.signals.main_flow_pulses, command.spread_interval_us, command.rebase_counters, now_us_);
    levels_ = command.signals;
    last_command_sequence_ = command.sequence;
    last_problem_ = hid::ReportProblem::none;
    ++commands_applied_;
    queue_status(now_us_);
}

std::optional<std::vector<std::uint8_t>> FakeHidBoard::read_report(std::chrono::milliseconds timeout) {
    if (queue_.empty()) {
        if (timeout.count() <= 0) return std::nullopt;
        queue_status(now_us_);  // the next periodic report
    }
    std::vector<std::uint8_t> report = std::move(queue_.front());
    queue_.pop_front();
    return report;
}

void FakeHidBoard::advance_us(std::uint64_t microseconds) {
    const std::uint64_t end = now_us_ + microseconds;
    // Periodic reports at every multiple of the period passed on the way.
    for (std::uint64_t next = (now_us_ / kStatusPeriodUs + 1) * kStatusPeriodUs; next <= end;
         next += kStatusPeriodUs) {
        queue_status(next);
    }
    now_us_ = end;
}

void FakeHidBoard::set_relay_inputs(const io::ActuatorCommands& relays) {
    relays_ = relays;
    queue_status(now_us_);
}

void FakeHidBoard::set_indicator_inputs(const io::ControllerIndicators& indicators) {
    indicators_ = indicators;
    queue_status(now_us_);
}

void FakeHidBoard::queue_raw_report(std::vector<std::uint8_t> bytes) { queue_.push_back(std::move(bytes)); }

io::DeviceSignals FakeHidBoard::outputs() const {
    io::DeviceSignals outputs = levels_;
    outputs.wheel_encoder_count = wheel_encoder_emitted();
    outputs.main_flow_pulses = main_flow_emitted();
    return outputs;
}

hid::BoardStatus FakeHidBoard::status_at(std::uint64_t time_us) {
    hid::BoardStatus status;
    status.sequence = ++status_sequence_;
    status.last_command_sequence = last_command_sequence_;
    status.actuators = relays_;
    status.indicators = indicators_;
    status.wheel_encoder_emitted = wheel_.emitted_at(time_us);
    status.main_flow_emitted = flow_.emitted_at(time_us);
    status.board_time_us = static_cast<std::uint32_t>(time_us);  // free-running, wraps
    status.pulses_pending = wheel_.emitted_at(time_us) != wheel_.count_at_command + wheel_.to_emit ||
                            flow_.emitted_at(time_us) != flow_.count_at_command + flow_.to_emit;
    status.rate_limited = wheel_.rate_limited() || flow_.rate_limited();
    status.target_behind = wheel_.behind || flow_.behind;
    status.last_command_problem = last_problem_;
    return status;
}

void FakeHidBoard::queue_status(std::uint64_t time_us) {
    const hid::Report report = hid::encode_status(status_at(time_us));
    if (queue_.size() == kQueueCapacity) queue_.pop_front();  // hidraw drops the oldest
    queue_.emplace_back(report.begin(), report.end());
}

}  // namespace rig::testing
