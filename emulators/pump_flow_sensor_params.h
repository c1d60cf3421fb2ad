#pragma once
// The pump-outlet flow sensor's parameters (emulators/pump_flow_sensor.h), apart from the node so
// that case files take their defaults from here without DDS.
#include <cstdint>

#include "rig/papers/seed000.h"

namespace rig::emulators {

struct PumpFlowSensorParams {
    double full_scale_m3_h = papers::seed000::kPumpSensorFullScaleM3H;   // Q_F of Eq. 8 (133 L/min)
    double noise_mv = 2.0;
    double offset_ma = 0.0;
    double rate_hz = 20.0;
    std::uint64_t seed = 1;
};

}  // namespace rig::emulators
