#pragma once
// How well the plant's autosteer kept to the route (docs/guidance.md), from
// truth: the offset right of the route of a point of the vehicle and the
// heading minus the route's, over the time the vehicle moves. A pure function
// of plain samples, so both systems' judges share it and tests can hand it a
// known answer.
//   guidance_<point>_cross_track_rms_m    RMS offset over time (the autosteer's "+-2.5 cm" is of this kind)
//   guidance_<point>_cross_track_peak_m   the largest |offset|
//   guidance_heading_error_rms_deg        RMS heading error over time
//   guidance_moving_samples               samples judged (speed above kMovingSpeedMS)
// The RMS values weigh each sample by the time it stands for (half the gap to
// each neighbour), not one sample one vote: seed 000's truth/vehicle holds a
// 20 Hz grid and also a sample at every instant the controller published, and
// counting those equally would let the controller's timing weigh the judgement.
#include <string>
#include <vector>

#include "harness/judge/metric_set.h"
#include "rig/runtime/clock.h"

namespace rig::harness {

struct GuidanceErrorSample {
    TimeNs t_ns = 0;                  // when; the samples come in time order
    double cross_track_m = 0.0;       // the point's offset right of the route
    double heading_error_deg = 0.0;   // the body's heading minus the route's, (-180, 180]
    double speed_m_s = 0.0;
};

// A vehicle standing still is not being guided (its error is frozen, not kept).
inline constexpr double kMovingSpeedMS = 0.1;

// `point` names the vehicle point the cross-track is of ("axle", "antenna").
// With no moving sample the metrics are not measured, saying why. Samples all
// at one instant (no time between them) count one each.
MetricSet guidance_metrics(const std::vector<GuidanceErrorSample>& samples, const std::string& point);

}  // namespace rig::harness
