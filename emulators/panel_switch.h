#pragma once
// A contact on the controller board's panel, operated by a person at scripted
// times: the breakpoint button (seed 000 sec. 2.1: "buttons were provided for
// breakpoint input") and the main spray switch. The wire carries the line level.
#include <memory>
#include <string>
#include <vector>

#include "rig/runtime/clock.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/node.h"

namespace rig::emulators {

// Closed (pressed / on) from at_s for hold_s.
struct SwitchClosure {
    double at_s = 0.0;
    double hold_s = 0.2;
};

class PanelSwitch final : public Node {
public:
    // `topic` is one of topics::kBreakpointButton, topics::kSpraySwitch. The
    // level at t = 0 (open) is published too, so the board starts from a known state.
    PanelSwitch(std::string node_name, std::string topic, std::vector<SwitchClosure> closures);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;
    // The level at t (for tests and the wired adapters).
    bool closed_at(TimeNs t) const;

private:
    struct Edge {
        TimeNs at_ns;
        bool closed;
    };
    std::string name_;
    std::string topic_;
    std::vector<Edge> edges_;  // sorted; index 0 is the open level at t = 0
    std::size_t next_edge_ = 0;
    std::unique_ptr<Writer<msg::SwitchLevel>> level_writer_;
};

}  // namespace rig::emulators
