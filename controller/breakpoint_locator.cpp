#include "controller/breakpoint_locator.h"

#include "controller/breakpoint_equations.h"

namespace rig::controller {

BreakpointLocator::BreakpointLocator(const ControllerConfig& config)
    : config_(config),
      l4_m_(antenna_to_nozzle_m(config.l1_m, config.l2_m, config.l3_m, config.linkage_rise_m)) {}

void BreakpointLocator::set_linkage_rise_m(double linkage_rise_m) {
    l4_m_ = antenna_to_nozzle_m(config_.l1_m, config_.l2_m, config_.l3_m, linkage_rise_m);
}

void BreakpointLocator::set_target(std::optional<StoredBreakpoint> breakpoint) {
    target_ = std::move(breakpoint);
    armed_ = false;
    odometer_base_count_.reset();
    nozzle_to_go_m_.reset();
}

LocatorEvent BreakpointLocator::on_fix(const FixInput& fix, std::optional<std::uint32_t> latest_count,
                                       double speed_m_s) {
    constexpr int kRtkFixedQuality = 4;
    if (!target_ || fix.quality == 0 || !fix.course_deg) return LocatorEvent::none;
    if (config_.rtk_fixed_only && fix.quality != kRtkFixedQuality) return LocatorEvent::none;
    if (odometer_base_count_) return LocatorEvent::none;  // fusion: the odometer has taken over

    // S of Eq. 4, signed by whether the breakpoint lies ahead of the course.
    double antenna_ahead_m =
        signed_distance_ahead_m(fix.lat_deg, fix.lon_deg, *fix.course_deg, target_->lat_deg, target_->lon_deg);
    // The fix describes where the antenna was `latency` ago.
    antenna_ahead_m -= speed_m_s * config_.gnss_latency_compensation_s;
    const double nozzle_to_go_m = antenna_ahead_m + l4_m_;

    if (!armed_) {
        // Arm only while approaching from behind and clear of it, so a breakpoint
        // we are past, or standing on right after the button press, does not fire.
        if (nozzle_to_go_m >= config_.arm_distance_m && nozzle_to_go_m <= config_.approach_window_m) armed_ = true;
        else return LocatorEvent::none;
    }
    nozzle_to_go_m_ = nozzle_to_go_m;

    if (config_.positioning == Positioning::fusion && antenna_ahead_m <= config_.threshold_m && latest_count) {
        // Eq. 7: the first S at or inside the threshold is the mileage base s_b.
        mileage_base_m_ = antenna_ahead_m;
        odometer_base_count_ = *latest_count;
        return on_encoder(*latest_count);
    }
    if (config_.positioning == Positioning::rtk_only && nozzle_to_go_m <= 0.0) return LocatorEvent::reached;
    return LocatorEvent::none;
}

LocatorEvent BreakpointLocator::on_encoder(std::uint32_t count) {
    if (!target_ || !odometer_base_count_) return LocatorEvent::none;
    // Unsigned difference: correct across the 32-bit counter wrap.
    const std::uint32_t pulses = count - *odometer_base_count_;
    const double travelled_m = pulses_to_distance_m(pulses, config_.pulses_per_rev, config_.wheel_diameter_m);
    nozzle_to_go_m_ = mileage_base_m_ + l4_m_ - travelled_m;
    return *nozzle_to_go_m_ <= 0.0 ? LocatorEvent::reached : LocatorEvent::none;
}

}  // namespace rig::controller
