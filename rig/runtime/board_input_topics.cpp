#include "rig/runtime/board_input_topics.h"

#include "idl/topics.h"

namespace rig {

BoardInputReaders::BoardInputReaders(DdsContext& dds)
    : wheel_encoder(dds, topics::kWheelEncoder),
      main_flow_meter(dds, topics::kMainFlowMeter),
      pump_flow_sensor(dds, topics::kPumpFlowSensor),
      boom_height_sensor(dds, topics::kBoomHeightSensor),
      breakpoint_button(dds, topics::kBreakpointButton),
      spray_switch(dds, topics::kSpraySwitch) {}

bool BoardInputReaders::has_unread() const {
    return wheel_encoder.has_unread() || main_flow_meter.has_unread() || pump_flow_sensor.has_unread() ||
           boom_height_sensor.has_unread() || breakpoint_button.has_unread() || spray_switch.has_unread();
}

}  // namespace rig
