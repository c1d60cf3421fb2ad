#include "emulators/l4_laser_sensor.h"

#include <cmath>
#include <stdexcept>

#include "emulators/param_check.h"

namespace rig::emulators {

std::string format_l4_distance(double distance_m, int decimals) {
    if (!std::isfinite(distance_m) || distance_m < 0.0 || distance_m > 1e6) {
        throw std::invalid_argument("l4 format: distance must be finite, >= 0 and < 1e6 m");
    }
    if (decimals != 3 && decimals != 4) throw std::invalid_argument("l4 format: decimals must be 3 or 4");
    // Integer arithmetic on the rounded value, so the digits are exact.
    const long long unit = decimals == 3 ? 1000 : 10000;
    const long long scaled = std::llround(distance_m * static_cast<double>(unit));
    std::string fraction = std::to_string(scaled % unit);
    fraction.insert(0, static_cast<std::size_t>(decimals) - fraction.size(), '0');
    return "D=" + std::to_string(scaled / unit) + "." + fraction + "m\r\n";
}

std::string format_l4_error(int code) { return "E=" + std::to_string(code) + "\r\n"; }

L4LaserSensor::L4LaserSensor(const field2d::SprayerKinematics& kinematics, L4LaserParams params)
    : kinematics_(kinematics), params_(std::move(params)), noise_(params_.seed, "l4_laser.noise") {
    if (!std::isfinite(params_.rate_hz) || params_.rate_hz <= 0.0 || params_.rate_hz > 20.0) {
        throw std::invalid_argument("l4_laser.rate_hz: must be in (0, 20], got " + std::to_string(params_.rate_hz));
    }
    const double period_s = 1.0 / params_.rate_hz;
    check_range("l4_laser", "latency_s", params_.latency_s, 0.0, 1.0);
    check_range("l4_laser", "mount_offset_m", params_.mount_offset_m, -1.0, 2.0);
    check_range("l4_laser", "accuracy_base_m", params_.accuracy_base_m, 0.0, 1.0);
    check_range("l4_laser", "accuracy_per_m", params_.accuracy_per_m, 0.0, 0.1);
    if (!(params_.resolution_m > 0.0) || params_.resolution_m > 0.1) {
        throw std::invalid_argument("l4_laser.resolution_m: must be in (0, 0.1], got " +
                                    std::to_string(params_.resolution_m));
    }
    check_range("l4_laser", "min_range_m", params_.min_range_m, 0.0, 1000.0);
    if (!std::isfinite(params_.max_range_m) || params_.max_range_m <= params_.min_range_m) {
        throw std::invalid_argument("l4_laser.max_range_m: must be finite and > min_range_m");
    }
    if (params_.decimals != 3 && params_.decimals != 4) {
        throw std::invalid_argument("l4_laser.decimals: must be 3 or 4, got " + std::to_string(params_.decimals));
    }
    if (params_.phase_s) {
        check_range("l4_laser", "phase_s", *params_.phase_s, 0.0, period_s, true);
        phase_s_ = *params_.phase_s;
    } else {
        SeededRandom phase_draw(params_.seed, "l4_laser.phase");
        phase_s_ = phase_draw.uniform01() * period_s;
    }
    period_ns_ = seconds_to_ns(period_s);
    phase_ns_ = seconds_to_ns(phase_s_);
    latency_ns_ = seconds_to_ns(params_.latency_s);
}

TimeNs L4LaserSensor::next_due_ns() const { return phase_ns_ + next_sample_ * period_ns_ + latency_ns_; }

std::vector<TimedLine> L4LaserSensor::poll(TimeNs now_ns) {
    std::vector<TimedLine> lines;
    while (next_due_ns() <= now_ns) {
        const TimeNs sample_ns = phase_ns_ + next_sample_ * period_ns_;
        ++next_sample_;
        const double u = noise_.uniform01();  // one draw per sample, always
        const double truth_m = kinematics_.boom_height_at(ns_to_seconds(sample_ns)) + params_.mount_offset_m;
        std::string text;
        if (truth_m < params_.min_range_m || truth_m > params_.max_range_m) {
            text = format_l4_error(kL4OutOfRangeCode);
        } else {
            const double bound_m = params_.accuracy_base_m + params_.accuracy_per_m * truth_m;
            const double measured_m = truth_m + (2.0 * u - 1.0) * bound_m;
            const double rounded_m = std::round(measured_m / params_.resolution_m) * params_.resolution_m;
            text = format_l4_distance(std::max(0.0, rounded_m), params_.decimals);
        }
        lines.push_back(TimedLine{sample_ns + latency_ns_, std::move(text)});
    }
    return lines;
}

}  // namespace rig::emulators
