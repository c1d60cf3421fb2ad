#pragma once
// KF11-P10 main-pipeline flow meter (seed 000 sec. 2.1): a turbine meter whose
// pulses go to a frequency input of the board; 90 pulses/L (Eq. 3, k1), range
// 0.27-14.14 m^3/h (4.5-235.7 L/min). Publishes, at a fixed rate, what the
// board's input-capture timer holds: the cumulative pulse count (a 32-bit
// hardware counter) and the 1 MHz timer value at the last pulse edge (the edge
// instant interpolated within the sample interval).
//
// Faults, named per-device parameters:
//   k_factor_error_pct  the meter's real pulses per litre differ from the
//                       nameplate 90 by this much (the controller's Eq. 3 still
//                       uses 90, so it reads high when positive);
//   below range         under min_flow_m3_h the turbine stalls: volume passing
//                       then gives no pulses at all.
#include <cstdint>
#include <memory>
#include <string>

#include "emulators/spray_circuit.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/io_image.h"
#include "rig/runtime/node.h"
#include "rig/papers/seed000.h"
#include "emulators/flow_meter_kf11_params.h"

namespace rig::emulators {

class FlowMeterKf11 final : public Node {
public:
    FlowMeterKf11(const SprayCircuit& circuit, Kf11Params params);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;
    // Pulses counted so far (after a step), wrapping at 2^32 like the hardware counter.
    std::uint32_t count() const { return static_cast<std::uint32_t>(pulses_ & 0xffffffffULL); }
    // Capture timer (1 MHz, wraps) at the last edge.
    std::uint32_t last_edge_capture_us() const {
        constexpr TimeNs kNsPerTick = 1'000'000'000 / io::kCaptureTimerHz;
        return static_cast<std::uint32_t>(static_cast<std::uint64_t>(last_edge_ns_ / kNsPerTick) & 0xffffffffULL);
    }

private:
    std::string name_ = "main_flow_meter";
    const SprayCircuit& circuit_;
    Kf11Params params_;
    TimeNs period_ns_;
    TimeNs last_sample_ns_ = 0;
    double last_volume_l_ = 0.0;
    double registered_volume_l_ = 0.0;   // volume that passed while the turbine turned
    std::uint64_t pulses_ = 0;
    TimeNs last_edge_ns_ = 0;
    std::unique_ptr<Writer<msg::FlowMeterCount>> count_writer_;
};

}  // namespace rig::emulators
