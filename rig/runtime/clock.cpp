#include "rig/runtime/clock.h"

#include <cerrno>
#include <ctime>
#include <stdexcept>
#include <string>

namespace rig {

ClockMode clock_mode_from(std::string_view text) {
    if (text == "lockstep") return ClockMode::lockstep;
    if (text == "realtime") return ClockMode::realtime;
    throw std::invalid_argument("unknown clock mode '" + std::string(text) + "' (lockstep or realtime)");
}

RealtimeClock::RealtimeClock() : start_(std::chrono::steady_clock::now()) {}

TimeNs RealtimeClock::now_ns() const {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start_).count();
}

TimeNs RealtimeClock::sleep_until_ns(TimeNs deadline_ns) const {
    // clock_nanosleep with TIMER_ABSTIME on CLOCK_MONOTONIC (what steady_clock uses on
    // Linux): an absolute deadline, restarted after signals without drifting.
    const auto start_since_epoch =
        std::chrono::duration_cast<std::chrono::nanoseconds>(start_.time_since_epoch()).count();
    const TimeNs absolute = start_since_epoch + deadline_ns;
    timespec ts{};
    ts.tv_sec = static_cast<time_t>(absolute / 1'000'000'000);
    ts.tv_nsec = static_cast<long>(absolute % 1'000'000'000);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
    const TimeNs late = now_ns() - deadline_ns;
    return late > 0 ? late : 0;
}

void RealtimeClock::restart() { start_ = std::chrono::steady_clock::now(); }

std::chrono::steady_clock::time_point RealtimeClock::steady_time(TimeNs t) const {
    return start_ + std::chrono::nanoseconds(t);
}

void pause_between_polls(std::chrono::milliseconds interval) {
    const RealtimeClock clock;
    clock.sleep_until_ns(std::chrono::duration_cast<std::chrono::nanoseconds>(interval).count());
}

WallStopwatch::WallStopwatch() : start_(std::chrono::steady_clock::now()) {}

double WallStopwatch::elapsed_s() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::chrono::milliseconds WallStopwatch::elapsed() const {
    return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start_);
}

std::string utc_date_time_now() { return utc_date_time_from_now(std::chrono::seconds(0)); }

std::string utc_date_time_from_now(std::chrono::seconds offset) {
    const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now() + offset);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &utc);
    return text;
}

}  // namespace rig
