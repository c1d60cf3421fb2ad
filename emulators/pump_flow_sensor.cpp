#include "emulators/pump_flow_sensor.h"

#include <algorithm>
#include <stdexcept>

#include "idl/topics.h"
#include "rig/runtime/io_image.h"

namespace rig::emulators {

PumpFlowSensor::PumpFlowSensor(const SprayCircuit& circuit, PumpFlowSensorParams params)
    : circuit_(circuit), params_(params), noise_(params.seed, "pump_flow_sensor"),
      period_ns_(seconds_to_ns(1.0 / params.rate_hz)) {
    if (!(params.full_scale_m3_h > 0.0) || !(params.rate_hz > 0.0) || !(params.noise_mv >= 0.0)) {
        throw std::invalid_argument("pump flow sensor: full_scale_m3_h and rate_hz must be > 0, noise_mv >= 0");
    }
}

void PumpFlowSensor::configure(DdsContext& dds) {
    voltage_writer_ = std::make_unique<Writer<msg::AnalogInput>>(dds, topics::kPumpFlowSensor);
}

double PumpFlowSensor::voltage_for(double pump_flow_l_min) const {
    const double full_scale_l_min = params_.full_scale_m3_h * 1000.0 / 60.0;
    const double current_ma = std::clamp(4.0 + 16.0 * pump_flow_l_min / full_scale_l_min + params_.offset_ma, 4.0, 20.0);
    return (current_ma - 4.0) / 16.0 * io::kAdcReferenceV;
}

TimeNs PumpFlowSensor::step(TimeNs now_ns) {
    circuit_.require_advanced_to(now_ns, name_);
    const double noisy_v = voltage_for(circuit_.pump_flow_l_min()) + noise_.gaussian() * params_.noise_mv / 1000.0;
    msg::AnalogInput sample;
    sample.voltage_v(std::clamp(noisy_v, 0.0, io::kAdcReferenceV));
    voltage_writer_->publish(sample);
    return next_period_boundary(now_ns, period_ns_);
}

}  // namespace rig::emulators
