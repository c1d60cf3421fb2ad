#include "rig/runtime/realtime.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <mutex>
#include <optional>
#include <iostream>

namespace rig {

namespace {

constexpr std::chrono::milliseconds kLivenessSlice{50};

}  // namespace

JitterStats summarize_lateness(std::vector<TimeNs> late_ns) {
    JitterStats stats;
    stats.samples = late_ns.size();
    if (late_ns.empty()) return stats;
    std::sort(late_ns.begin(), late_ns.end());
    auto rank = [&](double fraction) {
        const auto index = static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(late_ns.size()))) - 1;
        return static_cast<double>(late_ns[std::min(index, late_ns.size() - 1)]) * 1e-6;
    };
    stats.p50_ms = rank(0.50);
    stats.p99_ms = rank(0.99);
    stats.max_ms = static_cast<double>(late_ns.back()) * 1e-6;
    return stats;
}

SchedulingReport request_realtime_scheduling(int priority) {
    SchedulingReport report;
    prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
    sched_param param{};
    param.sched_priority = priority;
    if (sched_setscheduler(0, SCHED_FIFO, &param) == 0) {
        report.fifo = true;
        report.priority = priority;
        report.detail = "SCHED_FIFO " + std::to_string(priority);
    } else {
        report.detail = std::string("SCHED_OTHER (SCHED_FIFO refused: ") + std::strerror(errno) + ")";
    }
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
        report.memory_locked = true;
        report.detail += ", memory locked";
    } else {
        report.detail += std::string(", memory not locked (") + std::strerror(errno) + ")";
    }
    return report;
}

std::string raise_thread_to_realtime(std::thread& thread, int priority) {
    if (!thread.joinable()) return "no thread";
    sched_param param{};
    param.sched_priority = priority;
    const int error = pthread_setschedparam(thread.native_handle(), SCHED_FIFO, &param);
    return error == 0 ? std::string() : std::string("SCHED_FIFO refused: ") + std::strerror(error);
}

std::string drop_to_time_sharing(std::optional<int> nice) {
    sched_param param{};
    param.sched_priority = 0;
    if (const int error = pthread_setschedparam(pthread_self(), SCHED_OTHER, &param); error != 0) {
        return std::string("SCHED_OTHER refused: ") + std::strerror(error);
    }
    // On Linux a nice value belongs to the thread (its id), not the process.
    if (nice && setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), *nice) != 0) {
        return "nice " + std::to_string(*nice) + " refused: " + std::strerror(errno);
    }
    return {};
}

namespace {

// /proc/self/autogroup reads "/autogroup-140 nice 0"; writing a number sets the nice value.
constexpr const char* kAutogroupFile = "/proc/self/autogroup";

std::optional<int> autogroup_nice() {
    std::ifstream in(kAutogroupFile);
    std::string group;
    std::string word;
    int nice = 0;
    if (in >> group >> word >> nice && word == "nice") return nice;
    return std::nullopt;
}

bool set_autogroup_nice(int nice) {
    std::ofstream out(kAutogroupFile);
    out << nice;
    out.flush();
    return static_cast<bool>(out);
}

std::mutex session_weight_mutex;
int session_weight_holders = 0;  // guards alive that raised it
int session_nice_before = 0;

}  // namespace

SessionCpuWeight::SessionCpuWeight(int nice) {
    const std::lock_guard lock(session_weight_mutex);
    const std::optional<int> current = autogroup_nice();
    if (!current) {
        detail_ = std::string("no session autogroup (") + kAutogroupFile + " unreadable)";
        return;
    }
    if (session_weight_holders == 0) {
        if (!set_autogroup_nice(nice)) {
            detail_ = "session autogroup nice " + std::to_string(nice) + " refused (" + std::strerror(errno) +
                      "), left at " + std::to_string(*current);
            return;
        }
        session_nice_before = *current;
    }
    ++session_weight_holders;
    raised_ = true;
    detail_ = "session autogroup nice " + std::to_string(nice) + " (was " + std::to_string(session_nice_before) + ")";
}

SessionCpuWeight::~SessionCpuWeight() {
    if (!raised_) return;
    const std::lock_guard lock(session_weight_mutex);
    if (--session_weight_holders == 0) set_autogroup_nice(session_nice_before);
}

RealtimeMaster::RealtimeMaster(DdsContext& dds, LockstepTimeouts timeouts) : dds_(dds), remotes_(dds, timeouts) {}

RealtimeMaster::~RealtimeMaster() { shutdown(); }

void RealtimeMaster::add_local_node(Node& node) { locals_.push_back(Local{&node, 0, {}, {}}); }

void RealtimeMaster::add_remote_node(const std::string& name, std::function<std::optional<std::string>()> liveness) {
    remotes_.add_remote_node(name, std::move(liveness));
}

void RealtimeMaster::start() {
    for (Local& local : locals_) local.node->configure(dds_);
    // Hello and endpoint matching exactly as in lockstep (the remotes' master has
    // no local nodes of its own: ours are configured above, so their writers are
    // among those it waits for).
    remotes_.start();
    clock_.restart();
    remotes_.tick_remotes_at(0);  // every remote starts its clock now
    for (Local& local : locals_) local.node->activate(0);
    started_ = true;
}

