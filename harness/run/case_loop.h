#pragma once
// The loop of one run, in the case's time mode: its local nodes and its
// controller stepped in lockstep (virtual time, rig/runtime/lockstep.h) or on
// the wall clock (rig/runtime/realtime.h, for a board on real wires), every
// round's samples recorded, and everything no node reports checked between
// rounds and in every wait (a stop signal, the case's wall-time bound, topic
// roles seen in discovery or declared in a hello, forged samples, a bench
// wire nobody reads). Seed 000's and seed 001's runs alike.
#include <atomic>
#include <optional>
#include <string>

#include "harness/session/board_attach.h"
#include "harness/session/case_session.h"
#include "harness/spec/case_spec.h"
#include "harness/systems/system.h"
#include "harness/trace/run_facts.h"
#include "harness/trace/trace_recorder.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/dds_context.h"

namespace rig::harness {

// A running case's simulated time and its end, published by its runner for a
// progress display to read from another thread (0: not known yet).
struct CaseClock {
    std::atomic<TimeNs> now_ns{0};
    std::atomic<TimeNs> end_ns{0};
};

// Runs the case's loop to `end_ns` (lockstep or real time, as the case says),
// the time reached kept in `now_ns` (also when it throws), and what the run
// learnt about itself in `facts` (rounds, start-up, the real-time scheduling
// and lateness) and how a wired board attached in `board`. Throws NodeFailure
// naming the node that failed, or the rig itself; the controller process is
// the session's to end.
void run_loop(const CaseSpec& spec, DdsContext& dds, SystemNodes& nodes, CaseSession& session, TraceRecorder& trace,
              const WallStopwatch& wall, TimeNs end_ns, TimeNs& now_ns, RunFacts& facts,
              std::optional<BoardAttachment>& board, CaseClock* clock);

// "stopped by SIGINT", for the interrupted runs' errors.
std::string describe_signal(int signal);

}  // namespace rig::harness
