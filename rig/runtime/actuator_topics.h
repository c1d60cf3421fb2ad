#pragma once
// The board's outputs (io::ActuatorCommands) onto the three actuator topics,
// each published only when it changed (and all three the first time). Used by
// whatever drives the plant's actuators: the controller on DDS
// (controller/reference_controller.h) and the board-I/O wire adapter
// (rig/wire/wire_adapters.h).
#include <memory>
#include <optional>

#include "rig/runtime/dds_context.h"
#include "rig/runtime/io_image.h"

namespace rig {

class ActuatorTopicsWriter {
public:
    // Creates the writers: actuator/ball_valve/relays, actuator/section_valves/open,
    // actuator/unloading_valve/open.
    explicit ActuatorTopicsWriter(DdsContext& dds);
    void publish_changes(const io::ActuatorCommands& commands);

private:
    std::unique_ptr<Writer<msg::BallValveRelays>> relays_writer_;
    std::unique_ptr<Writer<msg::SectionValves>> sections_writer_;
    std::unique_ptr<Writer<msg::UnloadingValve>> unloading_writer_;
    std::optional<io::ActuatorCommands> published_;
};

}  // namespace rig
