#include "emulators/wheel_encoder.h"

#include <cmath>

#include "idl/topics.h"

namespace rig::emulators {

WheelEncoder::WheelEncoder(const Plant& plant, WheelEncoderParams params)
    : plant_(plant), params_(params), period_ns_(seconds_to_ns(1.0 / params.rate_hz)) {}

void WheelEncoder::configure(DdsContext& dds) {
    count_writer_ = std::make_unique<Writer<msg::EncoderCount>>(dds, topics::kWheelEncoder);
}

std::uint32_t WheelEncoder::count_at(TimeNs t) const {
    const double wheel_travel_m = plant_.truth_at(t).wheel_travel_m();
    const double revolutions = wheel_travel_m / (M_PI * params_.wheel_diameter_m);
    const auto pulses = static_cast<std::uint64_t>(std::floor(revolutions * params_.pulses_per_rev));
    return static_cast<std::uint32_t>(pulses & 0xffffffffULL);
}

TimeNs WheelEncoder::step(TimeNs now_ns) {
    msg::EncoderCount count;
    count.count_pulses(count_at(now_ns));
    count_writer_->publish(count);
    return next_period_boundary(now_ns, period_ns_);
}

}  // namespace rig::emulators
