#include "harness/spec/realtime_spec.h"

#include <cstdio>
#include <string>

#include "harness/spec/case_spec.h"

namespace rig::harness {

LatenessBound read_realtime_section(const YamlSection& section) {
    LatenessBound bound;
    // Below 0.1 ms the kernel's own wake-up latency would count; above a second
    // nothing real-time is being judged any more.
    bound.late_after_ms =
        section.optional_in_range<double>("late_after_ms", bound.late_after_ms, Bounds::open_closed(0, 1000));
    bound.max_late_pct = section.optional_in_range<double>("max_late_pct", bound.max_late_pct, Bounds::closed(0, 100));
    bound.max_lateness_ms =
        section.optional_in_range<double>("max_lateness_ms", bound.max_lateness_ms, Bounds::closed(1, 60000));
    if (bound.max_lateness_ms < bound.late_after_ms) {
        char numbers[96];
        std::snprintf(numbers, sizeof numbers, "max_lateness_ms (%g ms) is below late_after_ms (%g ms)",
                      bound.max_lateness_ms, bound.late_after_ms);
        section.fail(section.has("max_lateness_ms") ? "max_lateness_ms" : "late_after_ms",
                     std::string(numbers) + ": an emission that late must already count as late");
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
