// A controller's start-up as a follower (rig/runtime/follower.h), the parts
// that need no DDS: what --clock says and what it chooses. The start-up
// itself runs in tests/lockstep_test.cpp (its echo node starts with it).
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "rig/runtime/follower.h"

namespace {

TEST(Follower, ReadsTheTwoClockModesOfTheContract) {
    EXPECT_EQ(rig::clock_mode_from("lockstep"), rig::ClockMode::lockstep);
    EXPECT_EQ(rig::clock_mode_from("realtime"), rig::ClockMode::realtime);
}

TEST(Follower, RefusesAnyOtherClockModeNamingIt) {
    for (const char* text : {"", "Realtime", "real-time", "lockstep ", "wall"}) {
        try {
            rig::clock_mode_from(text);
            ADD_FAILURE() << "'" << text << "' was taken";
        } catch (const std::invalid_argument& error) {
            EXPECT_EQ(std::string(error.what()), "unknown clock mode '" + std::string(text) + "' (lockstep or realtime)");
        }
    }
}

// The timers each controller program chose by hand before run_follower did.
TEST(Follower, RepairsPromptlyOnTheWallClockAndWakesSeldomInLockstep) {
    EXPECT_EQ(rig::reliability_timers_for(rig::ClockMode::realtime), rig::ReliabilityTimers::prompt_repair);
    EXPECT_EQ(rig::reliability_timers_for(rig::ClockMode::lockstep), rig::ReliabilityTimers::few_wakeups);
}

// A follower that says nothing else runs in lockstep and, on the wall clock,
// asks for the priority the reference controllers always asked for.
TEST(Follower, StartsInLockstepAndAsksForPriority40OnTheWallClock) {
    const rig::FollowerStartup startup;
    EXPECT_EQ(startup.clock, rig::ClockMode::lockstep);
    ASSERT_TRUE(startup.realtime_priority.has_value());
    EXPECT_EQ(*startup.realtime_priority, 40);
}

}  // namespace
