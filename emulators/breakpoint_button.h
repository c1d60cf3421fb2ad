#pragma once
// The breakpoint button on the controller board (seed 000 sec. 2.1): pressed by
// the operator at scripted times; the wire carries the line level.
#include <memory>
#include <string>
#include <vector>

#include "rig/clock.h"
#include "rig/dds_context.h"
#include "rig/node.h"

namespace rig::emulators {

struct ButtonPress {
    double at_s = 0.0;
    double hold_s = 0.2;
};

class BreakpointButton final : public Node {
public:
    explicit BreakpointButton(std::vector<ButtonPress> presses);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;

private:
    struct Edge {
        TimeNs at_ns;
        bool pressed;
    };
    std::string name_ = "breakpoint_button";
    std::vector<Edge> edges_;  // sorted; index 0 is the released level at t = 0
    std::size_t next_edge_ = 0;
    std::unique_ptr<Writer<msg::ButtonLevel>> level_writer_;
};

}  // namespace rig::emulators
