#include "controller/flow_rate_meter.h"

#include "controller/flow_equations.h"

namespace rig::controller {

FlowRateMeter::FlowRateMeter(double pulses_per_l, double window_s)
    : pulses_per_l_(pulses_per_l), window_ns_(seconds_to_ns(window_s)) {}

void FlowRateMeter::reset() {
    edges_.clear();
    first_pulse_ns_.reset();
}

void FlowRateMeter::add_count(std::uint32_t count_pulses, std::optional<std::uint32_t> last_edge_capture_us,
                              TimeNs now_ns) {
    // Capture times and read times are two time lines: a wire that switches between
    // them starts the measurement over rather than mixing them.
    if (last_count_ && last_edge_capture_us.has_value() != last_capture_us_.has_value()) {
        edges_.clear();
        last_capture_us_.reset();
    }
    if (last_edge_capture_us) {
        // Unsigned differences survive the 32-bit wrap of the timer, as of the counter.
        if (last_capture_us_) unwrapped_capture_us_ += static_cast<std::uint32_t>(*last_edge_capture_us - *last_capture_us_);
        last_capture_us_ = last_edge_capture_us;
    }
    if (last_count_ && count_pulses != *last_count_) {
        unwrapped_count_ += static_cast<std::uint32_t>(count_pulses - *last_count_);
        const std::int64_t edge_ns = last_edge_capture_us ? unwrapped_capture_us_ * 1000 : now_ns;
        edges_.push_back(Edge{now_ns, edge_ns, unwrapped_count_});
        if (!first_pulse_ns_) first_pulse_ns_ = now_ns;
    }
    last_count_ = count_pulses;
    while (!edges_.empty() && edges_.front().read_ns < now_ns - window_ns_) edges_.pop_front();
}

std::optional<double> FlowRateMeter::flow_l_min() const {
    if (edges_.size() < 2) return std::nullopt;
    const Edge& first = edges_.front();
    const Edge& last = edges_.back();
    if (last.edge_ns <= first.edge_ns) return std::nullopt;
    return main_flow_l_min_from_pulses(static_cast<std::uint32_t>(last.count - first.count), pulses_per_l_,
                                       static_cast<double>(last.edge_ns - first.edge_ns) * 1e-9);
}

}  // namespace rig::controller
