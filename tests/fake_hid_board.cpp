#include "tests/fake_hid_board.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

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
    if (command.protocol_version > firmware_version_) {
        // A version-1 firmware's frame check: it does not know this version.
        last_problem_ = hid::ReportProblem::unsupported_version;
        ++commands_refused_;
        queue_status(now_us_);
        return;
    }
    const auto newly_captured = static_cast<std::uint8_t>(command.pwm_capture_inputs & ~capture_inputs_);
    reported_levels_ = static_cast<std::uint8_t>((reported_levels_ & ~newly_captured) | (pin_levels_ & newly_captured));
    capture_inputs_ = command.pwm_capture_inputs;
    if (capture_inputs_ == 0) edge_buffer_.clear();
    status_version_ = command.protocol_version;
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
    if (capture_inputs_ == 0) {
        capture_edges(now_us_, end);  // the pins move; nothing is captured
        // Periodic reports at every multiple of the period passed on the way.
        for (std::uint64_t next = (now_us_ / kStatusPeriodUs + 1) * kStatusPeriodUs; next <= end;
             next += kStatusPeriodUs) {
            queue_status(next);
        }
        now_us_ = end;
        return;
    }
    // Capture on: interrupt interval by interrupt interval.
    std::uint64_t done = now_us_;
    for (std::uint64_t tick = (now_us_ / kInterruptIntervalUs + 1) * kInterruptIntervalUs; tick <= end;
         tick += kInterruptIntervalUs) {
        capture_edges(done, tick);
        done = tick;
        if (tick % kStatusPeriodUs == 0) {
            queue_status(tick);
            queue_edge_report(tick);
        } else if (edge_buffer_.size() >= hid::kMaxEdgesPerReport) {
            queue_edge_report(tick);
        }
    }
    capture_edges(done, end);
    now_us_ = end;
}

void FakeHidBoard::set_pwm_source(int input, PwmSource source) {
    if (input < 0 || input >= hid::kPwmCaptureInputs) throw std::invalid_argument("fake board: no capture input " + std::to_string(input));
    if (!(source.frequency_hz > 0.0) || !(source.duty_pct >= 0.0 && source.duty_pct <= 100.0)) {
        throw std::invalid_argument("fake board: PWM source needs frequency > 0 and duty 0..100");
    }
    const auto i = static_cast<std::size_t>(input);
    sources_[i].push_back(SourceSpell{now_us_, source});
    // The pin goes to the new source's level at once.
    const bool now_high = pin_level(input, now_us_);
    if (now_high != (((pin_levels_ >> input) & 1u) != 0)) injected_[i].emplace_back(now_us_, now_high);
}

void FakeHidBoard::inject_edge(int input, std::uint64_t time_us, bool rising) {
    if (input < 0 || input >= hid::kPwmCaptureInputs || time_us < now_us_) {
        throw std::invalid_argument("fake board: an injected edge needs an input 0..5 and a time not before now");
    }
    injected_[static_cast<std::size_t>(input)].emplace_back(time_us, rising);
}

void FakeHidBoard::suppress_edges(int input, std::uint64_t from_us, std::uint64_t to_us) {
    if (input < 0 || input >= hid::kPwmCaptureInputs) throw std::invalid_argument("fake board: no capture input " + std::to_string(input));
    suppressed_[static_cast<std::size_t>(input)].emplace_back(from_us, to_us);
}

// The source's level at `time_us` (the spell in effect then), by its own
// period arithmetic; edges fall on whole microseconds (the board's timer).
bool FakeHidBoard::pin_level(int input, std::uint64_t time_us) const {
    const auto& spells = sources_[static_cast<std::size_t>(input)];
    const SourceSpell* spell = nullptr;
    for (const SourceSpell& s : spells) {
        if (s.from_us <= time_us) spell = &s;
    }
    if (spell == nullptr || spell->source.duty_pct <= 0.0) return false;
    if (spell->source.duty_pct >= 100.0) return true;
    const double period = 1e6 / spell->source.frequency_hz;
    const double k = std::floor((static_cast<double>(time_us) - spell->source.phase_us) / period);
    const auto rise = std::llround(spell->source.phase_us + k * period);
    const auto fall = std::llround(spell->source.phase_us + k * period + spell->source.duty_pct / 100.0 * period);
    const auto t = static_cast<long long>(time_us);
    return t >= rise && t < fall;
}

