#include "emulators/boom_height_sensor.h"

#include <algorithm>
#include <stdexcept>

#include "idl/topics.h"
#include "rig/runtime/io_image.h"

namespace rig::emulators {

BoomHeightSensor::BoomHeightSensor(const Plant& plant, BoomHeightSensorParams params)
    : plant_(plant), params_(params), period_ns_(seconds_to_ns(1.0 / params.rate_hz)) {
    if (!(params.range_m > 0.0) || !(params.rate_hz > 0.0)) {
        throw std::invalid_argument("boom height sensor: range_m and rate_hz must be > 0");
    }
}

void BoomHeightSensor::configure(DdsContext& dds) {
    voltage_writer_ = std::make_unique<Writer<msg::AnalogInput>>(dds, topics::kBoomHeightSensor);
}

double BoomHeightSensor::voltage_for(double linkage_rise_m) const {
    return std::clamp(linkage_rise_m / params_.range_m, 0.0, 1.0) * io::kAdcReferenceV;
}

TimeNs BoomHeightSensor::step(TimeNs now_ns) {
    msg::AnalogInput sample;
    sample.voltage_v(voltage_for(plant_.truth_at(now_ns).boom_height_m()));
    voltage_writer_->publish(sample);
    return next_period_boundary(now_ns, period_ns_);
}

}  // namespace rig::emulators
