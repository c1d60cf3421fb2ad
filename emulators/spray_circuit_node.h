#pragma once
// The spray circuit as a rig node: it takes the controller's actuator topics
// (ball-valve relays, section valves, unloading valve) and applies them to the
// plant at the instant they were published, and publishes truth/hydraulics at a
// fixed rate for the trace and the harness's flow metrics. A section-valve
// command for a section the boom does not have ends the run
// (malformed_command, emulators/malformed_command.h).
//
// Subscriptions: actuator/ball_valve/relays, actuator/section_valves/open,
//                actuator/unloading_valve/open
// Publications:  truth/hydraulics
#include <memory>
#include <string>

#include "emulators/spray_circuit.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/node.h"

namespace rig::emulators {

class SprayCircuitNode final : public Node {
public:
    SprayCircuitNode(SprayCircuit& circuit, double truth_rate_hz);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;
    bool has_unread_input() const override;

private:
    std::string name_ = "spray_circuit";
    SprayCircuit& circuit_;
    TimeNs truth_period_ns_;
    TimeNs next_truth_ns_ = 0;
    // --- subscriptions
    std::unique_ptr<Reader<msg::BallValveRelays>> relays_reader_;
    std::unique_ptr<Reader<msg::SectionValves>> sections_reader_;
    std::unique_ptr<Reader<msg::UnloadingValve>> unloading_reader_;
    // --- publications
    std::unique_ptr<Writer<msg::HydraulicsTruth>> truth_writer_;
};

}  // namespace rig::emulators
