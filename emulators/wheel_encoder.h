#pragma once
// Land-wheel incremental encoder (seed 000 sec. 2.1: ZSP5208, 1000 pulses/rev) on
// a counter input of the board. Publishes, at a fixed rate, what the board's
// timer holds: the cumulative pulse count (a 32-bit hardware counter) and the
// capture of the 1 MHz timer at the last counted edge, as the KF11 flow meter's
// input does. The count follows what the wheel actually rolled (plant's land
// wheel model, slip and terrain included), not the true ground distance.
//
// The capture timer (the controller board's, on the rig's clock):
//   epoch  rig time 0 (the case's t = 0; the board's timer started with it)
//   tick   1 us; the value is the tick in which the edge came: floor(edge ns / 1000)
//   wrap   32 bit, every 2^32 us = 71.6 min; only differences (unsigned) mean anything
// The edge is the instant the wheel's travel crossed count x (pi D / pulses_per_rev),
// found exactly in the plant (which is a pure function of time) to the
// nanosecond: not interpolated, not on the publishing grid. Before the first
// edge it reads 0.
#include <cstdint>
#include <memory>
#include <string>

#include "emulators/plant.h"
#include "rig/papers/seed000.h"
#include "emulators/wheel_encoder_params.h"

namespace rig::emulators {

class WheelEncoder final : public Node {
public:
    WheelEncoder(const Plant& plant, WheelEncoderParams params);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;
    // Cumulative count at t (wraps at 2^32 like the hardware counter).
    std::uint32_t count_at(TimeNs t) const;
    // Updates the count and the last edge to now_ns (what step() publishes).
    // Times must not go backwards.
    void sample(TimeNs now_ns);
    // After sample(): the count, and the capture timer's value at its last edge.
    std::uint32_t count() const { return static_cast<std::uint32_t>(pulses_ & 0xffffffffULL); }
    std::uint32_t last_edge_capture_us() const {
        return static_cast<std::uint32_t>(static_cast<std::uint64_t>(last_edge_ns_ / 1000) & 0xffffffffULL);
    }
    // The last edge to the nanosecond (the rig's time; the capture truncates it).
    TimeNs last_edge_ns() const { return last_edge_ns_; }

private:
    std::uint64_t pulses_at(TimeNs t) const;

    std::string name_ = "wheel_encoder";
    const Plant& plant_;
    WheelEncoderParams params_;
    TimeNs period_ns_;
    TimeNs last_sample_ns_ = 0;
    std::uint64_t pulses_ = 0;
    TimeNs last_edge_ns_ = 0;
    std::unique_ptr<Writer<msg::EncoderCount>> count_writer_;
};

}  // namespace rig::emulators
