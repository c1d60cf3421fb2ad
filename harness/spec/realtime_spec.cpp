#include "harness/spec/realtime_spec.h"

#include <cstdio>
#include <string>

#include "harness/spec/case_spec.h"

namespace rig::harness {

namespace {

// late_after_ms, max_late_pct and max_lateness_ms of `section`, each defaulting to `fallback`'s.
LatenessLimits read_limits(const YamlSection& section, const LatenessLimits& fallback) {
    LatenessLimits limits;
    // Below 0.1 ms the kernel's own wake-up latency would count; above a second
    // nothing real-time is being judged any more.
    limits.late_after_ms =
        section.optional_in_range<double>("late_after_ms", fallback.late_after_ms, Bounds::open_closed(0, 1000));
    limits.max_late_pct = section.optional_in_range<double>("max_late_pct", fallback.max_late_pct, Bounds::closed(0, 100));
    limits.max_lateness_ms =
        section.optional_in_range<double>("max_lateness_ms", fallback.max_lateness_ms, Bounds::closed(1, 60000));
    if (limits.max_lateness_ms < limits.late_after_ms) {
        char numbers[96];
        std::snprintf(numbers, sizeof numbers, "max_lateness_ms (%g ms) is below late_after_ms (%g ms)",
                      limits.max_lateness_ms, limits.late_after_ms);
        section.fail(section.has("max_lateness_ms") ? "max_lateness_ms" : "late_after_ms",
                     std::string(numbers) + ": an emission that late must already count as late");
    }
    return limits;
}

}  // namespace

LatenessBound read_realtime_section(const YamlSection& section) {
    LatenessBound bound;
    static_cast<LatenessLimits&>(bound) = read_limits(section, LatenessLimits{});
    // A device's own limits: what it leaves out takes the case's.
    const YamlSection devices = section.section("devices");
    for (const std::string& device : devices.keys()) {
        bound.devices[device] = read_limits(devices.section(device), bound);
    }
    return bound;
}

std::optional<RigFaultsSpec> read_rig_faults(const YamlSection& section) {
    if (!section.present()) return std::nullopt;
    RigFaultsSpec faults;
    faults.master_stall_at_s =
        section.required_in_range<double>("master_stall_at_s", Bounds::closed(0, kMaxEventS));
    faults.at_location = section.location("master_stall_at_s");
    faults.master_stall_for_s = section.required_in_range<double>("master_stall_for_s", Bounds::open_closed(0, 60));
    faults.for_location = section.location("master_stall_for_s");
    return faults;
}

}  // namespace rig::harness
