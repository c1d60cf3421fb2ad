#include "emulators/panel_switch.h"

#include <algorithm>

namespace rig::emulators {

PanelSwitch::PanelSwitch(std::string node_name, std::string topic, std::vector<SwitchClosure> closures)
    : name_(std::move(node_name)), topic_(std::move(topic)) {
    // Overlapping closures are one longer closure (a finger held down), not a
    // release in the middle of the second one.
    std::sort(closures.begin(), closures.end(),
              [](const SwitchClosure& a, const SwitchClosure& b) { return a.at_s < b.at_s; });
    std::vector<std::pair<TimeNs, TimeNs>> merged;
    for (const SwitchClosure& closure : closures) {
        const TimeNs from = seconds_to_ns(closure.at_s);
        const TimeNs to = seconds_to_ns(closure.at_s + closure.hold_s);
        if (!merged.empty() && from <= merged.back().second) {
            merged.back().second = std::max(merged.back().second, to);
        } else {
            merged.emplace_back(from, to);
        }
    }
    edges_.push_back(Edge{0, false});
    for (const auto& [from, to] : merged) {
        edges_.push_back(Edge{from, true});
        edges_.push_back(Edge{to, false});
    }
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
