#include "harness/judge/guidance_metrics.h"

#include <algorithm>
#include <cmath>

namespace rig::harness {

MetricSet guidance_metrics(const std::vector<GuidanceErrorSample>& samples, const std::string& point) {
    MetricSet metrics;
    const std::string cross = "guidance_" + point + "_cross_track_";
    double cross_sq = 0.0;
    double heading_sq = 0.0;
    double peak = 0.0;
    int moving = 0;
    for (const GuidanceErrorSample& s : samples) {
        if (!(s.speed_m_s > kMovingSpeedMS)) continue;
        cross_sq += s.cross_track_m * s.cross_track_m;
        heading_sq += s.heading_error_deg * s.heading_error_deg;
        peak = std::max(peak, std::abs(s.cross_track_m));
        ++moving;
    }
    metrics.values["guidance_moving_samples"] = moving;
    if (moving == 0) {
        const std::string why = "the vehicle never moved faster than 0.1 m/s: nothing was steered";
        for (const std::string& name : {cross + "rms_m", cross + "peak_m", std::string("guidance_heading_error_rms_deg")}) {
            metrics.not_measured[name] = why;
        }
        return metrics;
    }
    metrics.values[cross + "rms_m"] = std::sqrt(cross_sq / moving);
    metrics.values[cross + "peak_m"] = peak;
    metrics.values["guidance_heading_error_rms_deg"] = std::sqrt(heading_sq / moving);
    return metrics;
}

}  // namespace rig::harness
