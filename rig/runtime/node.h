#pragma once
// A node: one simulated device, the plant, or the controller under test.
// Lifecycle (ros2_control / PX4 style, driven by rig/runtime/lockstep.h or a real-time
// loop): configure (create endpoints, validate parameters) -> activate -> step ...
// -> shutdown. Nodes are shut down in the reverse order of configuration.
#include <string>

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
