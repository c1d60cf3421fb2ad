#pragma once
// The main-pipeline flow as the board measures it: Eq. 3 on the KF11's pulses,
// with w and t2 taken edge to edge inside a sliding window: w = the pulses
// between the first and the last pulse edge seen in the window, t2 = the time
// between those two edges. Counting whole pulses over a fixed window would
// quantise the flow to 60 / (90 t2) L/min (3.3 L/min at t2 = 0.2 s, more than the
// 3 % the controller must hold at 20 L/min).
//
// Edge times come from the input-capture timer when the wire provides it (the
// DDS device topic does: a 1 MHz, 32-bit capture value); otherwise the instant a
// new count was read stands in for the edge, which costs the read period in
// resolution.
#include <cstdint>
#include <deque>
#include <optional>

#include "rig/runtime/clock.h"

namespace rig::controller {

class FlowRateMeter {
public:
    FlowRateMeter(double pulses_per_l, double window_s);

    // A cumulative count (32-bit, wraps) read at now_ns, with the capture timer's
    // value (1 MHz, 32-bit, wraps) at the last edge if the wire carries it.
    void add_count(std::uint32_t count_pulses, std::optional<std::uint32_t> last_edge_capture_us, TimeNs now_ns);
    // Forget history (the pipeline was closed: no flow to measure).
    void reset();
    // Eq. 3 over the window ending at the latest sample; nullopt until two edges
    // lie in the window (no flow, or too little to measure yet).
    std::optional<double> flow_l_min() const;
    // When (read time) the first pulse after the last reset() arrived.
    std::optional<TimeNs> first_pulse_ns() const { return first_pulse_ns_; }

private:
    struct Edge {
        TimeNs read_ns;         // when it was seen (prunes the window)
        std::int64_t edge_ns;   // when it happened, on the capture timer's (or the read) time line
        std::uint64_t count;    // unwrapped
    };
    double pulses_per_l_;
    TimeNs window_ns_;
    std::deque<Edge> edges_;
    std::optional<std::uint32_t> last_count_;
    std::optional<std::uint32_t> last_capture_us_;
    std::uint64_t unwrapped_count_ = 0;
    std::int64_t unwrapped_capture_us_ = 0;
    std::optional<TimeNs> first_pulse_ns_;
};

}  // namespace rig::controller
