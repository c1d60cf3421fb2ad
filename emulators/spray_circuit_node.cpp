#include "emulators/spray_circuit_node.h"

#include "emulators/malformed_command.h"
#include "idl/topics.h"

namespace rig::emulators {

SprayCircuitNode::SprayCircuitNode(SprayCircuit& circuit, double truth_rate_hz)
    : circuit_(circuit), truth_period_ns_(seconds_to_ns(1.0 / truth_rate_hz)) {}

void SprayCircuitNode::configure(DdsContext& dds) {
    relays_reader_ = std::make_unique<Reader<msg::BallValveRelays>>(dds, topics::kBallValveRelays);
    sections_reader_ = std::make_unique<Reader<msg::SectionValves>>(dds, topics::kSectionValves);
    unloading_reader_ = std::make_unique<Reader<msg::UnloadingValve>>(dds, topics::kUnloadingValve);
    truth_writer_ = std::make_unique<Writer<msg::HydraulicsTruth>>(dds, topics::kHydraulicsTruth);
}

bool SprayCircuitNode::has_unread_input() const {
    return relays_reader_->has_unread() || sections_reader_->has_unread() || unloading_reader_->has_unread();
}

TimeNs SprayCircuitNode::step(TimeNs now_ns) {
    // Everything up to now happened under the previous commands: the master
    // advanced the circuit to now before any node stepped; the commands taken
    // here act from now on.
    circuit_.require_advanced_to(now_ns, name_);
    for (const auto& relays : relays_reader_->take_all()) {
        using Drive = BallValve::Drive;
        circuit_.set_valve_drive(relays.forward() && relays.reverse() ? Drive::both
                                 : relays.forward()                   ? Drive::forward
                                 : relays.reverse()                   ? Drive::reverse
                                                                      : Drive::off);
    }
    for (const auto& sections : sections_reader_->take_all()) {
        // A section the boom does not have is no command the circuit can carry out: the run ends on it.
        if (const auto problem = section_valves_problem(sections, circuit_.section_count())) {
            throw malformed_command(topics::kSectionValves, now_ns, *problem);
        }
        circuit_.set_sections_commanded(sections.open_mask());
    }
    for (const auto& unloading : unloading_reader_->take_all()) circuit_.set_unloading_open(unloading.open());
    if (now_ns >= next_truth_ns_) {
        truth_writer_->publish(circuit_.truth());
        next_truth_ns_ = next_period_boundary(now_ns, truth_period_ns_);
    }
    return next_truth_ns_;
}

}  // namespace rig::emulators
