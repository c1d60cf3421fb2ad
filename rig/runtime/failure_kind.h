#pragma once
// Why a run could not go on (rig/runtime/lockstep.h throws them in NodeFailure). The
// names are part of the results contract (results.json `error_kind`, a case's
// `expect: { error: ... }`), so a case can say which failure a faulty
// controller must cause. No DDS here: case files are checked against the names.
#include <optional>
#include <string>
#include <string_view>

namespace rig {

enum class FailureKind {
    node_exited,           // the node's process ended (crash, exit) before the run did
    node_unresponsive,     // it did not acknowledge a tick within the bound
    node_fatal_error,      // it reported a fatal error in its acknowledgement
    startup_timeout,       // discovery, hello or endpoint matching not done in time
    delivery_timeout,      // samples it published did not arrive in time
    topic_role_violation,  // a process read or wrote a topic its role forbids (truth, device, clock)
    malformed_command,     // the plant got an actuator command it cannot act on (a duty per nozzle missing
                           // or extra, NaN, out of range; a section the boom lacks): docs/controller-contract.md
    wire_unread,           // a bench wire's far end never took what the rig wrote on it
    wall_time_exceeded,    // the case ran past its wall-time bound
    feedback_loop,         // nodes kept answering each other at one instant
    interrupted,           // SIGINT / SIGTERM stopped the run
    harness_error,         // the rig itself failed (a trace it cannot write, a bad wire...)
    board_not_attached,    // an external board did not attach to its wires within board.attach_timeout_s
    board_silent,          // the board's Modbus master sent no valid request for board.silence_timeout_s
    rig_overloaded,        // real time: the rig's own emissions passed the case's lateness bound (realtime:);
                           // the run is invalid, it cannot judge the controller (docs/metrics.md "Verdicts")
};
std::string_view to_string(FailureKind kind);
// True for the kinds that are the rig's own failure, not the controller's
// (interrupted, harness_error, rig_overloaded): such a run says nothing of the
// controller, and a search over cases must not count it for or against it.
bool is_rigs_own_failure(FailureKind kind);
// The kind with this name; nullopt for an unknown one.
std::optional<FailureKind> failure_kind_from_string(std::string_view name);
// Every kind, for validation messages ("one of: ...").
std::string failure_kind_names();

}  // namespace rig
