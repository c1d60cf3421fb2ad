#pragma once
// The flow-side equations of seed 000, as the board's firmware evaluates them
// from wire-level inputs. Pure functions; tests check them against hand-worked values.
#include <cstdint>

namespace rig::controller {

// Eq. 3: Q1 = 60 w / (k1 t2), main-pipeline flow in L/min from w pulses of the
// KF11 meter (k1 = 90 pulses/L) counted over t2 seconds.
double main_flow_l_min_from_pulses(std::uint32_t pulses, double pulses_per_l, double interval_s);

// Eq. 8: Q0 = 50 i p / (3 u k0) Q_F, the pump-outlet flow in L/min. How the rig
// reads it: the transmitter's 4-20 mA span p maps onto the converter's voltage
// span u, so the ADC voltage V over u is the fraction i p / (u k0) of the sensor's
// range Q_F (m^3/h); 50 / 3 turns m^3/h into L/min (1000 / 60). The paper's k0
// (16, the span in mA here) and p cancel for a module that maps 4-20 mA onto
// 0-u, leaving Q0 = (50 / 3) (V / u) Q_F.
double pump_flow_l_min_from_voltage(double voltage_v, double span_v, double full_scale_m3_h);

// The pull-wire boom-height sensor: linkage rise h in metres from its voltage.
double linkage_rise_m_from_voltage(double voltage_v, double span_v, double range_m);

}  // namespace rig::controller
