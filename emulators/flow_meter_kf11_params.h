#pragma once
// The KF11-P10 flow meter's parameters (emulators/flow_meter_kf11.h), apart from
// the node so that case files can take their defaults without DDS.
#include "rig/papers/seed000.h"

namespace rig::emulators {

struct Kf11Params {
    double pulses_per_l = papers::seed000::kFlowMeterPulsesPerLitre;
    double k_factor_error_pct = 0.0;
    double min_flow_m3_h = 0.27;   // the range's top, 14.14 m^3/h (236 L/min), is far above the pump's 81 L/min
    double rate_hz = 100.0;
};

}  // namespace rig::emulators
