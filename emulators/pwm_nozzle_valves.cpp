#include "emulators/pwm_nozzle_valves.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "emulators/seeded_random.h"

namespace rig::emulators {
namespace {

constexpr double kMlMinToLitresPerSecond = 1.0 / 60000.0;

}  // namespace

PwmNozzleValves::PwmNozzleValves(PwmValveParams params, field2d::NozzleFlowTable table)
    : params_(params), table_(std::move(table)) {
    if (!std::isfinite(params_.frequency_hz) || params_.frequency_hz <= 0.0 || params_.frequency_hz > 1000.0) {
        throw std::invalid_argument("pwm valves: frequency_hz must be in (0, 1000], got " +
                                    std::to_string(params_.frequency_hz));
    }
    period_s_ = 1.0 / params_.frequency_hz;
    if (!std::isfinite(params_.response_s) || params_.response_s < 0.0 || params_.response_s >= 0.5 * period_s_) {
        throw std::invalid_argument("pwm valves: response_s must be in [0, half a PWM period = " +
                                    std::to_string(0.5 * period_s_) + " s), got " + std::to_string(params_.response_s));
    }
    if (params_.pwm_phase_s) {
        const double phase = *params_.pwm_phase_s;
        if (!std::isfinite(phase) || phase < 0.0 || phase >= period_s_) {
            throw std::invalid_argument("pwm valves: pwm_phase_s must be in [0, one period = " +
                                        std::to_string(period_s_) + " s), got " + std::to_string(phase));
        }
        phase_s_ = phase;
    } else {
        SeededRandom draw(params_.seed, "pwm_valves.phase");
        phase_s_ = draw.uniform01() * period_s_;
    }
    for (int n = 0; n < table_.nozzle_count(); ++n) {
        if (table_.max_duty_pct(n) != 100.0) {
            throw std::invalid_argument("pwm valves: flow table nozzle " + std::to_string(n) +
                                        " has no 100 % duty point (the fully open flow)");
        }
    }
    valves_.resize(static_cast<std::size_t>(table_.nozzle_count()));
    // One period before the one that contains t = 0, so that the first
    // integration latches the duty of that period (commands at t = 0 included).
    const std::int64_t first = phase_s_ > 0.0 ? -1 : 0;
    for (std::size_t n = 0; n < valves_.size(); ++n) {
        valves_[n].period = first - 1;
        valves_[n].flow_scale_ml_min = open_flow_ml_min(static_cast<int>(n), 100.0);
    }
}

const PwmNozzleValves::Valve& PwmNozzleValves::valve(int nozzle) const {
    if (nozzle < 0 || nozzle >= nozzle_count()) {
        throw std::invalid_argument("pwm valves: no nozzle " + std::to_string(nozzle) + " (have " +
                                    std::to_string(nozzle_count()) + ")");
    }
    return valves_[static_cast<std::size_t>(nozzle)];
}

void PwmNozzleValves::command(int nozzle, double duty_pct, TimeNs at_ns) {
    (void)valve(nozzle);  // range check
    if (!std::isfinite(duty_pct) || duty_pct < 0.0 || duty_pct > 100.0) {
        throw std::invalid_argument("pwm valves: nozzle " + std::to_string(nozzle) + ": duty must be in [0, 100] %, got " +
                                    std::to_string(duty_pct));
    }
    Valve& v = valves_[static_cast<std::size_t>(nozzle)];
    const double at_s = ns_to_seconds(at_ns);
    if (at_ns < now_ns_ || (!v.pending.empty() && at_s < v.pending.back().at_s) || at_s < v.last_command_s) {
        throw std::logic_error("pwm valves: nozzle " + std::to_string(nozzle) + ": command at " + std::to_string(at_s) +
                               " s is before what is already integrated or commanded (" +
                               std::to_string(ns_to_seconds(now_ns_)) + " s)");
    }
    v.last_command_s = at_s;
    v.pending.push_back(Command{at_s, duty_pct});
}

double PwmNozzleValves::open_time_per_period_s(double duty_pct) const {
    if (duty_pct >= 100.0) return period_s_;
    if (duty_pct <= 0.0) return 0.0;
    const double tau = params_.response_s;
    const double on = duty_pct / 100.0 * period_s_;
    const double off = period_s_ - on;
    if (tau == 0.0) return on;
    // Constant-rate stroke: a pulse shorter than the stroke never opens fully
    // (a triangle of base 2 on and height on / tau); a gap shorter than the
    // stroke never closes fully (the mirror image).
    if (on < tau) return on * on / tau;
    if (off < tau) return period_s_ - off * off / tau;
    return on;
}

double PwmNozzleValves::open_flow_ml_min(int nozzle, double duty_pct) const {
    (void)valve(nozzle);
    const double lowest = table_.min_duty_pct(nozzle);
    const double d = std::clamp(duty_pct, lowest, 100.0);
    return table_.flow_ml_min(nozzle, d) * period_s_ / open_time_per_period_s(d);
}

double PwmNozzleValves::mean_flow_ml_min(int nozzle, double duty_pct) const {
    if (duty_pct <= 0.0) return 0.0;
    return open_flow_ml_min(nozzle, duty_pct) * open_time_per_period_s(duty_pct) / period_s_;
}

double PwmNozzleValves::integrate(Valve& v, int nozzle, double from_s, double to_s) const {
    const bool latched = params_.latch_at_period_start;
    const double tau = params_.response_s;
    double litres = 0.0;
    double t = from_s;
    const auto apply_pending_up_to = [&](double limit_s) {
        while (!v.pending.empty() && v.pending.front().at_s <= limit_s) {
            v.active_duty_pct = v.pending.front().duty_pct;
            v.pending.pop_front();
            // A valve still closing after a 0 % command delivers at the rate of
            // the pulse it is closing from: the scale only follows non-zero duties.
            if (v.active_duty_pct > 0.0) v.flow_scale_ml_min = open_flow_ml_min(nozzle, v.active_duty_pct);
        }
    };
    while (t < to_s) {
        while (period_start_s(v.period + 1) <= t) {
            ++v.period;
            if (latched) apply_pending_up_to(period_start_s(v.period));
        }
        if (!latched) apply_pending_up_to(t);
        double next = std::min(to_s, period_start_s(v.period + 1));
        const double d = v.active_duty_pct;
        bool drive = false;
        if (d >= 100.0) {
            drive = true;
        } else if (d > 0.0) {
            const double fall_s = period_start_s(v.period) + d / 100.0 * period_s_;
            drive = t < fall_s;
            if (drive) next = std::min(next, fall_s);
        }
        if (!latched && !v.pending.empty()) next = std::min(next, v.pending.front().at_s);
        const double dt = next - t;
        const double target = drive ? 1.0 : 0.0;
        const double x0 = v.opening;
        double area = 0.0;
        if (tau == 0.0 || x0 == target) {
            area = target * dt;
            v.opening = target;
        } else {
            const double stroke_s = std::abs(target - x0) * tau;
            if (stroke_s >= dt) {
                const double x1 = std::clamp(x0 + (target > x0 ? dt : -dt) / tau, 0.0, 1.0);
                area = 0.5 * (x0 + x1) * dt;
                v.opening = x1;
            } else {
                area = 0.5 * (x0 + target) * stroke_s + target * (dt - stroke_s);
                v.opening = target;
            }
        }
        litres += area * v.flow_scale_ml_min * kMlMinToLitresPerSecond;
        t = next;
    }
    return litres;
}

std::vector<double> PwmNozzleValves::advance(TimeNs to_ns) {
    if (to_ns < now_ns_) {
        throw std::logic_error("pwm valves: cannot integrate back to " + std::to_string(ns_to_seconds(to_ns)) +
                               " s from " + std::to_string(ns_to_seconds(now_ns_)) + " s");
    }
    std::vector<double> volumes(valves_.size(), 0.0);
    const double from_s = ns_to_seconds(now_ns_);
    const double to_s = ns_to_seconds(to_ns);
    for (std::size_t n = 0; n < valves_.size(); ++n) {
        volumes[n] = integrate(valves_[n], static_cast<int>(n), from_s, to_s);
        valves_[n].delivered_l += volumes[n];
    }
    now_ns_ = to_ns;
    return volumes;
}

double PwmNozzleValves::opening(int nozzle) const { return valve(nozzle).opening; }
double PwmNozzleValves::active_duty_pct(int nozzle) const { return valve(nozzle).active_duty_pct; }
double PwmNozzleValves::delivered_l(int nozzle) const { return valve(nozzle).delivered_l; }

double PwmNozzleValves::flow_ml_min(int nozzle) const {
    const Valve& v = valve(nozzle);
    return v.opening * v.flow_scale_ml_min;
}

}  // namespace rig::emulators
