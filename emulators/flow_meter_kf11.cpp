#include "emulators/flow_meter_kf11.h"

#include <cmath>
#include <stdexcept>

#include "idl/topics.h"

namespace rig::emulators {

FlowMeterKf11::FlowMeterKf11(const SprayCircuit& circuit, Kf11Params params)
    : circuit_(circuit), params_(params), period_ns_(seconds_to_ns(1.0 / params.rate_hz)) {
    if (!(params.pulses_per_l > 0.0) || !(params.rate_hz > 0.0)) {
        throw std::invalid_argument("KF11 flow meter: pulses_per_l and rate_hz must be > 0");
    }
}

void FlowMeterKf11::configure(DdsContext& dds) {
    count_writer_ = std::make_unique<Writer<msg::FlowMeterCount>>(dds, topics::kMainFlowMeter);
}

TimeNs FlowMeterKf11::step(TimeNs now_ns) {
    circuit_.require_advanced_to(now_ns, name_);
    const double volume_l = circuit_.main_volume_l();
    const double interval_s = ns_to_seconds(now_ns - last_sample_ns_);
    const double passed_l = volume_l - last_volume_l_;
    // The turbine turns only when the mean flow over the sample interval is in range.
    const double mean_flow_m3_h = interval_s > 0.0 ? passed_l / interval_s * 3.6 : 0.0;
    const double pulses_per_l = params_.pulses_per_l * (1.0 + params_.k_factor_error_pct / 100.0);
    if (mean_flow_m3_h >= params_.min_flow_m3_h && passed_l > 0.0) {
        const double registered_before_l = registered_volume_l_;
        registered_volume_l_ += passed_l;
        const auto pulses = static_cast<std::uint64_t>(std::floor(registered_volume_l_ * pulses_per_l));
        if (pulses > pulses_) {
            // The last edge: when the registered volume crossed pulses / k, the flow
            // taken as constant over the sample interval.
            const double fraction = (static_cast<double>(pulses) / pulses_per_l - registered_before_l) / passed_l;
            last_edge_ns_ = last_sample_ns_ + static_cast<TimeNs>(std::llround(fraction * static_cast<double>(now_ns - last_sample_ns_)));
            pulses_ = pulses;
        }
    }
    last_volume_l_ = volume_l;
    last_sample_ns_ = now_ns;

    msg::FlowMeterCount sample;
    sample.count_pulses(count());
    sample.last_edge_capture_us(last_edge_capture_us());
    count_writer_->publish(sample);
    return next_period_boundary(now_ns, period_ns_);
}

}  // namespace rig::emulators
