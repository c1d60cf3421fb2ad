#pragma once
// Seed 000's numbers that the plant, the controller and the judge all take:
// the breakpoint-continuation sprayer of Li et al. 2023 (Agriculture 13, 2203).
// One home each, with its unit and where it comes from; none of the three
// owns them (the plant models the device, the controller believes it, the
// judge reads the device's wire the paper's way). A number only one of them
// uses lives with that one (emulators/*.h, controller/controller_config.h).
#include <cstdint>

namespace rig::papers::seed000 {

// KF11-P10 main-pipeline flow meter: pulses per litre, the k of Eq. 3
// (Q = 60 w / (k t2) L/min). Sec. 2.2.2.
inline constexpr double kFlowMeterPulsesPerLitre = 90.0;

// ZSP5208 land-wheel encoder: pulses per revolution (Eq. 5). Sec. 2.2.1.
inline constexpr std::uint32_t kEncoderPulsesPerRev = 1000;
// The land wheel's diameter, m (Eq. 5). Not given in the paper: assumed.
inline constexpr double kLandWheelDiameterM = 1.0;

// WL-LWGA-20 pump-outlet turbine: the top of its 0.8-8 m^3/h range, Q_F of
// Eq. 8 (4-20 mA over the converter's span). Sec. 2.2.2.
inline constexpr double kPumpSensorFullScaleM3H = 8.0;

// Pull-wire boom-height sensor: the linkage rise h at full span, m (Eq. 6
// uses h). The paper gives no range: assumed.
inline constexpr double kBoomHeightRangeM = 1.0;

// Eq. 6, antenna to nozzle line: L4 = L1 + cos(atan(h / L2)) L2 + L3 (Fig. 5),
// m. With these values L4 is the paper's 1.63 m at h = 0.5 m.
inline constexpr double kL1M = 0.50;              // antenna to the four-bar linkage
inline constexpr double kL2M = 0.80;              // the linkage's length
inline constexpr double kL3M = 0.45;              // linkage to the nozzle line
inline constexpr double kLinkageRiseM = 0.50;     // h, the linkage's rise

}  // namespace rig::papers::seed000
