#pragma once
// How well the plant's autosteer kept to the route (docs/guidance.md), from
// truth: the offset right of the route of a point of the vehicle and the
// heading minus the route's, over the samples where the vehicle moves. A pure
// function of plain samples, so both systems' judges share it and tests can
// hand it a known answer.
//   guidance_<point>_cross_track_rms_m    RMS offset (the autosteer's "+-2.5 cm" is of this kind)
//   guidance_<point>_cross_track_peak_m   the largest |offset|
//   guidance_heading_error_rms_deg        RMS heading error
//   guidance_moving_samples               samples judged (speed above kMovingSpeedMS)
#include <string>
#include <vector>

#include "harness/judge/metric_set.h"

namespace rig::harness {

struct GuidanceErrorSample {
    double cross_track_m = 0.0;       // the point's offset right of the route
    double heading_error_deg = 0.0;   // the body's heading minus the route's, (-180, 180]
    double speed_m_s = 0.0;
};

// A vehicle standing still is not being guided (its error is frozen, not kept).
inline constexpr double kMovingSpeedMS = 0.1;

// `point` names the vehicle point the cross-track is of ("axle", "antenna").
// With no moving sample the metrics are not measured, saying why.
MetricSet guidance_metrics(const std::vector<GuidanceErrorSample>& samples, const std::string& point);

}  // namespace rig::harness
