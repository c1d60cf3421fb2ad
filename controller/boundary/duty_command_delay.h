#pragma once
// What the node sends out of the duties the logic decides: a new command
// whenever the duties change (and once at the start), each going out
// delay_ns after it was decided. The reference controller's delay is 0 (a
// command goes out in the step that decided it); the TEST-ONLY fault
// BoundaryControllerFaults::command_delay_s makes it a controller that acts
// late by a fixed time, e.g. an output task fed through a queue. Case time
// only: the node asks to be stepped again when the next command is due.
#include <deque>
#include <optional>
#include <vector>

#include "rig/runtime/clock.h"

namespace rig::controller::boundary {

class DutyCommandDelay {
public:
    // Throws std::invalid_argument for a negative delay.
    explicit DutyCommandDelay(TimeNs delay_ns);

    // The duties the logic holds at now_ns (non-decreasing): queued when they
    // differ from the last decided ones, or are the first.
    void decide(const std::vector<double>& duty_pct, TimeNs now_ns);
    // The queued commands due at or before now_ns, oldest first, taken out.
    std::vector<std::vector<double>> take_due(TimeNs now_ns);
    // When the oldest queued command is due; kNever when none is queued.
    TimeNs next_due_ns() const;

private:
    struct Queued {
        TimeNs due_ns = 0;
        std::vector<double> duty_pct;
    };
    TimeNs delay_ns_ = 0;
    std::deque<Queued> queued_;
    std::optional<std::vector<double>> last_decided_;
};

}  // namespace rig::controller::boundary
