#pragma once
// The real-time loop of one case run, seed 000's and seed 001's alike
// (defined in harness/case_runner.cpp, beside seed 000's lockstep loop): the
// local nodes (plant, device emulators, wire adapters) on the RealtimeMaster,
// the controller process as its remote node, the watchdog (stop signals, the
// wall-time bound, topic roles, unread wires), an external board's attach wait
// (harness/board_attach.h), and the rig's lateness against the case's
// `realtime:` bound (rig/runtime/lateness.h), which judge.cpp turns into an
// invalid verdict (rig_overloaded) when the rig itself kept time badly.
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/case_runner.h"
#include "harness/case_session.h"
#include "harness/trace_recorder.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/node.h"

namespace rig::harness {

// Runs `nodes` from case time 0 to end_ns on the wall clock; `now_ns` follows
// the case clock. `run_facts` gets the trace's meta `run` (controller mode,
// scheduling, emission jitter, lateness, board I/O), also when the run fails:
// throws what the run failed on (NodeFailure naming the node, mostly).
void run_case_in_realtime(const CaseSpec& spec, DdsContext& dds, const std::vector<Node*>& nodes, CaseSession& session,
                          TraceRecorder& trace, const WallStopwatch& wall, TimeNs end_ns, TimeNs& now_ns,
                          CaseClock* clock, nlohmann::json& run_facts);

}  // namespace rig::harness
