// The thread-id cache (rig/runtime/thread_id_cache.h): the rig's `syscall`
// answers SYS_gettid with the kernel's own answer, per thread and in a forked
// child, and passes every other call through to libc's with its result and errno.
#include <gtest/gtest.h>

#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <set>
#include <thread>
#include <vector>

#include "rig/runtime/thread_id_cache.h"

namespace {

// The kernel's answer, not through `syscall` (glibc's gettid() calls it directly).
long kernel_thread_id() { return static_cast<long>(gettid()); }

TEST(ThreadIdCache, IsTheProgramsSyscall) { EXPECT_TRUE(rig::thread_id_cache_in_use()); }

TEST(ThreadIdCache, AnswersEachThreadWithItsOwnId) {
    EXPECT_EQ(syscall(SYS_gettid), kernel_thread_id());
    EXPECT_EQ(syscall(SYS_gettid), kernel_thread_id());  // from the cache now
    std::vector<long> answers(4), truth(4);
    std::vector<std::thread> threads;
    for (std::size_t i = 0; i < answers.size(); ++i) {
        threads.emplace_back([&, i] {
            answers[i] = syscall(SYS_gettid);
            truth[i] = kernel_thread_id();
            if (syscall(SYS_gettid) != answers[i]) answers[i] = -1;
        });
    }
    for (auto& thread : threads) thread.join();
    EXPECT_EQ(answers, truth);
    EXPECT_EQ(std::set<long>(answers.begin(), answers.end()).size(), answers.size());
    EXPECT_EQ(syscall(SYS_gettid), kernel_thread_id());
}

TEST(ThreadIdCache, AForkedChildGetsItsOwnId) {
    const long parent = syscall(SYS_gettid);  // cached in this thread before the fork
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        // Exit code 0 only if the child's answer is its own id, not the parent's.
        const long answer = syscall(SYS_gettid);
        _exit(answer == kernel_thread_id() && answer != parent ? 0 : 1);
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0);
}

TEST(ThreadIdCache, PassesOtherCallsThroughWithResultAndErrno) {
    EXPECT_EQ(syscall(SYS_getpid), static_cast<long>(getpid()));
    // Arguments reach the kernel: a write of 3 bytes to a pipe, read back.
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    EXPECT_EQ(syscall(SYS_write, fds[1], "abc", 3), 3);
    char buffer[4] = {};
    EXPECT_EQ(read(fds[0], buffer, sizeof buffer), 3);
    EXPECT_STREQ(buffer, "abc");
    close(fds[0]);
    close(fds[1]);
    // A failing call: -1 and libc's errno.
    errno = 0;
    EXPECT_EQ(syscall(SYS_close, -1), -1);
    EXPECT_EQ(errno, EBADF);
}

}  // namespace
