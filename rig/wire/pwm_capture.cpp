#include "rig/wire/pwm_capture.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace rig {

PwmCapture::PwmCapture(PwmCaptureParams params) : params_(params) {
    if (params_.glitch_max_us > 100'000) {
        throw std::invalid_argument("pwm capture: glitch_max_us " + std::to_string(params_.glitch_max_us) +
                                    " outside 0..100000");
    }
    if (params_.steady_after_us < 1000 || params_.steady_after_us > 10'000'000) {
        throw std::invalid_argument("pwm capture: steady_after_us " + std::to_string(params_.steady_after_us) +
                                    " outside 1000..10000000");
    }
    if (params_.steady_after_us <= params_.glitch_max_us) {
        throw std::invalid_argument("pwm capture: steady_after_us must exceed glitch_max_us");
    }
}

std::int64_t PwmCapture::unwrap(std::uint32_t board_time_us) {
    if (last_board_time_) {
        unwrapped_ += hid::counter_ahead(*last_board_time_, board_time_us);
    } else {
        unwrapped_ = board_time_us;
    }
    last_board_time_ = board_time_us;
    return unwrapped_;
}

void PwmCapture::restart_all() {
    for (Input& in : inputs_) {
        if (in.last_rise || in.pending_time) ++periods_dropped_;
        in.pending_time.reset();
        in.last_rise.reset();
        in.last_fall.reset();
        in.level.reset();
    }
}

void PwmCapture::commit(int input, std::int64_t time_us, bool rising) {
    Input& in = inputs_[static_cast<std::size_t>(input)];
    if (in.level && *in.level == rising) {
        // The opposite edge between was never captured: no period around it.
        ++periods_dropped_;
        in.last_fall.reset();
        if (rising) {
            in.last_rise = time_us;
        } else {
            in.last_rise.reset();
        }
        return;
    }
    in.level = rising;
    NozzlePwmReading& held = readings_[static_cast<std::size_t>(input)];
    if (held.state == NozzlePwmReading::State::steady) {
        // A line held at 0 % or 100 % that changes level: the valve driver
        // follows the line at once, so the reading does (a nozzle on at 100 %
        // is shut off by one falling edge, and waiting steady_after_us for the
        // next would put 0.375 m of overrun at 1.5 m/s on the controller). If
        // a PWM starts instead, its first complete period replaces this.
        held.duty_pct = rising ? 100.0 : 0.0;
        held.measured_at_us = time_us;
    }
    if (!rising) {
        if (in.last_rise) in.last_fall = time_us;
        return;
    }
    if (in.last_rise && in.last_fall) {
        const double period_us = static_cast<double>(time_us - *in.last_rise);
        const double high_us = static_cast<double>(*in.last_fall - *in.last_rise);
        if (period_us > 0.0) {
            NozzlePwmReading& reading = readings_[static_cast<std::size_t>(input)];
            reading.state = NozzlePwmReading::State::pwm;
            reading.duty_pct = std::clamp(100.0 * high_us / period_us, 0.0, 100.0);
            reading.frequency_hz = 1e6 / period_us;
            reading.measured_at_us = time_us;
            ++periods_;
        }
    }
    in.last_rise = time_us;
    in.last_fall.reset();
}

void PwmCapture::edge(int input, std::int64_t time_us, bool rising) {
    Input& in = inputs_[static_cast<std::size_t>(input)];
    if (in.pending_time) {
        if (time_us - *in.pending_time < static_cast<std::int64_t>(params_.glitch_max_us) &&
            rising != in.pending_rising) {
            // A phase too short to be the controller's: the glitch and its return both go.
            ++glitches_;
            in.pending_time.reset();
            return;
        }
        commit(input, *in.pending_time, in.pending_rising);
    }
    in.pending_time = time_us;
    in.pending_rising = rising;
    in.last_edge_time = time_us;
    in.seen_edge = true;
}

void PwmCapture::on_report(const hid::EdgeReport& report) {
    ++reports_;
    if (last_sequence_) {
        const auto gap = static_cast<std::uint16_t>(report.sequence - *last_sequence_ - 1);
        if (gap != 0) {
            reports_lost_ += gap;
            restart_all();
        }
    }
    last_sequence_ = report.sequence;
    if (report.overflow) {
        ++overflows_;
        restart_all();
    }
    for (const hid::CapturedEdge& e : report.edges) {
        if (e.input >= hid::kPwmCaptureInputs) continue;  // decode_edges refuses these
        edge(e.input, unwrap(e.time_us), e.rising);
    }
    const std::int64_t now = unwrap(report.report_time_us);
    if (!first_report_time_) first_report_time_ = now;
    for (int i = 0; i < hid::kPwmCaptureInputs; ++i) {
        Input& in = inputs_[static_cast<std::size_t>(i)];
        const bool high = (report.levels >> i) & 1u;
        // No later edge can cancel a pending one once the glitch window has passed.
        if (in.pending_time && now - *in.pending_time >= static_cast<std::int64_t>(params_.glitch_max_us)) {
            commit(i, *in.pending_time, in.pending_rising);
            in.pending_time.reset();
        }
        if (!in.pending_time && in.level && *in.level != high) {
            // The board's level disagrees with the edges: one was lost.
            ++periods_dropped_;
            in.level = high;
            in.last_rise.reset();
            in.last_fall.reset();
        }
        const std::int64_t quiet_since = in.seen_edge ? in.last_edge_time : *first_report_time_;
        if (!in.pending_time && now - quiet_since >= static_cast<std::int64_t>(params_.steady_after_us)) {
            NozzlePwmReading& reading = readings_[static_cast<std::size_t>(i)];
            reading.state = NozzlePwmReading::State::steady;
            reading.duty_pct = high ? 100.0 : 0.0;
            reading.frequency_hz = 0.0;
            reading.measured_at_us = now;
            in.level = high;
            in.last_rise.reset();
            in.last_fall.reset();
        }
    }
}

std::vector<double> PwmCapture::duty_pct() const {
    std::vector<double> duty;
    for (const NozzlePwmReading& r : readings_) duty.push_back(r.duty_pct);
    return duty;
}

double PwmCapture::frequency_hz() const {
    std::vector<double> f;
    for (const NozzlePwmReading& r : readings_) {
        if (r.state == NozzlePwmReading::State::pwm) f.push_back(r.frequency_hz);
    }
    if (f.empty()) return 0.0;
    std::sort(f.begin(), f.end());
    return f.size() % 2 ? f[f.size() / 2] : 0.5 * (f[f.size() / 2 - 1] + f[f.size() / 2]);
}

msg::NozzlePwm PwmCapture::nozzle_pwm(int nozzles) const {
    if (nozzles < 1 || nozzles > hid::kPwmCaptureInputs) {
        throw std::invalid_argument("pwm capture: " + std::to_string(nozzles) + " nozzles, the board captures 1.." +
                                    std::to_string(hid::kPwmCaptureInputs));
    }
    std::vector<double> duty = duty_pct();
    duty.resize(static_cast<std::size_t>(nozzles));
    msg::NozzlePwm pwm;
    pwm.frequency_hz(frequency_hz());
    pwm.duty_pct(duty);
    return pwm;
}

}  // namespace rig
