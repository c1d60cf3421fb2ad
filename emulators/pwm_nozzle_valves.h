#pragma once
// The six nozzle valves of seed 001 (Zwqd 2L030-08 solenoid valves, 24 V,
// response 10-20 ms, Table 1) driven by PWM at 9 Hz (Sec. 3.2.1), each feeding
// one Agrotop 110 deg flat-fan nozzle at a constant 0.6 MPa. What the plant
// needs from them: how much each nozzle delivers, pulse by pulse.
//
// Model, per nozzle:
//   - PWM periods start at phase + k / frequency_hz (the phase of the
//     controller's PWM against the run's clock: given, or drawn from the seed,
//     stream "pwm_valves.phase", so where a switch-off falls between PWM edges
//     varies run to run as on a real machine). In a period with duty
//     d the drive is on for the first d / frequency_hz seconds, off for the rest
//     (d = 0: always off, d = 100 %: always on).
//   - A duty command takes effect at the start of the next period (as a PWM
//     peripheral's shadow register or a software PWM loop that reads the duty
//     once per cycle does; assumed), or at once with latch_at_period_start false.
//   - The valve's opening x (0 closed .. 1 open) follows the drive at a constant
//     rate, taking response_s to travel fully (the paper's 10-20 ms "response
//     time" read as the stroke time; the middle, 15 ms, by default).
//   - Flow is x times q_open(d), the flow through the fully open valve in a
//     period of duty d. q_open is chosen so that the mean over a steady period
//     equals Table 3 for that nozzle and duty (linear between the measured
//     duties): Table 3 is the plant's input, and at 30 % duty it is about 65 %
//     of full flow, which the valve's open time alone (30 %) cannot give, so the
//     open-valve flow itself depends on the duty (pressure recovers between
//     short pulses). Below the table's lowest duty q_open stays at its value
//     there (the mean then falls with the open time).
//   - Constant pressure: the nozzles do not interact.
// Integration is exact (piecewise linear opening) between events: PWM edges,
// period starts and (unlatched) command times.
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "emulators/field2d/nozzle_flow_table.h"
#include "rig/runtime/clock.h"
#include "rig/papers/seed001.h"

namespace rig::emulators {

struct PwmValveParams {
    double frequency_hz = papers::seed001::kPwmFrequencyHz;  // (0, 1000]
    double response_s = 0.015;          // [0, half a period); Table 1: 10-20 ms
    std::optional<double> pwm_phase_s;  // [0, period); unset: drawn from the seed
    bool latch_at_period_start = true;  // assumed, see above
    std::uint64_t seed = 1;
};

class PwmNozzleValves {
public:
    // Throws std::invalid_argument naming the parameter (frequency, response
    // not below half a period, phase outside a period) or, for the table, a
    // nozzle without a 100 % point.
    PwmNozzleValves(PwmValveParams params, field2d::NozzleFlowTable table);

    int nozzle_count() const { return table_.nozzle_count(); }
    // The controller's duty for `nozzle` from `at_ns` on. Throws
    // std::invalid_argument for a duty outside [0, 100] % or a bad nozzle, and
    // std::logic_error for a time before what is already integrated or before
    // the nozzle's previous command.
    void command(int nozzle, double duty_pct, TimeNs at_ns);
    // Integrates every valve up to `to_ns` and returns the volume each nozzle
    // delivered since the previous call, in litres (index = nozzle). Throws
    // std::logic_error when to_ns is before now_ns().
    std::vector<double> advance(TimeNs to_ns);
    TimeNs now_ns() const { return now_ns_; }

    // State at now_ns().
    double opening(int nozzle) const;              // 0..1
    double active_duty_pct(int nozzle) const;      // duty of the PWM period running now
    double flow_ml_min(int nozzle) const;          // instantaneous
    double delivered_l(int nozzle) const;          // since t = 0
    // The model's curves: flow through the open valve in a period of duty d,
    // and the mean over a steady period (= Table 3 inside its range).
    double open_flow_ml_min(int nozzle, double duty_pct) const;
    double mean_flow_ml_min(int nozzle, double duty_pct) const;

    double period_s() const { return period_s_; }
    double pwm_phase_s() const { return phase_s_; }
    const PwmValveParams& params() const { return params_; }
    const field2d::NozzleFlowTable& table() const { return table_; }

private:
    struct Command {
        double at_s = 0.0;
        double duty_pct = 0.0;
    };
    struct Valve {
        double opening = 0.0;
        double active_duty_pct = 0.0;
        std::int64_t period = 0;   // index of the period whose start was last passed
        std::deque<Command> pending;
        double last_command_s = 0.0;
        double delivered_l = 0.0;
        double flow_scale_ml_min = 0.0;  // q_open of the last non-zero duty
    };
    // Open fraction integrated over one steady period of duty d (seconds).
    double open_time_per_period_s(double duty_pct) const;
    double period_start_s(std::int64_t k) const { return phase_s_ + static_cast<double>(k) * period_s_; }
    // Integrates one valve over [from_s, to_s); returns litres.
    double integrate(Valve& valve, int nozzle, double from_s, double to_s) const;
    const Valve& valve(int nozzle) const;

    PwmValveParams params_;
    field2d::NozzleFlowTable table_;
    double period_s_ = 0.0;
    double phase_s_ = 0.0;
    TimeNs now_ns_ = 0;
    std::vector<Valve> valves_;
};

}  // namespace rig::emulators
