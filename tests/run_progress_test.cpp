// What `rig run` shows while it runs (harness/run/run_progress.h), without DDS:
// the status line's wording, the estimate of what is left, the terminal
// progress's lines and clock, and when colour is wanted (a terminal, no NO_COLOR).
#include "harness/run/run_progress.h"

#include <gtest/gtest.h>
#include <pty.h>
#include <unistd.h>

#include <cstdlib>
#include <regex>
#include <sstream>

namespace rig::harness {
namespace {

TEST(ProgressStatusLine, ShowsTheRunningCaseItsNumberItsClockAndTheEstimate) {
    ProgressSnapshot snapshot;
    snapshot.total = 12;
    snapshot.finished = 2;
    snapshot.running.push_back({"continuation-6kmh-wired-rtu", 3, 14.0, 12.34, 50.0, true});
    snapshot.running.push_back({"table2-20lmin-opening93", 4, 1.0, 0.0, 0.0, false});
    snapshot.elapsed_s = 41.0;
    snapshot.left_s = 80.0;
    EXPECT_EQ(progress_status_line(snapshot, 200),
              "rig: [3/12] continuation-6kmh-wired-rtu (real time) t 12.3/50.0 s (+1 running) | 0:41 elapsed, about "
              "1:20 left");
    // Before the case has published its clock: its wall time so far.
    snapshot.running.resize(1);
    snapshot.running[0].clock_s = 0.0;
    snapshot.left_s.reset();
    EXPECT_EQ(progress_status_line(snapshot, 200),
              "rig: [3/12] continuation-6kmh-wired-rtu (real time) 0:14 | 0:41 elapsed, no estimate yet");
    // Between cases; hours; cut to the terminal's width.
    snapshot.running.clear();
    snapshot.elapsed_s = 3723.0;
    EXPECT_EQ(progress_status_line(snapshot, 200), "rig: 2/12 done | 1:02:03 elapsed, no estimate yet");
    EXPECT_EQ(progress_status_line(snapshot, 16), "rig: 2/12 done |");
}

TEST(EstimateSecondsLeft, LockstepCasesShareTheJobsAndRealTimeCasesLastTheirLength) {
    const std::vector<double> lockstep_walls = {1.0, 3.0};  // a mean of 2 s
    const std::vector<CaseToCome> three_lockstep(3, CaseToCome{});
    EXPECT_DOUBLE_EQ(*estimate_seconds_left(three_lockstep, lockstep_walls, {}, 1), 6.0);
    EXPECT_DOUBLE_EQ(*estimate_seconds_left(three_lockstep, lockstep_walls, {}, 2), 3.0);
    // A running lockstep case has done part of its mean.
    std::vector<CaseToCome> one_running = {CaseToCome{false, true, 1.5, 0.0, 0.0}};
    EXPECT_DOUBLE_EQ(*estimate_seconds_left(one_running, lockstep_walls, {}, 2), 0.5);
    // A real-time case on its clock: 30 s of its 50 s left, whatever lockstep took.
    const std::vector<CaseToCome> realtime = {CaseToCome{true, true, 21.0, 20.0, 50.0}};
    EXPECT_DOUBLE_EQ(*estimate_seconds_left(realtime, {}, {}, 2), 30.0);
    // Nothing to go by: no estimate.
    EXPECT_FALSE(estimate_seconds_left(three_lockstep, {}, {}, 1).has_value());
    EXPECT_FALSE(estimate_seconds_left({CaseToCome{true, false, 0.0, 0.0, 0.0}}, lockstep_walls, {}, 1).has_value());
    // A real-time case of unknown length goes by the real-time cases that ran.
    EXPECT_DOUBLE_EQ(*estimate_seconds_left({CaseToCome{true, false, 0.0, 0.0, 0.0}}, {}, {40.0}, 1), 40.0);
}

CaseSpec lockstep_spec() {
    CaseSpec spec;
    spec.mode = ClockMode::lockstep;
    spec.source_path = "cases/suite/a.yaml";
    return spec;
}

CaseResult passed(const std::string& name) {
    CaseResult result;
    result.name = name;
    result.passed = true;
    result.wall_seconds = 2.0;
    return result;
}

// Lines for ended cases scroll above; the status line is redrawn in place
// (carriage return, spaces over a longer old line) and cleared at the end.
TEST(TerminalProgress, KeepsTheStatusLineBelowTheCasesLinesAndClearsIt) {
    std::ostringstream out;
    {
        // No redraws on a timer: what is drawn follows the calls alone.
        TerminalProgress progress(out, Verbosity::normal, 2, 100, /*redraw_on_timer=*/false);
        progress.runs_planned({{0, 5, "first"}, {0, 6, "second"}}, {lockstep_spec()});
        progress.case_started(0);
        // The first case publishes its clock; the second starts, and the line shows the first's clock.
        CaseClock* clock = progress.case_clock(0);
        ASSERT_NE(clock, nullptr);
        clock->end_ns = 22'000'000'000;
        clock->now_ns = 10'900'000'000;
        progress.case_started(1);
        EXPECT_TRUE(std::regex_search(
            out.str(), std::regex(R"(\rrig: \[1/2\] first t 10\.9/22\.0 s \(\+1 running\) \| \d:\d\d elapsed, no estimate yet)")))
            << out.str();
        progress.case_finished(0, passed("first"));
        EXPECT_NE(out.str().find("\rrig: [PASS] first (2 s wall)\n"), std::string::npos) << out.str();
        // One case ran (2 s), the other is running: an estimate now.
        EXPECT_TRUE(std::regex_search(
            out.str(), std::regex(R"(\rrig: \[2/2\] second \d:\d\d \| \d:\d\d elapsed, about 0:0[0-2] left)")))
            << out.str();
        progress.case_finished(1, passed("second"));
        progress.finish();
    }
    const std::string text = out.str();
    // Cleared at the end: the last thing written is a carriage return after blanks.
    ASSERT_FALSE(text.empty());
    EXPECT_EQ(text.back(), '\r');
    EXPECT_EQ(text.find('\033'), std::string::npos) << "no escape sequences: NO_COLOR has nothing to turn off here";
}

TEST(CaseLineLog, SaysOneLinePerCaseMoreWhenVerboseNothingWhenQuiet) {
    const std::vector<CaseInstance> runs = {{0, 5, "first"}};
    const std::vector<CaseSpec> specs = {lockstep_spec()};
    std::ostringstream normal, verbose, quiet;
    for (auto [out, verbosity] : {std::pair{&normal, Verbosity::normal}, std::pair{&verbose, Verbosity::verbose},
                                  std::pair{&quiet, Verbosity::quiet}}) {
        CaseLineLog log(*out, verbosity);
        log.runs_planned(runs, specs);
        log.case_started(0);
        log.case_finished(0, passed("first"));
    }
    EXPECT_EQ(normal.str(), "rig: [PASS] first (2 s wall)\n");
    EXPECT_EQ(verbose.str(), "rig: start first (seed 5, lockstep, cases/suite/a.yaml)\nrig: [PASS] first (2 s wall)\n");
    EXPECT_EQ(quiet.str(), "");
}

// https://no-color.org: set and not empty means no colour; a pipe never gets colour.
TEST(ColourWanted, OnATerminalUnlessNoColorIsSet) {
    int master = -1, terminal = -1;
    ASSERT_EQ(openpty(&master, &terminal, nullptr, nullptr, nullptr), 0);
    int pipe_ends[2];
    ASSERT_EQ(pipe(pipe_ends), 0);
    const char* before = std::getenv("NO_COLOR");
    const std::string saved = before ? before : "";
    ::unsetenv("NO_COLOR");
    EXPECT_TRUE(colour_wanted(terminal));
    EXPECT_FALSE(colour_wanted(pipe_ends[1]));
    ::setenv("NO_COLOR", "1", 1);
    EXPECT_FALSE(colour_wanted(terminal));
    ::setenv("NO_COLOR", "", 1);
    EXPECT_TRUE(colour_wanted(terminal));
    if (before) {
        ::setenv("NO_COLOR", saved.c_str(), 1);
    } else {
        ::unsetenv("NO_COLOR");
    }
    for (int fd : {master, terminal, pipe_ends[0], pipe_ends[1]}) ::close(fd);
}

}  // namespace
}  // namespace rig::harness
