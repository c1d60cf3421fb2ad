#pragma once
// G970II RTK-GNSS receiver emulator (seed 000 sec. 2.1: NMEA over RS232 at 5 Hz,
// RTK 8 mm + 1 ppm). Each epoch it samples the plant's antenna position, applies
// the receiver's error model and faults, and sends GGA then RMC on the wire
// `latency_s` after the epoch. The fix (data) and NMEA (wire format,
// rig/nmea/nmea_encoder.h) are kept apart.
//
// Faults, all named per-device parameters:
//   latency_s  epoch -> sentences on the wire
//   dropouts   intervals with no sentences at all (signal lost, Table 4 run 8)
//   degraded   intervals with a worse fix (RTK float / DGPS / autonomous) and noise
//   wire_faults  byte loss, corrupt checksums, truncated sentences on the way
//              out (emulators/wire_faults.h): only the bytes change, never the fix
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rig/nmea/nmea_encoder.h"
#include "emulators/plant.h"
#include "emulators/seeded_random.h"
#include "emulators/wire_faults.h"

namespace rig::emulators {

enum class GnssFixKind { rtk_fixed, rtk_float, dgps, autonomous };
int gga_quality(GnssFixKind kind);  // NMEA GGA quality indicator

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

class GnssG970 final : public Node {
public:
    GnssG970(const Plant& plant, G970Params params);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;

    // The receiver's solution for the epoch at `epoch_ns` (nullopt inside a dropout).
    // Public so tests can check the error model without DDS.
    std::optional<nmea::GnssFix> solve_epoch(TimeNs epoch_ns);

    // What the wire faults did so far (all zero when they are off).
    const NmeaWireFaultCounts& wire_fault_counts() const { return wire_faults_.counts(); }

private:
    TimeNs epoch_period_ns() const;
    std::string name_ = "gnss_g970";
    const Plant& plant_;
    G970Params params_;
    SeededRandom noise_;
    NmeaWireFaults wire_faults_;
    std::int64_t next_epoch_index_ = 0;
    std::unique_ptr<Writer<msg::NmeaSentence>> nmea_writer_;
};

}  // namespace rig::emulators
