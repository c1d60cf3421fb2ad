#pragma once
// A real-time case's `realtime:` and `rig_faults:` sections (docs/metrics.md
// "Verdicts"): the bound on the rig's own emission lateness past which the run
// is invalid (rig overloaded) instead of a verdict on the controller, and the
// self-test fault that proves the bound is watched. Parsed with the case file;
// no DDS and no I/O here, so the fuzzed case-file loader links it.
//
//   mode: realtime
//   realtime:
//     late_after_ms: 10        # an emission this much past its deadline is late
//     max_late_pct: 1          # more late emissions than this share: invalid
//     max_lateness_ms: 100     # any one emission later than this: invalid
//     devices:                 # a device judged by limits of its own (by node name);
//       camera_left: { late_after_ms: 85, max_lateness_ms: 85 }   # keys left out: the above
//   rig_faults:                # self-test only: never in a case that judges a controller
//     master_stall_at_s: 3     # the rig's real-time loop stops stepping at this case time ...
//     master_stall_for_s: 0.5  # ... for this long
#include <optional>

#include "rig/config/yaml_fields.h"
#include "rig/runtime/lateness.h"

namespace rig::harness {

// `realtime:`: defaults, their reasons and units in rig/runtime/lateness.h.
LatenessBound read_realtime_section(const YamlSection& section);

// `rig_faults:`: faults of the rig itself, to show that the overload
// detection works (tests/whole_run_test.cpp); a case with them judges the rig,
// not a controller.
struct RigFaultsSpec {
    // The RealtimeMaster blocks once, at the first pass at or after this case
    // time, as a machine that took the rig's CPU away would; [0, kMaxEventS] s,
    // within the case (check_case_timeline).
    double master_stall_at_s = 0.0;
    // For this long: (0, 60] s (a minute of lost time is overload enough).
    double master_stall_for_s = 0.0;
    SourceLocation at_location;
    SourceLocation for_location;
};
// Empty when the section is absent; both keys are required when it is given.
std::optional<RigFaultsSpec> read_rig_faults(const YamlSection& section);

}  // namespace rig::harness
