#pragma once
// The boom-height pull-wire sensor's parameters (emulators/boom_height_sensor.h), apart from the node so
// that case files take their defaults from here without DDS.
#include "rig/papers/seed000.h"

namespace rig::emulators {

struct BoomHeightSensorParams {
    double range_m = papers::seed000::kBoomHeightRangeM;  // h at 3.3 V
    double rate_hz = 10.0;
};

}  // namespace rig::emulators
