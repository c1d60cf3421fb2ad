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
#include "emulators/gnss_g970_params.h"

namespace rig::emulators {

int gga_quality(GnssFixKind kind);  // NMEA GGA quality indicator

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
