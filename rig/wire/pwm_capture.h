#pragma once
// PWM duty and frequency per nozzle from the HID I/O board's captured edges
// (protocol version 2, report 0x03: rig/wire/hid_board_protocol.h,
// docs/hid-io-board.md "PWM edge capture"). Seed 001's controller drives six
// GPIO PWM outputs to the nozzle valve drivers at 9 Hz (Sec. 3.2.1); on the
// bench the board timestamps their edges with its 1 MHz timer and the rig turns
// them into what the DDS path carries on actuator/nozzle_pwm/duty: a duty per
// nozzle and the PWM frequency.
//
// Per input, from the edges in board time (unwrapped across the 32-bit wrap):
//   - a period is rising edge to rising edge with one falling edge between;
//     duty = high time / period, frequency = 1 / period. The reading is the
//     last complete period's (what the valve driver was last given).
//   - glitch: a high or low phase shorter than glitch_max_us (e.g. contact
//     bounce, crosstalk) is removed with both its edges before periods are
//     measured. The pulse a 9 Hz PWM at 1 % makes is 1.1 ms, well above it.
//   - missing edge: two rising (or two falling) edges in a row mean one was
//     not captured; the period around it is not measured (counted), and
//     measuring restarts at the next rising edge.
//   - steady level: no edge on an input for steady_after_us while the board's
//     report time has passed it: duty 0 % (low) or 100 % (high), frequency 0
//     (no PWM). A controller sets 0 % and 100 % this way on a GPIO PWM. The
//     first edge out of a steady level is taken at once (the valve follows the
//     line): 100 % then a falling edge reads 0 % from that edge, until a PWM's
//     first complete period says otherwise.
//   - lost edges: an edge-report sequence gap or the board's overflow flag
//     drops every partial period (counted); readings keep their last value
//     until a complete period (or a steady level) replaces them.
// Bad reports never throw here: HidBoard refuses malformed ones before.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "actuator.h"
#include "rig/wire/hid_board_protocol.h"

namespace rig {

struct PwmCaptureParams {
    // Phases shorter than this are glitches. [0, 100000] us. Assumed: 200 us,
    // a fifth of the shortest real phase (1 % of a 9 Hz period, 1.1 ms) and far
    // below what the 2L030-08 valve (10-20 ms response, Table 1) can follow.
    std::uint32_t glitch_max_us = 200;
    // No edge for this long: a steady level (0 % or 100 %). [1000, 10^7] us.
    // Assumed: 250 ms, 2.25 periods of the paper's 9 Hz.
    std::uint32_t steady_after_us = 250'000;
};

struct NozzlePwmReading {
    enum class State : std::uint8_t {
        unknown,   // nothing measured yet
        pwm,       // a complete period measured
        steady,    // no edges for steady_after_us: duty 0 or 100 %
    };
    State state = State::unknown;
    double duty_pct = 0.0;           // 0..100
    double frequency_hz = 0.0;       // 0 when steady or unknown
    std::int64_t measured_at_us = 0; // board time (unwrapped) of the edge or report that set it
};

class PwmCapture {
public:
    // Throws std::invalid_argument naming a parameter out of its bounds.
    explicit PwmCapture(PwmCaptureParams params = {});

    // One decoded edge report, in the order the board sent them.
    void on_report(const hid::EdgeReport& report);

    const std::array<NozzlePwmReading, hid::kPwmCaptureInputs>& readings() const { return readings_; }
    // The duties (%) per input and the common PWM frequency: the median over
    // inputs measuring a PWM (0 when none does), as actuator/nozzle_pwm/duty
    // carries them (one frequency for all nozzles, the controller's).
    std::vector<double> duty_pct() const;
    double frequency_hz() const;

    // What the DDS path carries on actuator/nozzle_pwm/duty (msg::NozzlePwm),
    // for the first `nozzles` inputs (1..6): a bench controller's PWM becomes
    // the same actuator state a DDS controller publishes.
    msg::NozzlePwm nozzle_pwm(int nozzles = hid::kPwmCaptureInputs) const;

    std::uint64_t reports() const { return reports_; }
    std::uint64_t reports_lost() const { return reports_lost_; }   // sequence gaps
    std::uint64_t overflows() const { return overflows_; }         // reports flagged
    std::uint64_t glitches() const { return glitches_; }           // phases removed
    std::uint64_t periods_dropped() const { return periods_dropped_; }  // missing edges, losses
    std::uint64_t periods() const { return periods_; }             // measured

private:
    struct Input {
        std::optional<std::int64_t> pending_time;  // an edge the glitch filter still holds
        bool pending_rising = false;
        std::optional<std::int64_t> last_rise;
        std::optional<std::int64_t> last_fall;      // after last_rise
        std::optional<bool> level;                  // after the last committed edge
        std::int64_t last_edge_time = 0;            // committed or pending
        bool seen_edge = false;
    };
    std::int64_t unwrap(std::uint32_t board_time_us);
    void edge(int input, std::int64_t time_us, bool rising);
    void commit(int input, std::int64_t time_us, bool rising);
    void restart_all();

    PwmCaptureParams params_;
    std::array<Input, hid::kPwmCaptureInputs> inputs_{};
    std::array<NozzlePwmReading, hid::kPwmCaptureInputs> readings_{};
    std::optional<std::uint16_t> last_sequence_;
    std::optional<std::uint32_t> last_board_time_;
    std::int64_t unwrapped_ = 0;
    std::optional<std::int64_t> first_report_time_;  // inputs without an edge are quiet since it
    std::uint64_t reports_ = 0;
    std::uint64_t reports_lost_ = 0;
    std::uint64_t overflows_ = 0;
    std::uint64_t glitches_ = 0;
    std::uint64_t periods_dropped_ = 0;
    std::uint64_t periods_ = 0;
};

}  // namespace rig
