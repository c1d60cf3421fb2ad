#pragma once
// A node: one simulated device, the plant, or the controller under test.
// Lifecycle (ros2_control / PX4 style, driven by rig/runtime/lockstep.h or a real-time
// loop): configure (create endpoints, validate parameters) -> activate -> step ...
// -> shutdown. Nodes are shut down in the reverse order of configuration.
#include <string>
#include <vector>

#include "rig/runtime/clock.h"

namespace rig {

class DdsContext;

class Node {
public:
    virtual ~Node() = default;

    virtual const std::string& name() const = 0;
    // Create readers and writers; throw std::runtime_error naming what is wrong.
    virtual void configure(DdsContext& dds) = 0;
    // Called once at time 0, after every endpoint in the run is matched.
    virtual void activate(TimeNs /*now_ns*/) {}
    // Do all work due at `now_ns`: take unread inputs, update, publish.
    // Returns the next time the node must run even without input (kNever if it
    // only reacts to input). Must not block or read the wall clock.
    virtual TimeNs step(TimeNs now_ns) = 0;
    // True when a reader holds samples not yet taken (the node is due at once).
    virtual bool has_unread_input() const { return false; }
    // How a real-time loop (rig/runtime/realtime.h) counts this node's lateness.
    // false, most nodes: a step emits what is due, so each timed wake is one
    // emission, late by when its step began. true: the node's emission waits on
    // work of its own that runs on another thread (a camera's frame still
    // rendering), and its step never waits for that work: a step that waited
    // would hold up every node after it in the loop. Such a node emits when
    // its work is done and reports each emission's deadline through
    // take_emitted_deadlines(); its has_unread_input() turns true when the work
    // is done, and the worker wakes the loop (DdsContext::notify_data_arrived).
    virtual bool reports_own_emissions() const { return false; }
    // With reports_own_emissions(): the deadlines (case time) of the emissions
    // its steps made since the last call, oldest first. The loop counts each
    // late by when the step that made it began, against this node alone.
    virtual std::vector<TimeNs> take_emitted_deadlines() { return {}; }
    virtual void shutdown() {}
};

// The plant's state that evolves under the actuators (the spray circuit), which
// the device nodes sample. The master advances it to each instant once, before
// any local node steps at that instant; nodes only read it. So what a sensor
// reports at t is the plant at t whichever node ran first, and no device can
// move the plant's time (ros2_control's split: the framework moves the state,
// components read and write it).
class TruthModel {
public:
    virtual ~TruthModel() = default;
    // Integrate up to `now_ns`; called with non-decreasing instants.
    virtual void advance_to(TimeNs now_ns) = 0;
};

}  // namespace rig
