#include "rig/runtime/actuator_topics.h"

#include "idl/topics.h"

namespace rig {

ActuatorTopicsWriter::ActuatorTopicsWriter(DdsContext& dds)
    : relays_writer_(std::make_unique<Writer<msg::BallValveRelays>>(dds, topics::kBallValveRelays)),
      sections_writer_(std::make_unique<Writer<msg::SectionValves>>(dds, topics::kSectionValves)),
      unloading_writer_(std::make_unique<Writer<msg::UnloadingValve>>(dds, topics::kUnloadingValve)) {}

void ActuatorTopicsWriter::publish_changes(const io::ActuatorCommands& commands) {
    const bool first = !published_;
    if (first || commands.ball_valve_forward != published_->ball_valve_forward ||
        commands.ball_valve_reverse != published_->ball_valve_reverse) {
        msg::BallValveRelays relays;
        relays.forward(commands.ball_valve_forward);
        relays.reverse(commands.ball_valve_reverse);
        relays_writer_->publish(relays);
    }
    if (first || commands.section_valves_open != published_->section_valves_open) {
        msg::SectionValves sections;
        sections.open_mask(commands.section_valves_open);
        sections_writer_->publish(sections);
    }
    if (first || commands.unloading_valve_open != published_->unloading_valve_open) {
        msg::UnloadingValve unloading;
        unloading.open(commands.unloading_valve_open);
        unloading_writer_->publish(unloading);
    }
    published_ = commands;
}

}  // namespace rig
