#pragma once
// The land-wheel encoder's parameters (emulators/wheel_encoder.h), apart from the node so
// that case files take their defaults from here without DDS.
#include <cstdint>

#include "rig/papers/seed000.h"

namespace rig::emulators {

struct WheelEncoderParams {
    std::uint32_t pulses_per_rev = papers::seed000::kEncoderPulsesPerRev;
    double wheel_diameter_m = papers::seed000::kLandWheelDiameterM;
    double rate_hz = 100.0;
};

}  // namespace rig::emulators
