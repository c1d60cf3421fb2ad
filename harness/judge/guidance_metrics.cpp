#include "harness/judge/guidance_metrics.h"

#include <algorithm>
#include <cmath>

namespace rig::harness {

MetricSet guidance_metrics(const std::vector<GuidanceErrorSample>& samples, const std::string& point) {
    MetricSet metrics;
    const std::string cross = "guidance_" + point + "_cross_track_";
    // Each sample stands for the time from halfway to the one before it to
    // halfway to the one after (the ends for half a gap): the midpoint rule.
    std::vector<double> weights(samples.size(), 0.0);
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const TimeNs before = samples[i > 0 ? i - 1 : i].t_ns;
        const TimeNs after = samples[i + 1 < samples.size() ? i + 1 : i].t_ns;
        weights[i] = 0.5 * static_cast<double>(after - before);
    }
    const bool timed = samples.size() > 1 && samples.back().t_ns > samples.front().t_ns;
    double cross_sq = 0.0;
    double heading_sq = 0.0;
    double weight_sum = 0.0;
    double peak = 0.0;
    int moving = 0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const GuidanceErrorSample& s = samples[i];
        if (!(s.speed_m_s > kMovingSpeedMS)) continue;
        const double weight = timed ? weights[i] : 1.0;
        cross_sq += weight * s.cross_track_m * s.cross_track_m;
        heading_sq += weight * s.heading_error_deg * s.heading_error_deg;
        weight_sum += weight;
        peak = std::max(peak, std::abs(s.cross_track_m));
        ++moving;
    }
    metrics.values["guidance_moving_samples"] = moving;
    if (moving == 0 || !(weight_sum > 0.0)) {
        const std::string why = moving == 0 ? "the vehicle never moved faster than 0.1 m/s: nothing was steered"
                                            : "the moving samples stand for no time (each an end at one instant)";
        for (const std::string& name : {cross + "rms_m", cross + "peak_m", std::string("guidance_heading_error_rms_deg")}) {
            metrics.not_measured[name] = why;
        }
        return metrics;
    }
    metrics.values[cross + "rms_m"] = std::sqrt(cross_sq / weight_sum);
    metrics.values[cross + "peak_m"] = peak;
    metrics.values["guidance_heading_error_rms_deg"] = std::sqrt(heading_sq / weight_sum);
    return metrics;
}

}  // namespace rig::harness
