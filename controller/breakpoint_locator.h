#pragma once
// Breakpoint identification (seed 000 sec. 2.2.3, 2.5.1): where is the nozzle line
// relative to the stored breakpoint? Pure logic, no DDS and no clock of its own:
// the reference controller feeds it fixes and encoder counts with their arrival
// time, and it says when the nozzle line has reached the breakpoint.
//
// RTK-only: S from Eq. 4 on every fix; the nozzle line is L4 (Eq. 6) behind the
//   antenna, so it is at the breakpoint when S_ahead + L4 <= 0. At 5 Hz the fix
//   that first satisfies this comes up to v x 0.2 s late (Table 4's growth with speed).
// Fusion: the first fix with S_ahead <= threshold gives the mileage base s_b
//   (Eq. 7); from then on the wheel odometer counts, and the nozzle line is at the
//   breakpoint when the odometer distance reaches s_b + L4 (Eq. 7 with the spray
//   lead v(t2+t3) = 0, which the flow-control issue adds).
//
// Between encoder reads (the board reads its counter on a grid, 10 ms on the
// rig) the odometer is not blind when the wire carries the capture time of the
// last counted edge (EncoderReading::last_edge_ns): the wheel was exactly
// count x pulse length along at that instant, and moves on at the Eq. 5 speed.
// So the position at any instant t (the fix's arrival, the breakpoint) is
//   odometer(t) = pulses x pi D / N + v x (t - last_edge), 0 <= t - last_edge <= t1,
// and the instant the nozzle line reaches the breakpoint is predicted from the
// last read; the controller acts then (a timer compare, next_compare_ns()),
// not at the next read of the grid: the error is no longer a multiple of
// v x read period. Beyond t1 (speed_window_s) after the last edge the speed is
// not trusted and nothing is extrapolated. Without a capture time the count is
// known at the read instant only, and the locator acts on reads as before.
#include <cstdint>
#include <optional>
#include <vector>

#include "controller/breakpoint_store.h"
#include "controller/controller_config.h"
#include "rig/runtime/clock.h"

namespace rig::controller {

struct FixInput {
    double lat_deg = 0.0;
    double lon_deg = 0.0;
    std::optional<double> course_deg;  // RMC course, absent at standstill
    int quality = 0;
};

// One read of the land-wheel encoder.
struct EncoderReading {
    std::uint32_t count = 0;   // cumulative pulses, 32 bit, wraps
    // When the last counted edge came, on the controller's clock (from the
    // board's capture timer); absent when the wire does not carry it.
    std::optional<TimeNs> last_edge_ns;
};

enum class LocatorEvent { none, reached };

class BreakpointLocator {
public:
    explicit BreakpointLocator(const ControllerConfig& config);

    void set_target(std::optional<StoredBreakpoint> breakpoint);
    const std::optional<StoredBreakpoint>& target() const { return target_; }

    // A fix completed at now_ns; `latest` is the last encoder read, `speed_m_s`
    // the Eq. 5 speed.
    LocatorEvent on_fix(const FixInput& fix, std::optional<EncoderReading> latest, double speed_m_s, TimeNs now_ns);
    LocatorEvent on_encoder(const EncoderReading& reading, double speed_m_s, TimeNs now_ns);
    // No new input, time passed: reached when now_ns is at or past the predicted
    // instant (next_compare_ns()).
    LocatorEvent on_time(TimeNs now_ns);
    // When the odometer predicts the nozzle line at the breakpoint (kNever when it
    // cannot: no capture time, no speed, already there, not integrating).
    TimeNs next_compare_ns() const;
    // When the odometer predicts the nozzle line `remaining_m` before the
    // breakpoint (in the past when it already is); nullopt when it cannot predict
    // (no capture time, no speed, or further than speed_window_s after the last edge).
    std::optional<TimeNs> instant_nozzle_to_go_m(double remaining_m) const;
    // Forgets the odometer's mileage base, so the next fix inside the threshold
    // sets s_b again (only the catalogue's stale-fix fault does this).
    void release_odometer();

    double l4_m() const { return l4_m_; }
    // The boom moved: Eq. 6 again with the pull-wire sensor's linkage rise h.
    void set_linkage_rise_m(double linkage_rise_m);
    // A stored breakpoint is ahead and was seen approaching it (within the window).
    bool armed() const { return armed_; }
    bool odometer_active() const { return odometer_base_count_.has_value(); }
    // Latest estimate of the nozzle line's remaining distance to the breakpoint.
    std::optional<double> nozzle_to_breakpoint_m() const { return nozzle_to_go_m_; }
    // The same at now_ns: the odometer's estimate carried on from the last edge.
    std::optional<double> nozzle_to_breakpoint_m_at(TimeNs now_ns) const;

private:
    ControllerConfig config_;
    double l4_m_;
    std::optional<StoredBreakpoint> target_;
    bool armed_ = false;                      // seen approaching within the window
    // Distance past the last counted edge at t: v x (t - last edge), 0 without a
    // capture time or more than speed_window_s after the edge.
    double extrapolated_m(TimeNs t) const;
    // s_b + L4 - odometer distance since the base, at t.
    double odometer_to_go_m(TimeNs t) const;

    std::optional<std::uint32_t> odometer_base_count_;
    double base_extrapolated_m_ = 0.0;        // extrapolated_m() at the base fix
    double mileage_base_m_ = 0.0;             // s_b
    EncoderReading last_reading_;             // the read the odometer now stands on
    double speed_m_s_ = 0.0;                  // Eq. 5 speed at that read
    std::optional<TimeNs> compare_ns_;        // predicted instant at the breakpoint, pending
    std::optional<double> nozzle_to_go_m_;
};

}  // namespace rig::controller
