#include "emulators/breakpoint_button.h"

#include <algorithm>

#include "idl/topics.h"

namespace rig::emulators {

BreakpointButton::BreakpointButton(std::vector<ButtonPress> presses) {
    edges_.push_back(Edge{0, false});
    for (const ButtonPress& press : presses) {
        edges_.push_back(Edge{seconds_to_ns(press.at_s), true});
        edges_.push_back(Edge{seconds_to_ns(press.at_s + press.hold_s), false});
    }
    std::stable_sort(edges_.begin(), edges_.end(), [](const Edge& a, const Edge& b) { return a.at_ns < b.at_ns; });
}

void BreakpointButton::configure(DdsContext& dds) {
    level_writer_ = std::make_unique<Writer<msg::ButtonLevel>>(dds, topics::kBreakpointButton);
}

TimeNs BreakpointButton::step(TimeNs now_ns) {
    while (next_edge_ < edges_.size() && edges_[next_edge_].at_ns <= now_ns) {
        msg::ButtonLevel level;
        level.pressed(edges_[next_edge_].pressed);
        level_writer_->publish(level);
        ++next_edge_;
    }
    return next_edge_ < edges_.size() ? edges_[next_edge_].at_ns : kNever;
}

}  // namespace rig::emulators
