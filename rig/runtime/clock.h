#pragma once
// The one time abstraction every node uses (docs/design.md "Time"). Nothing outside
// rig/ reads the wall clock or sleeps: nodes get the time from a Clock, and in
// lockstep the harness decides what time it is.
#include <chrono>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

namespace rig {

// Simulated (or real) time since case start, in nanoseconds.
using TimeNs = std::int64_t;
inline constexpr TimeNs kNever = std::numeric_limits<TimeNs>::max();
constexpr TimeNs seconds_to_ns(double s) { return static_cast<TimeNs>(s * 1e9 + (s >= 0 ? 0.5 : -0.5)); }
constexpr double ns_to_seconds(TimeNs t) { return static_cast<double>(t) * 1e-9; }

// The first multiple of period_ns strictly after now_ns: the next wake of a node
// that runs on a fixed grid (every sample of a 100 Hz device lands on k x 10 ms,
// whenever the node happened to be woken).
constexpr TimeNs next_period_boundary(TimeNs now_ns, TimeNs period_ns) { return (now_ns / period_ns + 1) * period_ns; }

// What a case's `mode:` and the controller contract's --clock say: step when
// the rig's tick says (virtual time), or run on the wall clock from the rig's
// start tick.
enum class ClockMode { lockstep, realtime };

// "lockstep" or "realtime"; anything else throws std::invalid_argument
// naming the text and the two choices.
ClockMode clock_mode_from(std::string_view text);

class Clock {
public:
    virtual ~Clock() = default;
    virtual TimeNs now_ns() const = 0;
};

// Lockstep: time only moves when the harness's tick says so.
class ManualClock final : public Clock {
public:
    TimeNs now_ns() const override { return now_ns_; }
    void set_ns(TimeNs t) { now_ns_ = t; }

private:
    TimeNs now_ns_ = 0;
};

// Real time: the wall (monotonic) clock since construction, with absolute-deadline
// waits so a periodic loop does not drift by its own processing time.
class RealtimeClock final : public Clock {
public:
    RealtimeClock();
    TimeNs now_ns() const override;
    // Blocks until now_ns() >= deadline_ns (returns at once if already past).
    // Returns how late the wake-up was, in ns (>= 0).
    TimeNs sleep_until_ns(TimeNs deadline_ns) const;
    // Time zero is now (a run starts its clock once every node is ready).
    void restart();
    // The monotonic instant of `t` on this clock, for waits with a deadline.
    std::chrono::steady_clock::time_point steady_time(TimeNs t) const;

private:
    std::chrono::steady_clock::time_point start_;
};

// Wall-clock stopwatch for bounds that must hold in real time even in lockstep
// (a node that stops answering, a run that must end): never used for simulated time.
class WallStopwatch {
public:
    WallStopwatch();
    double elapsed_s() const;
    std::chrono::milliseconds elapsed() const;

private:
    std::chrono::steady_clock::time_point start_;
};

// A wall-time pause between two polls of something that signals no event (a
// discovery record, a pty's far end being opened): start-up and bench waits,
// never inside a lockstep round. Outside rig/, this is the way to wait.
void pause_between_polls(std::chrono::milliseconds interval);

// Today's date and time in UTC as "2026-11-24T12:05:09" (ISO 8601 without a
// zone, the form JUnit XML's timestamp takes): a label for a run's reports,
// never an input to it.
std::string utc_date_time_now();
// The same, `offset` from now (e.g. a certificate's validity window for the
// run's DDS-Security credentials): a label outside the trace, never an input to it.
std::string utc_date_time_from_now(std::chrono::seconds offset);

}  // namespace rig
