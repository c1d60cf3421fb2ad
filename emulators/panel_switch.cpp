#include "emulators/panel_switch.h"

#include <algorithm>

namespace rig::emulators {

PanelSwitch::PanelSwitch(std::string node_name, std::string topic, std::vector<SwitchClosure> closures)
    : name_(std::move(node_name)), topic_(std::move(topic)) {
    edges_.push_back(Edge{0, false});
    for (const SwitchClosure& closure : closures) {
        edges_.push_back(Edge{seconds_to_ns(closure.at_s), true});
        edges_.push_back(Edge{seconds_to_ns(closure.at_s + closure.hold_s), false});
    }
    std::stable_sort(edges_.begin(), edges_.end(), [](const Edge& a, const Edge& b) { return a.at_ns < b.at_ns; });
}

void PanelSwitch::configure(DdsContext& dds) { level_writer_ = std::make_unique<Writer<msg::SwitchLevel>>(dds, topic_); }

bool PanelSwitch::closed_at(TimeNs t) const {
    bool closed = false;
    for (const Edge& edge : edges_) {
        if (edge.at_ns > t) break;
        closed = edge.closed;
    }
    return closed;
}

TimeNs PanelSwitch::step(TimeNs now_ns) {
    while (next_edge_ < edges_.size() && edges_[next_edge_].at_ns <= now_ns) {
        msg::SwitchLevel level;
        level.closed(edges_[next_edge_].closed);
        level_writer_->publish(level);
        ++next_edge_;
    }
    return next_edge_ < edges_.size() ? edges_[next_edge_].at_ns : kNever;
}

}  // namespace rig::emulators
