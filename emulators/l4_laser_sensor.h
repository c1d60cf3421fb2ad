#pragma once
// The MyAntenna L4 laser range sensor at the boom centre (seed 001 Sec. 1.1,
// Table 1), looking down: it tells the controller the boom height H3 that
// Eq. 18 and the vision's height projection need. Table 1: accuracy
// +-(1 mm + 0.0005 D), resolution 1 mm, 1-10 Hz continuous (about 10/20 Hz
// in fast mode).
//
// Wire format. The paper does not print it. MyAntenna's ASCII protocol, as a
// public driver for their L1 module shows it (github, "myantenna_L1.c" by
// CV-Engineer-Chen, after imyantenna.com/list-8.html), answers a measurement
// with "D=<metres>m" and an error with "E=<code>", each line ended by CR LF,
// three decimals by default (four optional). The rig ASSUMES the L4 speaks the
// same in its power-on continuous mode:
//     "D=0.503m\r\n"        a distance of 0.503 m
//     "E=1\r\n"             no valid measurement (out of range; code assumed)
//
// Model: samples at phase_s + k / rate_hz; the reading is the true distance
// D = H + mount_offset_m plus an error drawn uniformly within the stated
// accuracy (assumed distribution: the datasheet gives a bound, not a sigma),
// rounded to the 1 mm resolution, on the wire latency_s after the sample.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "emulators/field2d/sprayer_kinematics.h"
#include "emulators/seeded_random.h"
#include "emulators/timed_line.h"
#include "rig/runtime/clock.h"

namespace rig::emulators {

struct L4LaserParams {
    double rate_hz = 10.0;             // (0, 20]; Table 1: 1-10 Hz continuous
    double latency_s = 0.02;           // [0, 1]; assumed: measurement + 10 bytes on the line
    std::optional<double> phase_s;     // [0, 1 / rate_hz); unset: drawn from the seed
    // Sensor above the nozzles' plane: D = H + mount_offset_m. Assumed 0 (the
    // paper mounts it "at the boom centre" to measure the boom height).
    double mount_offset_m = 0.0;       // [-1, 2]
    double accuracy_base_m = 0.001;    // >= 0; Table 1: +-(1 mm + 0.0005 D)
    double accuracy_per_m = 0.0005;    // >= 0; Table 1
    double resolution_m = 0.001;       // (0, 0.1]; Table 1: 1 mm
    double min_range_m = 0.03;         // assumed measuring range of the module
    double max_range_m = 40.0;         // assumed
    int decimals = 3;                  // 3 or 4 (the protocol's two formats)
    std::uint64_t seed = 1;
};

// "D=0.503m\r\n" and "E=1\r\n" (see above). format_l4_distance throws
// std::invalid_argument for a non-finite or negative distance or decimals not 3 or 4.
std::string format_l4_distance(double distance_m, int decimals = 3);
std::string format_l4_error(int code);
inline constexpr int kL4OutOfRangeCode = 1;  // assumed

class L4LaserSensor {
public:
    // `kinematics` must outlive the sensor. Throws std::invalid_argument naming
    // the parameter when one is out of its range.
    L4LaserSensor(const field2d::SprayerKinematics& kinematics, L4LaserParams params);

    // Every line on the wire at or before now_ns not returned before, in order.
    std::vector<TimedLine> poll(TimeNs now_ns);
    TimeNs next_due_ns() const;
    double phase_s() const { return phase_s_; }
    const L4LaserParams& params() const { return params_; }

private:
    const field2d::SprayerKinematics& kinematics_;
    L4LaserParams params_;
    double phase_s_ = 0.0;
    TimeNs period_ns_ = 0;
    TimeNs phase_ns_ = 0;
    TimeNs latency_ns_ = 0;
    SeededRandom noise_;
    std::int64_t next_sample_ = 0;
};

}  // namespace rig::emulators
