#pragma once
// The G970II receiver's parameters (emulators/gnss_g970.h), apart from the node so
// that case files take their defaults from here without DDS.
#include <cstdint>
#include <string>
#include <vector>

#include "emulators/wire_faults.h"

namespace rig::emulators {

enum class GnssFixKind { rtk_fixed, rtk_float, dgps, autonomous };

struct GnssEpisode {
    double at_s = 0.0;
    double for_s = 0.0;
    GnssFixKind fix = GnssFixKind::rtk_float;  // degraded episodes only
    double sigma_m = 0.3;                       // degraded episodes only
};

struct G970Params {
    std::string talker = "GP";
    double rate_hz = 5.0;
    double latency_s = 0.02;
    double epoch_phase_s = 0.0;    // epochs at epoch_phase_s + k / rate_hz, [0, 1 / rate_hz)
    GnssFixKind fix = GnssFixKind::rtk_fixed;
    double noise_base_m = 0.008;   // RTK 8 mm + 1 ppm (sec. 2.2.3)
    double noise_ppm = 1.0;
    double baseline_km = 2.0;      // rover to base station
    std::vector<GnssEpisode> dropouts;
    std::vector<GnssEpisode> degraded;
    int utc_year = 2023, utc_month = 7, utc_day = 15;
    double utc_start_seconds_of_day = 2 * 3600.0;
    NmeaWireFaultRates wire_faults;  // all off by default
    std::uint64_t seed = 1;
};

}  // namespace rig::emulators
