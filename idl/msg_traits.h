#pragma once
// Maps each generated message type to its fastddsgen PubSubType, so rig::Writer<T>
// and rig::Reader<T> can register types without the caller naming them twice.
#include "actuatorPubSubTypes.h"
#include "clockPubSubTypes.h"
#include "controllerPubSubTypes.h"
#include "devicePubSubTypes.h"
#include "truthPubSubTypes.h"

namespace rig {

template <class Msg>
struct MsgTraits;  // undefined for types not declared in idl/

#define RIG_DECLARE_MSG(Type)                  \
    template <>                                \
    struct MsgTraits<msg::Type> {              \
        using PubSubType = msg::Type##PubSubType; \
    };

RIG_DECLARE_MSG(ClockTick)
RIG_DECLARE_MSG(ClockAck)
RIG_DECLARE_MSG(NmeaSentence)
RIG_DECLARE_MSG(EncoderCount)
RIG_DECLARE_MSG(FlowMeterCount)
RIG_DECLARE_MSG(AnalogInput)
RIG_DECLARE_MSG(SwitchLevel)
RIG_DECLARE_MSG(BallValveRelays)
RIG_DECLARE_MSG(SectionValves)
RIG_DECLARE_MSG(UnloadingValve)
RIG_DECLARE_MSG(BreakpointEvent)
RIG_DECLARE_MSG(ControllerStatus)
RIG_DECLARE_MSG(VehicleTruth)
RIG_DECLARE_MSG(HydraulicsTruth)
// Seed 001
RIG_DECLARE_MSG(SerialLine)
RIG_DECLARE_MSG(NozzlePwm)
RIG_DECLARE_MSG(Vehicle2dTruth)
RIG_DECLARE_MSG(NozzlesTruth)
RIG_DECLARE_MSG(CameraFrame)
RIG_DECLARE_MSG(VisionReport)
RIG_DECLARE_MSG(CameraViewTruth)

#undef RIG_DECLARE_MSG

}  // namespace rig
