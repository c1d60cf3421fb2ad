#pragma once
// What a run learnt about itself (the trace's meta `run`, docs/trace-format.md;
// results.json echoes it): where the controller ran, how long start-up and
// stepping took, real-time scheduling and lateness, the board wire's counts,
// and what the case's system adds. harness/run writes it, the judge reads it:
// this is the one place its keys are named.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rig::harness {

// How late one device's emissions were against their deadlines in a real-time run.
struct EmissionJitter {
    std::string device;
    std::size_t samples = 0;
    double p50_ms = 0.0;
    double p99_ms = 0.0;
    double max_ms = 0.0;
    double step_p99_ms = 0.0;   // the device's own step (update) durations
    double step_max_ms = 0.0;
};

struct RunFacts {
    double wall_seconds = 0.0;
    std::string controller_mode;     // process, in_process, external
    std::string in_process_refused;  // asked for in process, ran as a process: why
    double startup_wall_seconds = 0.0;
    // Lockstep: simulated instants processed and rounds run (a round: the local
    // nodes, then one tick to the controller and its answer), and the wall time
    // from the end of start-up to the last instant (rig bench's per-round cost).
    std::uint64_t instants = 0;
    std::uint64_t rounds = 0;
    double stepping_wall_seconds = 0.0;
    std::string realtime_scheduling;
    std::string cpu_placement;  // rig/host/cpu_lease.h describe_thread_placement()
    std::vector<EmissionJitter> emission_jitter;
    nlohmann::json lateness;  // real time: the rig's own lateness against the case's bound; null in lockstep
    nlohmann::json board_io;  // a Modbus wire's frame counts (harness/session/board_attach.h); null without one
    // The system's own facts (seed 001: the frames each camera rendered, the
    // duty commands a wired board's PWM capture published), kept as written; an object.
    nlohmann::json system = nlohmann::json::object();
};

nlohmann::json to_json(const RunFacts& facts);
// Tolerates keys a trace from an earlier rig lacks (their defaults), keeps
// keys it does not know in `system`. Throws std::runtime_error for a value of
// the wrong type.
RunFacts run_facts_from_json(const nlohmann::json& json);

}  // namespace rig::harness