void RealtimeMaster::run_until(TimeNs end_ns) {
    if (!started_) throw std::logic_error("RealtimeMaster::run_until before start");
    for (;;) {
        const std::uint64_t arrivals_seen = dds_.arrival_count();
        if (clock_.now_ns() >= stall_at_ns_) {
            stall_at_ns_ = kNever;
            clock_.sleep_until_ns(clock_.now_ns() + stall_for_ns_);
        }
        const TimeNs now = clock_.now_ns();
        if (now >= end_ns) return;
        for (TruthModel* model : truth_models_) model->advance_to(now);
        for (Local& local : locals_) {
            const bool due = local.next_wake_ns <= now;
            if (!due && !local.node->has_unread_input()) continue;
            // Late by when its step began: a long step of a node before it in
            // this pass delays its emission too.
            const TimeNs step_started_ns = clock_.now_ns();
            const bool counts_own = local.node->reports_own_emissions();
            // The wake at t = 0 follows the start-up (activation, the start tick): not scheduling jitter.
            if (due && !counts_own && local.next_wake_ns > 0) record_emission(local, local.next_wake_ns, step_started_ns);
            const TimeNs wake = local.node->step(now);
            local.next_wake_ns = due ? wake : std::min(local.next_wake_ns, wake);
            local.step_ns.push_back(clock_.now_ns() - step_started_ns);
            if (counts_own) {
                for (const TimeNs deadline_ns : local.node->take_emitted_deadlines()) {
                    if (deadline_ns > 0) record_emission(local, deadline_ns, step_started_ns);
                }
            }
        }
        if (after_step_) after_step_(now);
        remotes_.check_remotes_alive(now);
        if (watchdog_) watchdog_();

        TimeNs next = end_ns;
        bool input_pending = false;
        for (const Local& local : locals_) {
            next = std::min(next, local.next_wake_ns);
            input_pending |= local.node->has_unread_input();
        }
        if (input_pending) continue;
        // Sleep to the earliest deadline, but no longer than a liveness slice,
        // and wake at once when input arrives.
        const TimeNs wake = std::min(next, clock_.now_ns() + std::chrono::nanoseconds(kLivenessSlice).count());
        dds_.wait_for_arrival(arrivals_seen, clock_.steady_time(wake));
    }
}

void RealtimeMaster::record_emission(Local& local, TimeNs deadline_ns, TimeNs emitted_ns) {
    local.late_ns.push_back(std::max<TimeNs>(0, emitted_ns - deadline_ns));
    lateness_.record(local.node->name(), deadline_ns, emitted_ns);
}

void RealtimeMaster::shutdown(bool after_failure) noexcept {
    if (shut_down_) return;
    shut_down_ = true;
    remotes_.shutdown(after_failure);  // the shutdown tick; it has no local nodes to stop
    for (auto it = locals_.rbegin(); it != locals_.rend(); ++it) {
        try {
            it->node->shutdown();
        } catch (const std::exception& error) {
            std::cerr << "rig: shutting down node '" << it->node->name() << "': " << error.what() << "\n";
        }
    }
}

std::map<std::string, JitterStats> RealtimeMaster::emission_jitter() const {
    std::map<std::string, JitterStats> jitter;
    for (const Local& local : locals_) {
        JitterStats stats = summarize_lateness(local.late_ns);
        const JitterStats steps = summarize_lateness(local.step_ns);
        stats.step_p99_ms = steps.p99_ms;
        stats.step_max_ms = steps.max_ms;
        jitter[local.node->name()] = stats;
    }
    return jitter;
}

int run_realtime_follower(Node& node, DdsContext& dds, const FollowerOptions& options) {
    auto started = start_follower(node, dds, options);
    if (const int* exit_code = std::get_if<int>(&started)) return *exit_code;
    const std::unique_ptr<FollowerLink> link = std::move(std::get<std::unique_ptr<FollowerLink>>(started));

    // Until the start tick, only hellos are answered.
    const WallStopwatch waiting;
    std::optional<msg::ClockTick> start;
    while (!(start = link->next_tick(kLivenessSlice))) {
        if (waiting.elapsed() > options.idle_timeout) {
            std::cerr << options.node_name << ": no start from the harness for " << options.idle_timeout.count()
                      << " ms; exiting\n";
            return 4;
        }
    }
    if (start->shutdown()) {
        link->final_ack(start->seq(), "");
        return 0;
    }
    if (const std::string problem = link->wait_writers_reach_readers(*start); !problem.empty()) {
        link->final_ack(start->seq(), problem);
        std::cerr << options.node_name << ": " << problem << "\n";
        return 3;
    }
    RealtimeClock clock;
    TimeNs next_wake = 0;
    try {
        node.activate(0);
        next_wake = node.step(clock.now_ns());
    } catch (const std::exception& error) {
        link->final_ack(start->seq(), error.what());
        std::cerr << options.node_name << ": " << error.what() << "\n";
        return 2;
    }
    link->ack(start->seq(), next_wake, 0, "", "");

    WallStopwatch harness_missing;
    for (;;) {
        const std::uint64_t arrivals_seen = dds.arrival_count();
        if (const std::optional<msg::ClockTick> tick = link->next_tick(std::chrono::milliseconds(0))) {
            if (tick->shutdown()) {
                node.shutdown();
                link->final_ack(tick->seq(), "");
                return 0;
            }
            link->ack(tick->seq(), next_wake, 0, "", "");
        }
        const TimeNs now = clock.now_ns();
        try {
            if (next_wake <= now || node.has_unread_input()) next_wake = node.step(now);
        } catch (const std::exception& error) {
            std::cerr << options.node_name << ": " << error.what() << "\n";
            return 2;
        }
        if (link->harness_present()) {
            harness_missing = WallStopwatch();
        } else if (harness_missing.elapsed() > options.idle_timeout) {
            std::cerr << options.node_name << ": the harness is gone; exiting\n";
            return 4;
        }
        if (node.has_unread_input()) continue;
        const TimeNs wake = std::min(next_wake, clock.now_ns() + std::chrono::nanoseconds(kLivenessSlice).count());
        dds.wait_for_arrival(arrivals_seen, clock.steady_time(wake));
    }
}

}  // namespace rig