void FakeHidBoard::capture_edges(std::uint64_t from_us, std::uint64_t to_us) {
    struct Event {
        std::uint64_t time;
        int input;
        bool rising;
    };
    std::vector<Event> events;
    for (int input = 0; input < hid::kPwmCaptureInputs; ++input) {
        const auto i = static_cast<std::size_t>(input);
        const auto& spells = sources_[i];
        for (std::size_t j = 0; j < spells.size(); ++j) {
            const PwmSource& src = spells[j].source;
            const std::uint64_t spell_from = spells[j].from_us;
            const std::uint64_t spell_to = j + 1 < spells.size() ? spells[j + 1].from_us : to_us + 1;
            const std::uint64_t a = std::max(from_us, spell_from);
            const std::uint64_t b = std::min(to_us, spell_to > 0 ? spell_to - 1 : 0);
            if (a >= b || src.duty_pct <= 0.0 || src.duty_pct >= 100.0) continue;
            const double period = 1e6 / src.frequency_hz;
            const double high = src.duty_pct / 100.0 * period;
            for (double k = std::floor((static_cast<double>(a) - src.phase_us) / period) - 1.0;; k += 1.0) {
                const double rise = src.phase_us + k * period;
                if (rise > static_cast<double>(b) + 1.0) break;
                for (const auto& [x, rising] : {std::pair{rise, true}, std::pair{rise + high, false}}) {
                    const long long t = std::llround(x);
                    if (t > static_cast<long long>(a) && t <= static_cast<long long>(b) &&
                        t > static_cast<long long>(spell_from)) {
                        events.push_back({static_cast<std::uint64_t>(t), input, rising});
                    }
                }
            }
        }
        auto& injected = injected_[i];
        for (auto it = injected.begin(); it != injected.end();) {
            if (it->first <= to_us) {
                events.push_back({it->first, input, it->second});
                it = injected.erase(it);
            } else {
                ++it;
            }
        }
    }
    std::stable_sort(events.begin(), events.end(), [](const Event& x, const Event& y) { return x.time < y.time; });
    for (const Event& e : events) {
        const auto mask = static_cast<std::uint8_t>(1u << e.input);
        pin_levels_ = e.rising ? static_cast<std::uint8_t>(pin_levels_ | mask) : static_cast<std::uint8_t>(pin_levels_ & ~mask);
        if ((capture_inputs_ & mask) == 0) continue;
        bool missed = false;
        for (const auto& [a, b] : suppressed_[static_cast<std::size_t>(e.input)]) missed = missed || (e.time >= a && e.time <= b);
        if (missed) continue;
        if (edge_buffer_.size() == kEdgeBufferCapacity) {
            ++edges_lost_;
            overflow_ = true;
            continue;
        }
        ++edges_captured_;
        edge_buffer_.push_back(hid::CapturedEdge{static_cast<std::uint32_t>(e.time), static_cast<std::uint8_t>(e.input), e.rising});
    }
}

void FakeHidBoard::queue_edge_report(std::uint64_t time_us) {
    hid::EdgeReport report;
    report.sequence = ++edge_sequence_;
    report.overflow = overflow_;
    overflow_ = false;
    while (!edge_buffer_.empty() && report.edges.size() < hid::kMaxEdgesPerReport) {
        const hid::CapturedEdge edge = edge_buffer_.front();
        edge_buffer_.pop_front();
        const auto mask = static_cast<std::uint8_t>(1u << edge.input);
        reported_levels_ = edge.rising ? static_cast<std::uint8_t>(reported_levels_ | mask)
                                       : static_cast<std::uint8_t>(reported_levels_ & ~mask);
        report.edges.push_back(edge);
    }
    if (edge_buffer_.empty()) {
        // Everything captured is out: the levels are the pins' (they differ
        // from the edges' only where an edge was missed or lost).
        reported_levels_ = static_cast<std::uint8_t>(pin_levels_ & capture_inputs_);
        report.report_time_us = static_cast<std::uint32_t>(time_us);
    } else {
        // Capture is complete only up to the first edge still waiting.
        report.report_time_us = edge_buffer_.front().time_us;
    }
    report.levels = static_cast<std::uint8_t>(reported_levels_ & capture_inputs_);
    ++edge_reports_sent_;
    queue_report(hid::encode_edges(report));
}

void FakeHidBoard::queue_report(const hid::Report& report) {
    if (queue_.size() == kQueueCapacity) queue_.pop_front();  // hidraw drops the oldest
    queue_.emplace_back(report.begin(), report.end());
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
    status.protocol_version = std::min(status_version_, firmware_version_);
    return status;
}

void FakeHidBoard::queue_status(std::uint64_t time_us) { queue_report(hid::encode_status(status_at(time_us))); }

}  // namespace rig::testing
