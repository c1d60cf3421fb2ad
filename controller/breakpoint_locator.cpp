#include "controller/breakpoint_locator.h"

#include <algorithm>
#include <cmath>

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
    compare_ns_.reset();
    nozzle_to_go_m_.reset();
}

void BreakpointLocator::release_odometer() {
    odometer_base_count_.reset();
    compare_ns_.reset();
}

LocatorEvent BreakpointLocator::on_fix(const FixInput& fix, std::optional<EncoderReading> latest, double speed_m_s,
                                       TimeNs now_ns) {
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

    if (config_.positioning == Positioning::fusion && antenna_ahead_m <= config_.threshold_m && latest) {
        // Eq. 7: the first S at or inside the threshold is the mileage base s_b,
        // and the odometer's base is where the wheel is at this fix's instant (the
        // last edge carried on to now_ns), not where it was at the last read.
        mileage_base_m_ = antenna_ahead_m;
        odometer_base_count_ = latest->count;
        last_reading_ = *latest;
        speed_m_s_ = speed_m_s;
        base_extrapolated_m_ = extrapolated_m(now_ns);
        return on_encoder(*latest, speed_m_s, now_ns);
    }
    if (config_.positioning == Positioning::rtk_only && nozzle_to_go_m <= 0.0) return LocatorEvent::reached;
    return LocatorEvent::none;
}

LocatorEvent BreakpointLocator::on_encoder(const EncoderReading& reading, double speed_m_s, TimeNs now_ns) {
    last_reading_ = reading;
    speed_m_s_ = speed_m_s;
    if (!target_ || !odometer_base_count_) return LocatorEvent::none;
    nozzle_to_go_m_ = odometer_to_go_m(now_ns);
    const std::optional<TimeNs> at_breakpoint_ns = instant_nozzle_to_go_m(0.0);
    const bool reached = *nozzle_to_go_m_ <= 0.0 || (at_breakpoint_ns && *at_breakpoint_ns <= now_ns);
    // The compare for the predicted instant; every read replaces it with a fresher one.
    compare_ns_.reset();
    if (!reached && at_breakpoint_ns) compare_ns_ = *at_breakpoint_ns;
    return reached ? LocatorEvent::reached : LocatorEvent::none;
}

LocatorEvent BreakpointLocator::on_time(TimeNs now_ns) {
    if (!target_ || !odometer_base_count_ || !compare_ns_ || now_ns < *compare_ns_) return LocatorEvent::none;
    compare_ns_.reset();
    // The prediction says this is the instant; rounding may leave a nanometre to go.
    nozzle_to_go_m_ = std::min(0.0, odometer_to_go_m(now_ns));
    return LocatorEvent::reached;
}

TimeNs BreakpointLocator::next_compare_ns() const { return compare_ns_.value_or(kNever); }

std::optional<TimeNs> BreakpointLocator::instant_nozzle_to_go_m(double remaining_m) const {
    if (!target_ || !odometer_base_count_ || !last_reading_.last_edge_ns || !(speed_m_s_ > 0.0)) return std::nullopt;
    // Odometer distance since the base at the last edge, and what is missing to `remaining_m` before it.
    const double at_edge_m = pulses_to_distance_m(last_reading_.count - *odometer_base_count_, config_.pulses_per_rev,
                                                  config_.wheel_diameter_m) -
                             base_extrapolated_m_;
    const double after_edge_s = (mileage_base_m_ + l4_m_ - remaining_m - at_edge_m) / speed_m_s_;
    // Already there at the last edge: some instant in the past, the edge will do.
    if (!(after_edge_s > 0.0)) return *last_reading_.last_edge_ns;
    // Further than the speed is trusted: the next read will tell.
    if (after_edge_s > config_.speed_window_s) return std::nullopt;
    return *last_reading_.last_edge_ns + static_cast<TimeNs>(std::ceil(after_edge_s * 1e9));
}

std::optional<double> BreakpointLocator::nozzle_to_breakpoint_m_at(TimeNs now_ns) const {
    if (target_ && odometer_base_count_) return odometer_to_go_m(now_ns);
    return nozzle_to_go_m_;
}

double BreakpointLocator::extrapolated_m(TimeNs t) const {
    if (!last_reading_.last_edge_ns || !(speed_m_s_ > 0.0)) return 0.0;
    const double since_edge_s = std::clamp(ns_to_seconds(t - *last_reading_.last_edge_ns), 0.0, config_.speed_window_s);
    return speed_m_s_ * since_edge_s;
}

double BreakpointLocator::odometer_to_go_m(TimeNs t) const {
    // Unsigned difference: correct across the 32-bit counter wrap.
    const std::uint32_t pulses = last_reading_.count - *odometer_base_count_;
    const double travelled_m = pulses_to_distance_m(pulses, config_.pulses_per_rev, config_.wheel_diameter_m) +
                               extrapolated_m(t) - base_extrapolated_m_;
    return mileage_base_m_ + l4_m_ - travelled_m;
}

}  // namespace rig::controller
