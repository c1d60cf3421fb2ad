// CPU leases (rig/host/cpu_lease.h): a lockstep case's thread pinned to one
// free CPU at SCHED_BATCH, inherited by the threads and processes it starts,
// never two leases on one CPU, everything as it was afterwards. Each test leases
// from a folder of its own, so the rig runs of other tests (ctest -j) do not
// take its CPUs.
#include <gtest/gtest.h>

#include <pthread.h>
#include <sched.h>
#include <sys/wait.h>
#include <unistd.h>

#include <condition_variable>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <vector>

#include "rig/host/cpu_lease.h"
#include "run_support.h"

namespace {

using rig::CpuLease;

int allowed_cpu_count() {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) != 0) return 0;
    return CPU_COUNT(&set);
}

std::set<int> this_thread_cpus() {
    cpu_set_t set;
    CPU_ZERO(&set);
    std::set<int> cpus;
    if (sched_getaffinity(0, sizeof set, &set) != 0) return cpus;
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
        if (CPU_ISSET(cpu, &set)) cpus.insert(cpu);
    }
    return cpus;
}

int this_thread_policy() {
    int policy = -1;
    sched_param param{};
    pthread_getschedparam(pthread_self(), &policy, &param);
    return policy;
}

TEST(CpuLease, PinsThisThreadAtBatchAndRestoresItAfterwards) {
    if (allowed_cpu_count() < 2) GTEST_SKIP() << "this test runs on one CPU: there is nothing to choose";
    const std::filesystem::path locks = rig::testing::fresh_dir("cpu_lease_pin");
    const std::set<int> before = this_thread_cpus();
    const int policy_before = this_thread_policy();
    {
        const CpuLease lease(true, locks);
        ASSERT_TRUE(lease.cpu().has_value()) << lease.not_pinned_because();
        EXPECT_TRUE(lease.not_pinned_because().empty());
        EXPECT_EQ(this_thread_cpus(), std::set<int>{*lease.cpu()});
        EXPECT_EQ(this_thread_policy(), SCHED_BATCH);
        EXPECT_NE(rig::describe_thread_placement().find("CPU " + std::to_string(*lease.cpu()) + " of"), std::string::npos)
            << rig::describe_thread_placement();
        EXPECT_NE(rig::describe_thread_placement().find("SCHED_BATCH"), std::string::npos);

        // A thread started now inherits both (Fast DDS's threads do).
        std::set<int> thread_cpus;
        int thread_policy = -1;
        std::thread([&] {
            thread_cpus = this_thread_cpus();
            thread_policy = this_thread_policy();
        }).join();
        EXPECT_EQ(thread_cpus, std::set<int>{*lease.cpu()});
        EXPECT_EQ(thread_policy, SCHED_BATCH);

        // So does a process started now (the controller): exit 0 only if so.
        const pid_t child = fork();
        ASSERT_GE(child, 0);
        if (child == 0) {
            const bool inherited = this_thread_cpus() == std::set<int>{*lease.cpu()} && sched_getscheduler(0) == SCHED_BATCH;
            _exit(inherited ? 0 : 1);
        }
        int status = 0;
        ASSERT_EQ(waitpid(child, &status, 0), child);
        EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);

        // A thread that leaves the leased CPU (a camera's renderer) gets the CPUs back.
        std::set<int> left_cpus;
        int left_policy = -1;
        std::thread([&] {
            rig::leave_leased_cpu();
            left_cpus = this_thread_cpus();
            left_policy = this_thread_policy();
        }).join();
        EXPECT_EQ(left_cpus, before);
        EXPECT_EQ(left_policy, SCHED_OTHER);
    }
    EXPECT_EQ(this_thread_cpus(), before);
    EXPECT_EQ(this_thread_policy(), policy_before);
}

TEST(CpuLease, NeverGivesOneCpuTwiceAndSaysWhenNoneIsLeft) {
    const int cpus = allowed_cpu_count();
    if (cpus < 2) GTEST_SKIP() << "this test runs on one CPU";
    const std::filesystem::path locks = rig::testing::fresh_dir("cpu_lease_all");
    // One lease per CPU, each on a thread of its own and held until all are
    // taken; then one more, which finds none.
    std::vector<std::optional<int>> taken(static_cast<std::size_t>(cpus));
    std::mutex mutex;
    std::condition_variable all_taken;
    int count = 0;
    bool release = false;
    std::vector<std::thread> holders;
    for (int i = 0; i < cpus; ++i) {
        holders.emplace_back([&, i] {
            const CpuLease lease(true, locks);
            std::unique_lock lock(mutex);
            taken[static_cast<std::size_t>(i)] = lease.cpu();
            ++count;
            all_taken.notify_all();
            all_taken.wait(lock, [&] { return release; });
        });
    }
    {
        std::unique_lock lock(mutex);
        all_taken.wait(lock, [&] { return count == cpus; });
    }
    std::set<int> distinct;
    for (const auto& cpu : taken) {
        ASSERT_TRUE(cpu.has_value());
        distinct.insert(*cpu);
    }
    EXPECT_EQ(static_cast<int>(distinct.size()), cpus);

    const std::set<int> before = this_thread_cpus();
    {
        const CpuLease none_left(true, locks);
        EXPECT_FALSE(none_left.cpu().has_value());
        EXPECT_NE(none_left.not_pinned_because().find("leased by another case"), std::string::npos)
            << none_left.not_pinned_because();
        EXPECT_EQ(this_thread_cpus(), before);  // left as it was
    }
    {
        std::lock_guard lock(mutex);
        release = true;
    }
    all_taken.notify_all();
    for (auto& holder : holders) holder.join();

    // Released with their holders: a new lease finds a CPU again.
    const CpuLease again(true, locks);
    EXPECT_TRUE(again.cpu().has_value()) << again.not_pinned_because();
}

TEST(CpuLease, WithoutPinNothingChanges) {
    const std::filesystem::path locks = rig::testing::fresh_dir("cpu_lease_off");
    const std::set<int> before = this_thread_cpus();
    const int policy_before = this_thread_policy();
    {
        const CpuLease lease(false, locks);
        EXPECT_FALSE(lease.cpu().has_value());
        EXPECT_EQ(this_thread_cpus(), before);
        EXPECT_EQ(this_thread_policy(), policy_before);
    }
    EXPECT_TRUE(std::filesystem::is_empty(locks));  // not even a lock file
}

}  // namespace
