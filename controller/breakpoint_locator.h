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
#include <cstdint>
#include <optional>
#include <vector>

#include "controller/breakpoint_store.h"
#include "controller/controller_config.h"

namespace rig::controller {

struct FixInput {
    double lat_deg = 0.0;
    double lon_deg = 0.0;
    std::optional<double> course_deg;  // RMC course, absent at standstill
    int quality = 0;
};

enum class LocatorEvent { none, reached };

class BreakpointLocator {
public:
    explicit BreakpointLocator(const ControllerConfig& config);

    void set_target(std::optional<StoredBreakpoint> breakpoint);
    const std::optional<StoredBreakpoint>& target() const { return target_; }

    LocatorEvent on_fix(const FixInput& fix, std::optional<std::uint32_t> latest_count, double speed_m_s);
    LocatorEvent on_encoder(std::uint32_t count);
    // Forgets the odometer's mileage base, so the next fix inside the threshold
    // sets s_b again (only the catalogue's stale-fix fault does this).
    void release_odometer() { odometer_base_count_.reset(); }

    double l4_m() const { return l4_m_; }
    // The boom moved: Eq. 6 again with the pull-wire sensor's linkage rise h.
    void set_linkage_rise_m(double linkage_rise_m);
    // A stored breakpoint is ahead and was seen approaching it (within the window).
    bool armed() const { return armed_; }
    bool odometer_active() const { return odometer_base_count_.has_value(); }
    // Latest estimate of the nozzle line's remaining distance to the breakpoint.
    std::optional<double> nozzle_to_breakpoint_m() const { return nozzle_to_go_m_; }

private:
    ControllerConfig config_;
    double l4_m_;
    std::optional<StoredBreakpoint> target_;
    bool armed_ = false;                      // seen approaching within the window
    std::optional<std::uint32_t> odometer_base_count_;
    double mileage_base_m_ = 0.0;             // s_b
    std::optional<double> nozzle_to_go_m_;
};

}  // namespace rig::controller
