#include "emulators/wheel_encoder.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "idl/topics.h"

namespace rig::emulators {

WheelEncoder::WheelEncoder(const Plant& plant, WheelEncoderParams params)
    : plant_(plant), params_(params), period_ns_(seconds_to_ns(1.0 / params.rate_hz)) {}

void WheelEncoder::configure(DdsContext& dds) {
    count_writer_ = std::make_unique<Writer<msg::EncoderCount>>(dds, topics::kWheelEncoder);
}

std::uint64_t WheelEncoder::pulses_at(TimeNs t) const {
    const double revolutions = plant_.wheel_travel_m_at(t) / (M_PI * params_.wheel_diameter_m);
    return static_cast<std::uint64_t>(std::floor(revolutions * params_.pulses_per_rev));
}

std::uint32_t WheelEncoder::count_at(TimeNs t) const {
    return static_cast<std::uint32_t>(pulses_at(t) & 0xffffffffULL);
}

void WheelEncoder::sample(TimeNs now_ns) {
    if (now_ns < last_sample_ns_) {
        throw std::logic_error("wheel encoder: sampled at " + std::to_string(now_ns) + " ns, before the last sample at " +
                               std::to_string(last_sample_ns_) + " ns");
    }
    const std::uint64_t pulses = pulses_at(now_ns);
    if (pulses > pulses_) {
        // The last edge is the first instant the count reached `pulses`: it lies in
        // (last sample, now], and the wheel never rolls back (land_wheel.h), so the
        // count is monotone in time and bisection finds it to the nanosecond.
        TimeNs before_ns = last_sample_ns_;  // count below `pulses` (or the start)
        TimeNs after_ns = now_ns;            // count at `pulses`
        if (pulses_at(before_ns) >= pulses) {
            after_ns = before_ns;  // only at the very first sample: reached before time began
        } else {
            while (after_ns - before_ns > 1) {
                const TimeNs middle_ns = before_ns + (after_ns - before_ns) / 2;
                if (pulses_at(middle_ns) >= pulses) after_ns = middle_ns;
                else before_ns = middle_ns;
            }
        }
        last_edge_ns_ = after_ns;
        pulses_ = pulses;
    }
    last_sample_ns_ = now_ns;
}

TimeNs WheelEncoder::step(TimeNs now_ns) {
    sample(now_ns);
    msg::EncoderCount count;
    count.count_pulses(this->count());
    count.last_edge_capture_us(last_edge_capture_us());
    count_writer_->publish(count);
    return next_period_boundary(now_ns, period_ns_);
}

}  // namespace rig::emulators
