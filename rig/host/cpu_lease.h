#pragma once
// One CPU for a lockstep case (docs/speed.md). A lockstep round is a chain of
// hand-offs: the rig's thread writes the devices' samples and the tick, Fast
// DDS's receiving thread in the controller's process takes them and wakes the
// controller's thread, which answers through the rig's receiving thread to the
// rig's thread. Nothing in the chain runs in parallel with the rest. Spread over
// the machine's CPUs, each hand-off wakes a CPU that went idle (on this
// machine's virtual CPUs, a halted one: 61 us in one round of a perf scheduler
// trace, itself slowed by the tracing) and the woken thread often
// preempts its waker while the waker still holds the lock it wants. On one CPU,
// with SCHED_BATCH (no wake-up preemption: the woken thread runs when the
// waker blocks), a hand-off is a plain context switch. Measured with `rig
// bench` and the paper suite (docs/speed.md).
//
// A lease is an flock() on /tmp/rig-cpu-N.lock, held while the case runs, so
// that concurrent cases (--jobs, parallel ctest, two rig runs) take different
// CPUs; a case that finds none free runs unpinned, as before. A crashed holder
// frees its lease when the kernel closes its file.
#include <filesystem>
#include <optional>
#include <string>

namespace rig {

class CpuLease {
public:
    // With `pin`: leases a CPU among those this thread may run on that no other
    // case holds, pins this thread to it and gives it SCHED_BATCH. Threads and
    // processes it starts from now on (Fast DDS's, the controller's) inherit
    // both. When the thread may run on one CPU only, or every CPU is leased,
    // nothing changes and cpu() is empty. Without `pin`, nothing changes.
    // `lock_dir`: where the lease files are (a test's own folder; every rig
    // process uses /tmp). Never throws.
    explicit CpuLease(bool pin, const std::filesystem::path& lock_dir = "/tmp");
    ~CpuLease();  // this thread's CPUs and scheduling policy as they were; the lease freed
    CpuLease(const CpuLease&) = delete;
    CpuLease& operator=(const CpuLease&) = delete;

    std::optional<int> cpu() const { return cpu_; }
    // Why this thread was left unpinned (empty when pinned, or not asked to pin).
    const std::string& not_pinned_because() const { return not_pinned_because_; }

private:
    std::optional<int> cpu_;
    int fd_ = -1;
    std::string not_pinned_because_;
    struct Saved;
    Saved* saved_ = nullptr;  // the thread's CPUs and policy before the pin
};

// For a thread that a pinned case starts for work that should run beside it
// (rendering camera frames): back to the CPUs the process had before any lease,
// and to SCHED_OTHER. Nothing when no lease was ever taken.
void leave_leased_cpu();

// The calling thread's CPUs and scheduling policy, e.g. "CPU 1 of 2, SCHED_BATCH"
// or "CPUs 0-1 of 2, SCHED_OTHER, nice -10" (its nice value when not 0) (a run's facts).
std::string describe_thread_placement();

}  // namespace rig
