#pragma once
// Land-wheel incremental encoder (seed 000 sec. 2.1: ZSP5208, 1000 pulses/rev).
// Publishes the cumulative pulse count, as a 32-bit hardware counter, at a fixed
// rate; the count follows what the wheel actually rolled (plant's land wheel model,
// slip and terrain included), not the true ground distance.
#include <cstdint>
#include <memory>
#include <string>

#include "emulators/plant.h"

namespace rig::emulators {

struct WheelEncoderParams {
    std::uint32_t pulses_per_rev = 1000;
    double wheel_diameter_m = 1.0;
    double rate_hz = 100.0;
};

class WheelEncoder final : public Node {
public:
    WheelEncoder(const Plant& plant, WheelEncoderParams params);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;
    // Cumulative count at t (wraps at 2^32 like the hardware counter).
    std::uint32_t count_at(TimeNs t) const;

private:
    std::string name_ = "wheel_encoder";
    const Plant& plant_;
    WheelEncoderParams params_;
    TimeNs period_ns_;
    std::unique_ptr<Writer<msg::EncoderCount>> count_writer_;
};

}  // namespace rig::emulators
