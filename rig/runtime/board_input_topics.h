#pragma once
// The six device topics a controller board reads besides the GNSS's NMEA: wheel
// encoder, main flow meter, pump-outlet sensor, boom-height sensor, breakpoint
// button, spray switch. The input-side counterpart of ActuatorTopicsWriter
// (rig/runtime/actuator_topics.h), used by the controller on DDS
// (controller/reference_controller.h) and the board-I/O wire adapter
// (rig/wire/wire_adapters.h). Each caller takes them in its own fixed order.
#include "rig/runtime/dds_context.h"

namespace rig {

struct BoardInputReaders {
    explicit BoardInputReaders(DdsContext& dds);
    bool has_unread() const;

    // Topic names: idl/topics.h (kWheelEncoder ... kSpraySwitch).
    Reader<msg::EncoderCount> wheel_encoder;
    Reader<msg::FlowMeterCount> main_flow_meter;
    Reader<msg::AnalogInput> pump_flow_sensor;
    Reader<msg::AnalogInput> boom_height_sensor;
    Reader<msg::SwitchLevel> breakpoint_button;
    Reader<msg::SwitchLevel> spray_switch;
};

}  // namespace rig
