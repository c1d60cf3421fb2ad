#include "controller/flow_equations.h"

#include <algorithm>
#include <limits>

namespace rig::controller {

double main_flow_l_min_from_pulses(std::uint32_t pulses, double pulses_per_l, double interval_s) {
    if (!(interval_s > 0.0) || !(pulses_per_l > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    return 60.0 * static_cast<double>(pulses) / (pulses_per_l * interval_s);
}

double pump_flow_l_min_from_voltage(double voltage_v, double span_v, double full_scale_m3_h) {
    if (!(span_v > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    return 50.0 / 3.0 * std::clamp(voltage_v / span_v, 0.0, 1.0) * full_scale_m3_h;
}

double linkage_rise_m_from_voltage(double voltage_v, double span_v, double range_m) {
    if (!(span_v > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    return std::clamp(voltage_v / span_v, 0.0, 1.0) * range_m;
}

}  // namespace rig::controller
