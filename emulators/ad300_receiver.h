#pragma once
// The AD300 GNSS-RTK receiver of seed 001 (Beidou; Shandong Beidou Huachen,
// Sec. 1.1): the paper's controller reads GPRMC at 10 Hz on a serial line
// (Sec. 4.2.2) for position, course over ground (0 = north, clockwise) and
// speed. The paper gives no accuracy, latency or baud rate: those are
// parameters (assumed values below).
//
// Each epoch (at epoch_phase_s + k / rate_hz) the receiver samples the plant's
// antenna (emulators/field2d/sprayer_kinematics.h) and reports:
//   position  truth + N(0, sigma) per horizontal axis, sigma = base + ppm x baseline
//             (independent per epoch);
//   velocity  the antenna's true velocity (in a turn not along the heading) +
//             N(0, velocity_noise_m_s) per axis, as a Doppler velocity is; speed
//             and course come from it, so the course noise grows as the speed
//             falls (about velocity_noise / v rad: 0.8 deg at 1.5 m/s, 11 deg at
//             0.1 m/s with the defaults), and below min_course_speed_m_s the
//             course field is left empty, as receivers do when nearly still.
// The RMC sentence (rig/nmea/nmea_encoder.h) is on the wire latency_s after
// its epoch. The epoch phase, unless given, is drawn from the seed (stream
// "ad300.epoch_phase"), so a case's seed decides where the epochs fall
// relative to the area's edge; the noise uses stream "ad300.noise".
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "emulators/field2d/sprayer_kinematics.h"
#include "rig/nmea/nmea_encoder.h"
#include "emulators/seeded_random.h"
#include "emulators/timed_line.h"
#include "rig/runtime/clock.h"

namespace rig::emulators {

struct Ad300Params {
    std::string talker = "GP";            // two letters; Sec. 4.2.2 reads "GPRMC"
    double rate_hz = 10.0;                // (0, 100]; Sec. 4.2.2
    double latency_s = 0.05;              // [0, 1]; assumed: epoch -> last byte of RMC on the wire
    std::optional<double> epoch_phase_s;  // [0, 1 / rate_hz); unset: drawn from the seed
    double noise_base_m = 0.01;           // >= 0; assumed RTK fixed 1 cm + 1 ppm (1-sigma per axis)
    double noise_ppm = 1.0;               // >= 0
    double baseline_km = 2.0;             // >= 0; rover to base station, assumed
    double velocity_noise_m_s = 0.02;     // >= 0; assumed, 1-sigma per axis of the Doppler velocity
    double min_course_speed_m_s = 0.1;    // >= 0; assumed: course left empty below this reported speed
    int utc_year = 2020, utc_month = 11, utc_day = 15;  // Sec. 5.1: November 2020 (day assumed)
    double utc_start_seconds_of_day = 2.0 * 3600.0;     // [0, 86400); 10:00 Beijing time, assumed
    std::uint64_t seed = 1;
};

class Ad300Receiver {
public:
    // `kinematics` must outlive the receiver. Throws std::invalid_argument
    // naming the parameter when one is out of its range.
    Ad300Receiver(const field2d::SprayerKinematics& kinematics, Ad300Params params);

    // Every RMC sentence on the wire at or before now_ns not returned before,
    // in order. Epochs are solved in order whatever the calls' spacing, so the
    // same seed gives the same sentences bit for bit.
    std::vector<TimedLine> poll(TimeNs now_ns);
    // When the next sentence will be on the wire.
    TimeNs next_due_ns() const;

    double epoch_phase_s() const { return phase_s_; }
    TimeNs epoch_ns(std::int64_t k) const;
    const Ad300Params& params() const { return params_; }

private:
    nmea::GnssFix solve_epoch(TimeNs epoch_ns);

    const field2d::SprayerKinematics& kinematics_;
    Ad300Params params_;
    double phase_s_ = 0.0;
    TimeNs period_ns_ = 0;
    TimeNs phase_ns_ = 0;
    TimeNs latency_ns_ = 0;
    SeededRandom noise_;
    std::int64_t next_epoch_ = 0;
};

}  // namespace rig::emulators
