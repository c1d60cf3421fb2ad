// Results computed ahead on a thread of their own (rig/runtime/work_ahead.h):
// in index order whoever asks, never more than `depth` held, and a failing
// index's exception at its take(). No clock: the worker is held and released
// by futures the test sets, so nothing depends on how fast the machine is.
#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <stdexcept>
#include <string>

#include "rig/runtime/work_ahead.h"

namespace {

TEST(WorkAhead, ResultsComeInIndexOrder) {
    rig::WorkAhead<std::string> ahead([](std::uint64_t k) { return "result " + std::to_string(k); }, 3);
    for (std::uint64_t k = 0; k < 20; ++k) {
        EXPECT_EQ(ahead.next_index(), k);
        EXPECT_EQ(ahead.take(), "result " + std::to_string(k));
    }
}

TEST(WorkAhead, NeverHoldsMoreThanItsDepth) {
    std::atomic<std::uint64_t> started{0};
    rig::WorkAhead<std::uint64_t> ahead(
        [&started](std::uint64_t k) {
            ++started;
            return k;
        },
        2);
    for (std::uint64_t taken = 0; taken < 50; ++taken) {
        ahead.wait_until_next_ready();
        // Started so far: those taken, those held (at most 2) and at most one more
        // that the last take made room for.
        EXPECT_LE(started.load(), taken + 2 + 1);
        EXPECT_EQ(ahead.take(), taken);
    }
}

TEST(WorkAhead, AResultNotComputedYetIsNotReadyAndOnReadySaysWhenItIs) {
    std::promise<void> release;
    std::shared_future<void> released = release.get_future().share();
    std::promise<void> ready_said;
    std::atomic<int> ready_calls{0};
    rig::WorkAhead<int> ahead(
        [released](std::uint64_t k) {
            if (k == 0) released.wait();
            return static_cast<int>(k);
        },
        1, {},
        [&] {
            if (ready_calls++ == 0) ready_said.set_value();
        });
    EXPECT_FALSE(ahead.next_ready());  // index 0 waits for the release
    release.set_value();
    ready_said.get_future().wait();
    EXPECT_TRUE(ahead.next_ready());
    EXPECT_EQ(ahead.take(), 0);
}

TEST(WorkAhead, AFailingIndexThrowsAtItsTakeAndNothingComesAfterIt) {
    rig::WorkAhead<int> ahead(
        [](std::uint64_t k) {
            if (k == 2) throw std::runtime_error("frame 2: boom height 7 m is outside (0, 5] m");
            return static_cast<int>(k);
        },
        4);
    EXPECT_EQ(ahead.take(), 0);
    EXPECT_EQ(ahead.take(), 1);
    try {
        ahead.take();
        FAIL() << "index 2 threw";
    } catch (const std::runtime_error& error) {
        EXPECT_STREQ(error.what(), "frame 2: boom height 7 m is outside (0, 5] m");
    }
    EXPECT_TRUE(ahead.next_ready());  // take() answers at once: with an error, not a wait
    EXPECT_THROW(ahead.take(), std::logic_error);
}

TEST(WorkAhead, ADepthOfZeroIsRefused) {
    EXPECT_THROW(rig::WorkAhead<int>([](std::uint64_t) { return 0; }, 0), std::invalid_argument);
}

}  // namespace
