#include "rig/host/cpu_lease.h"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <mutex>
#include <vector>

#include "rig/host/lease_file.h"

namespace rig {

namespace {

std::vector<int> cpus_of(const cpu_set_t& set) {
    std::vector<int> cpus;
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
        if (CPU_ISSET(cpu, &set)) cpus.push_back(cpu);
    }
    return cpus;
}

// The CPUs a thread had before the first lease of this process: where threads
// that leave a leased CPU go (leave_leased_cpu).
std::mutex unpinned_mutex;
std::optional<cpu_set_t> unpinned_cpus;

std::string policy_name(int policy) {
    switch (policy) {
        case SCHED_OTHER: return "SCHED_OTHER";
        case SCHED_BATCH: return "SCHED_BATCH";
        case SCHED_IDLE: return "SCHED_IDLE";
        case SCHED_FIFO: return "SCHED_FIFO";
        case SCHED_RR: return "SCHED_RR";
        default: return "policy " + std::to_string(policy);
    }
}

// "3", "0-1", "0,2-3"
std::string cpu_list(const std::vector<int>& cpus) {
    std::string text;
    for (std::size_t i = 0; i < cpus.size();) {
        std::size_t j = i;
        while (j + 1 < cpus.size() && cpus[j + 1] == cpus[j] + 1) ++j;
        if (!text.empty()) text += ",";
        text += std::to_string(cpus[i]);
        if (j > i) text += "-" + std::to_string(cpus[j]);
        i = j + 1;
    }
    return text;
}

}  // namespace

struct CpuLease::Saved {
    cpu_set_t cpus;
    int policy = SCHED_OTHER;
    sched_param param{};
};

CpuLease::CpuLease(bool pin, const std::filesystem::path& lock_dir) {
    if (!pin) return;
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) {
        not_pinned_because_ = std::string("cannot read this thread's CPUs: ") + std::strerror(errno);
        return;
    }
    const std::vector<int> cpus = cpus_of(allowed);
    if (cpus.size() < 2) {
        not_pinned_because_ = "this thread may run on one CPU only";
        return;
    }
    auto saved = std::make_unique<Saved>();
    saved->cpus = allowed;
    if (pthread_getschedparam(pthread_self(), &saved->policy, &saved->param) != 0) {
        not_pinned_because_ = "cannot read this thread's scheduling policy";
        return;
    }
    if (saved->policy != SCHED_OTHER && saved->policy != SCHED_BATCH) {
        // A real-time or idle thread keeps what it was given.
        not_pinned_because_ = "this thread runs at " + policy_name(saved->policy);
        return;
    }
    for (int cpu : cpus) {
        const int fd = try_lease_file((lock_dir / ("rig-cpu-" + std::to_string(cpu) + ".lock")).string());
        if (fd < 0) continue;
        cpu_set_t one;
        CPU_ZERO(&one);
        CPU_SET(cpu, &one);
        {
            const std::lock_guard lock(unpinned_mutex);
            if (!unpinned_cpus) unpinned_cpus = allowed;
        }
        if (sched_setaffinity(0, sizeof one, &one) != 0) {
            not_pinned_because_ = std::string("cannot pin this thread: ") + std::strerror(errno);
            ::close(fd);
            return;
        }
        sched_param batch{};
        batch.sched_priority = 0;
        pthread_setschedparam(pthread_self(), SCHED_BATCH, &batch);  // pinned without it if refused
        cpu_ = cpu;
        fd_ = fd;
        saved_ = saved.release();
        return;
    }
    not_pinned_because_ = "every CPU of " + cpu_list(cpus) + " is leased by another case";
}

CpuLease::~CpuLease() {
    if (saved_ != nullptr) {
        sched_setaffinity(0, sizeof saved_->cpus, &saved_->cpus);
        pthread_setschedparam(pthread_self(), saved_->policy, &saved_->param);
        delete saved_;
    }
    if (fd_ >= 0) ::close(fd_);  // closing releases the flock
}

void leave_leased_cpu() {
    std::optional<cpu_set_t> cpus;
    {
        const std::lock_guard lock(unpinned_mutex);
        cpus = unpinned_cpus;
    }
    if (!cpus) return;
    sched_setaffinity(0, sizeof *cpus, &*cpus);
    int policy = SCHED_OTHER;
    sched_param param{};
    if (pthread_getschedparam(pthread_self(), &policy, &param) == 0 && policy == SCHED_BATCH) {
        param.sched_priority = 0;
        pthread_setschedparam(pthread_self(), SCHED_OTHER, &param);
    }
}

std::string describe_thread_placement() {
    cpu_set_t set;
    CPU_ZERO(&set);
    std::string text;
    if (sched_getaffinity(0, sizeof set, &set) == 0) {
        const std::vector<int> cpus = cpus_of(set);
        text = (cpus.size() == 1 ? "CPU " : "CPUs ") + cpu_list(cpus) + " of " +
               std::to_string(sysconf(_SC_NPROCESSORS_ONLN));
    } else {
        text = "CPUs unknown";
    }
    int policy = SCHED_OTHER;
    sched_param param{};
    if (pthread_getschedparam(pthread_self(), &policy, &param) == 0) text += ", " + policy_name(policy);
    errno = 0;
    const int nice = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));  // -1 is also a nice value: errno tells
    if (errno == 0 && nice != 0) text += ", nice " + std::to_string(nice);
    return text;
}

}  // namespace rig
