// The judge on hand-made traces (harness/judge/judge_trace.h, harness/trace/trace_file.h): a
// trace written row by row, without DDS or a plant, then read back and judged
// as `rig judge` does. Each test builds the trace of a controller behaviour the
// judge must not be fooled by, and checks the verdict names the right metric or
// error:
//  * never resumes after the breakpoint: missed = the span after it;
//  * never sprays: missed = the whole strip;
//  * flickering sections: the flow never settles (no small adjust time);
//  * a truth reader, a truth forger: the case fails naming topic and participant;
//  * a killed controller: the trace keeps its samples, the error its kind;
//  * a trace edited after its run, or not a trace at all: refused, not judged;
//  * a trace write that failed (a full disk): finish() names the failure.
#include <gtest/gtest.h>

#include "run_support.h"

#include <sqlite3.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "emulators/deposition_grid.h"
#include "harness/judge/verdict.h"
#include "harness/systems/breakpoint/breakpoint_judge.h"
#include "harness/systems/breakpoint/breakpoint_world.h"
#include "harness/systems/systems.h"
#include "harness/trace/topic_roles.h"
#include "harness/trace/trace_file.h"
#include "harness/trace/trace_json.h"
#include "harness/trace/trace_reader.h"
#include "idl/topics.h"

namespace {

namespace fs = std::filesystem;
using rig::TimeNs;
namespace msg = rig::msg;
using namespace rig::harness;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kS = 1'000'000'000;
constexpr double kNominal = 20.0 / 60.0 / (6.0 / 3.6 * 12.2) * 100.0;  // 20 L/min, 6 km/h, 12.2 m: uL/cm^2

// A continuation at 6 km/h with the breakpoint at 0: the first pass from -25 m,
// the continuation pass (pass 1) from 30 s, the strip -24..+9 m.
BreakpointJudgingPlan continuation_plan() {
    BreakpointJudgingPlan plan;
    plan.scenario = "breakpoint_continuation";
    plan.breakpoint_along_m = 0.0;
    plan.field_origin_lat_deg = 40.18;
    plan.field_origin_lon_deg = 116.44;
    plan.field_heading_deg = 90.0;
    plan.judge_breakpoint = true;
    plan.judge_flow = true;
    plan.flow = FlowJudging{20.0, 3.0, 1.7};
    plan.flow_window = FlowWindow{30 * kS, 55 * kS};
    plan.judge_deposition = true;
    plan.deposition.nominal_dose_ul_cm2 = kNominal;
    plan.deposition.strip_from_m = -24.0;
    plan.deposition.strip_to_m = 9.0;
    plan.limits = {{"breakpoint_error_m", 0.2}, {"flow_adjust_time_s", 1.7}, {"flow_error_pct", 3.0},
                   {"overlap_m", 3.3},          {"missed_m", 0.0}};
    return plan;
}

// A trace file being written by hand.
class HandMadeTrace {
public:
    HandMadeTrace(const std::string& name, const BreakpointJudgingPlan& plan)
        : dir_(rig::testing::fresh_dir("judge-" + name)), trace_(dir_ / "trace.sqlite") {
        trace_.set_meta("case", name);
        trace_.set_meta("case_file", "hand-made/" + name + ".yaml");
        trace_.set_meta("seed", "1");
        trace_.set_meta("mode", "lockstep");
        trace_.set_meta("judging", to_json(plan).dump());
    }
    TraceFile& trace() { return trace_; }
    fs::path path() const { return dir_ / "trace.sqlite"; }

    // The vehicle: nozzle line along the track at 6 km/h, the first pass from
    // -25 m at 0 s to the breakpoint, the continuation from -8 m at 30 s.
    void drive() {
        for (TimeNs t = 0; t <= 60 * kS; t += 50 * kMs) {
            const double t_s = rig::ns_to_seconds(t);
            const bool second = t >= 30 * kS;
            const double along_m = second ? -8.0 + (t_s - 30.0) * 6.0 / 3.6 : std::min(0.0, -25.0 + t_s * 6.0 / 3.6);
            trace_.append(t, 0, rig::topics::kVehicleTruth,
                          {{"nozzle_line_along_m", along_m}, {"pass_index", second ? 1 : 0}, {"cross_m", 0.0}});
        }
    }
    // Section commands, and the hydraulics truth every 10 ms from 25 s to 60 s.
    void section_command(TimeNs t, int mask) {
        trace_.append(t, 0, rig::topics::kSectionValves, {{"open_mask", mask}});
    }
    void hydraulics(const std::function<double(TimeNs)>& flow, const std::function<bool(TimeNs)>& spraying) {
        for (TimeNs t = 25 * kS; t < 60 * kS; t += 10 * kMs) {
            trace_.append(t, 0, rig::topics::kHydraulicsTruth,
                          {{"main_flow_l_min", flow(t)}, {"sections_spraying_mask", spraying(t) ? 7 : 0}});
        }
    }
    void breakpoint_reached(TimeNs t) {
        trace_.append(t, 0, rig::topics::kBreakpointEvent, {{"kind", "reached"}, {"lat_deg", nullptr}, {"lon_deg", nullptr}});
    }
    // The nominal dose on every row of [from_m, to_m) in `pass`.
    void spray(int pass, double from_m, double to_m) {
        for (double along_m = from_m + 0.025; along_m < to_m; along_m += 0.05) {
            for (int nozzle = 0; nozzle < 22; ++nozzle) {
                grid_.deposit(pass, nozzle, along_m, kNominal * cell_area_cm2() / 1e6);
            }
        }
    }
    void finish(const TraceOutcome& outcome = TraceOutcome{"completed", "", "", 60 * kS}) {
        grid_.deposit(1, 0, -44.0, 0.0);  // both passes exist in the grid
        record_deposition(trace_, grid_);
        trace_.finish(outcome);
    }
    CaseRun judged() { return judge_trace(read_trace(path())); }

private:
    static rig::emulators::DepositionGridParams grid_params() {
        rig::emulators::DepositionGridParams params;
        params.from_along_m = -45.0;
        params.to_along_m = 15.0;
        params.cell_along_m = 0.05;
        params.footprint_along_m = 0.05;  // one cell: the dose lands where it is put
        return params;
    }
    static double cell_area_cm2() { return 5.0 * 12.2 / 22.0 * 100.0; }

    fs::path dir_;
    TraceFile trace_;
    rig::emulators::DepositionGrid grid_{grid_params()};
};

bool has_failure_starting(const CaseResult& result, const std::string& prefix) {
    for (const std::string& failure : result.failures) {
        if (failure.rfind(prefix, 0) == 0) return true;
    }
    return false;
}

TEST(Judge, NeverResumingMissesTheWholeSpanAfterTheBreakpoint) {
    HandMadeTrace made("never-resumes", continuation_plan());
    made.drive();
    made.section_command(0, 0);
    made.breakpoint_reached(35 * kS);
    made.hydraulics([](TimeNs) { return 0.0; }, [](TimeNs) { return false; });
    made.spray(0, -24.5, 0.0);  // the first pass up to the breakpoint, then nothing
    made.finish();
    const CaseResult result = made.judged().result;
    EXPECT_FALSE(result.passed);
    EXPECT_NEAR(result.metrics.at("missed_m"), 9.0, 1e-9) << "from the breakpoint to the strip's end";
    EXPECT_TRUE(has_failure_starting(result, "missed_m 9 > 0")) << testing::PrintToString(result.failures);
    EXPECT_TRUE(has_failure_starting(result, "flow_adjust_time_s not measured: never settled: the sections never opened"))
        << testing::PrintToString(result.failures);
}

TEST(Judge, NeverSprayingMissesTheWholeStrip) {
    HandMadeTrace made("never-sprays", continuation_plan());
    made.drive();
    made.section_command(0, 0);
    made.hydraulics([](TimeNs) { return 0.0; }, [](TimeNs) { return false; });
    made.finish();
    const CaseResult result = made.judged().result;
    EXPECT_FALSE(result.passed);
    EXPECT_NEAR(result.metrics.at("missed_m"), 33.0, 1e-9);
    EXPECT_EQ(result.metrics.at("overlap_m"), 0.0);
    EXPECT_TRUE(has_failure_starting(result, "breakpoint_error_m not measured: never declared"))
        << testing::PrintToString(result.failures);
}

TEST(Judge, FlickeringSectionsNeverSettleAndGetNoSmallAdjustTime) {
    BreakpointJudgingPlan plan = continuation_plan();
    plan.judge_deposition = false;
    HandMadeTrace made("flicker", plan);
    made.drive();
    made.section_command(0, 0);
    // Open at 40 s; shut for 50 ms every 0.5 s after (the valves follow 0.2 s
    // later and the line refills over 0.8 s each time).
    made.section_command(40 * kS, 7);
    for (TimeNs t = 40500 * kMs; t < 55 * kS; t += 500 * kMs) {
        made.section_command(t, 0);
        made.section_command(t + 50 * kMs, 7);
    }
    auto shut = [](TimeNs t) { return t < 40200 * kMs || (t >= 40700 * kMs && (t - 40700 * kMs) % (500 * kMs) < 50 * kMs); };
    auto flow = [&](TimeNs t) {
        if (shut(t)) return 0.0;
        const TimeNs since = t < 40700 * kMs ? t - 40200 * kMs : (t - 40700 * kMs) % (500 * kMs) - 50 * kMs;
        return 20.0 * std::min(1.0, static_cast<double>(since) / (800.0 * kMs));
    };
    made.hydraulics(flow, [&](TimeNs t) { return !shut(t); });
    made.breakpoint_reached(42 * kS);
    made.finish();
    const CaseResult result = made.judged().result;
    EXPECT_FALSE(result.passed);
    EXPECT_EQ(result.metrics.count("flow_adjust_time_s"), 0u) << "a flickering flow has no adjust time";
    ASSERT_EQ(result.not_measured.count("flow_adjust_time_s"), 1u);
    EXPECT_NE(result.not_measured.at("flow_adjust_time_s").find("never settled"), std::string::npos);
    EXPECT_TRUE(has_failure_starting(result, "flow_adjust_time_s not measured: never settled"));
    EXPECT_GT(result.metrics.at("flow_error_pct"), 3.0);
}

TEST(Judge, ATruthReaderFailsTheCaseNamingTopicAndParticipant) {
    HandMadeTrace made("truth-reader", continuation_plan());
    made.drive();
    made.trace().record_discoveries(
        0, {rig::DiscoveredEndpoint{"controller", "010f0a0b0c0d0e0f00000000", "device/gnss/nmea", "NmeaSentence", false, false},
            rig::DiscoveredEndpoint{"controller", "010f0a0b0c0d0e0f00000000", "truth/vehicle", "VehicleTruth", false, false}});
    made.finish();
    const CaseResult result = made.judged().result;
    EXPECT_FALSE(result.passed);
    EXPECT_EQ(result.error_kind, "topic_role_violation");
    EXPECT_NE(result.error.find("reads truth topic truth/vehicle"), std::string::npos) << result.error;
    EXPECT_NE(result.error.find("participant 'controller'"), std::string::npos) << result.error;
    // The same trace with the error expected passes as such.
    BreakpointJudgingPlan expecting = continuation_plan();
    expecting.expect_error = "topic_role_violation";
    HandMadeTrace again("truth-reader-expected", expecting);
    again.trace().record_discoveries(
        0, {rig::DiscoveredEndpoint{"controller", "010f0a0b0c0d0e0f00000000", "truth/vehicle", "VehicleTruth", false, false}});
    again.finish();
    const CaseResult expected = again.judged().result;
    EXPECT_TRUE(case_passed(expected)) << testing::PrintToString(expected.failures);
    EXPECT_TRUE(expected.expected_failure);
}

// A plan whose expectation was set aside (the case ran a controller other than
// the reference, harness/spec/case_spec.h applied_expectation): the same trace that
// passes as an expected error is judged on its own, a failure, and the result
// says why the expectation did not apply, from the trace alone.
TEST(Judge, AnExpectationSetAsideIsNotAppliedAndTheResultSaysWhy) {
    BreakpointJudgingPlan plan = continuation_plan();
    plan.expect_set_aside = "the case expects an error, topic_role_violation, of the reference controller; it ran ./mine";
    const BreakpointJudgingPlan back = breakpoint_judging_plan_from_json(to_json(plan));
    EXPECT_EQ(back.expect_set_aside, plan.expect_set_aside);
    HandMadeTrace made("truth-reader-set-aside", plan);
    made.trace().record_discoveries(
        0, {rig::DiscoveredEndpoint{"controller", "010f0a0b0c0d0e0f00000000", "truth/vehicle", "VehicleTruth", false, false}});
    made.finish();
    const CaseResult result = made.judged().result;
    EXPECT_FALSE(case_passed(result));
    EXPECT_FALSE(result.expected_failure);
    EXPECT_EQ(result.error_kind, "topic_role_violation");
    EXPECT_EQ(result.expectation_set_aside, plan.expect_set_aside);
    // A trace from before the reason existed still reads (no set_aside key).
    nlohmann::json old = to_json(continuation_plan());
    old["expect"].erase("set_aside");
    EXPECT_EQ(breakpoint_judging_plan_from_json(old).expect_set_aside, "");
}

TEST(Judge, ForgedTruthIsNeverJudgedAndFailsTheCase) {
    HandMadeTrace made("truth-forger", continuation_plan());
    made.drive();
    made.trace().append_foreign(45 * kS, 0, rig::topics::kHydraulicsTruth, "controller", "010f0a0b0c0d0e0f00000000",
                                nlohmann::json{{"main_flow_l_min", 20.0}, {"sections_spraying_mask", 7}}.dump());
    made.finish();
    const CaseRun run = made.judged();
    EXPECT_EQ(run.result.error_kind, "topic_role_violation");
    EXPECT_NE(run.result.error.find("truth/hydraulics"), std::string::npos) << run.result.error;
    EXPECT_NE(run.result.error.find("'controller'"), std::string::npos) << run.result.error;
    // The forged "flow on target" is not truth: the flow never opened.
    EXPECT_EQ(run.result.metrics.count("flow_adjust_time_s"), 0u);
}

TEST(Judge, AKilledControllersTraceKeepsItsSamplesAndItsError) {
    HandMadeTrace made("killed", continuation_plan());
    made.drive();
    made.section_command(0, 0);
    made.finish(TraceOutcome{"error", "node_exited",
                             "node 'controller': process killed by signal 6 (Aborted) (at t=20.000 s)", 20 * kS});
    const RecordedTrace trace = read_trace(made.path());
    EXPECT_EQ(trace.rows.at(rig::topics::kVehicleTruth).size(), 1201u) << "every sample written is there";
    const CaseResult result = judge_trace(trace).result;
    EXPECT_FALSE(case_passed(result));
    EXPECT_EQ(result.error_kind, "node_exited");
    EXPECT_EQ(result.sim_seconds, 20.0);
    ASSERT_FALSE(result.failures.empty());
    EXPECT_EQ(result.failures.front().rfind("error: node_exited: node 'controller': process killed", 0), 0u)
        << result.failures.front();
}

// A real-time run's facts with the rig's own lateness (harness/run/case_runner.cpp
// lateness_json): `overloaded` non-empty when it passed the case's bound.
std::string realtime_run_facts(const std::string& overloaded) {
    return nlohmann::json{{"wall_seconds", 61.0},
                          {"lateness",
                           {{"bound", {{"late_after_ms", 10.0}, {"max_late_pct", 1.0}, {"max_lateness_ms", 100.0}}},
                            {"emissions", 20000},
                            {"late", overloaded.empty() ? 0 : 7},
                            {"late_pct", overloaded.empty() ? 0.0 : 0.035},
                            {"max_ms", overloaded.empty() ? 1.2 : 500.4},
                            {"worst_device", "gnss_g970"},
                            {"worst_at_s", 33.0},
                            {"first_late_device", nullptr},
                            {"first_late_at_s", nullptr},
                            {"devices", nlohmann::json::object()},
                            {"injected_stall", nullptr},
                            {"overloaded", overloaded}}}}
        .dump();
}

// The controller that never resumes, recorded in a real-time run whose rig was
// late: the missed metres may be the rig's, so the case is invalid, not failed;
// the metrics are still there. The same behaviour with the rig on time fails.
TEST(Judge, AnOverloadedRigMakesTheRunInvalidNotTheControllersFailure) {
    const std::string overloaded = "gnss_g970 emitted 500.4 ms after its deadline at t = 33.000 s (bound "
                                   "realtime.max_lateness_ms: 100 ms)";
    for (const bool late : {true, false}) {
        SCOPED_TRACE(late ? "overloaded" : "on time");
        HandMadeTrace made(late ? "overloaded" : "on-time", continuation_plan());
        made.trace().set_meta("mode", "realtime");
        made.trace().set_meta("run", realtime_run_facts(late ? overloaded : ""));
        made.drive();
        made.section_command(0, 0);
        made.breakpoint_reached(35 * kS);
        made.hydraulics([](TimeNs) { return 0.0; }, [](TimeNs) { return false; });
        made.spray(0, -24.5, 0.0);
        made.finish();
        const CaseResult result = made.judged().result;
        EXPECT_FALSE(case_passed(result));
        EXPECT_NEAR(result.metrics.at("missed_m"), 9.0, 1e-9) << "metrics are computed either way";
        EXPECT_EQ(case_invalid(result), late);
        if (late) {
            EXPECT_EQ(result.error_kind, "rig_overloaded");
            EXPECT_EQ(result.error, "the rig was overloaded: " + overloaded +
                                        "; the run cannot judge the controller (its metrics are reported, not judged)");
            EXPECT_FALSE(has_failure_starting(result, "missed_m")) << testing::PrintToString(result.failures);
            EXPECT_EQ(result.rig_lateness.at("max_ms").get<double>(), 500.4);
        } else {
            EXPECT_EQ(result.error_kind, "");
            EXPECT_TRUE(has_failure_starting(result, "missed_m 9 > 0")) << testing::PrintToString(result.failures);
        }
    }
}

// What the overload wins over, and what it does not: an error the controller
// caused is kept in the text; a stop signal, the rig's own error, a broken
// topic role and a malformed command are not the lateness's doing and stay as
// they are.
TEST(Judge, TheOverloadWinsOverTheControllersErrorsButNotTheRigsOwn) {
    const std::string overloaded = "plant emitted 300.0 ms after its deadline at t = 10.000 s";
    const std::vector<std::pair<std::string, std::string>> ends = {
        {"node_exited", "rig_overloaded"},      {"board_silent", "rig_overloaded"},
        {"interrupted", "interrupted"},         {"harness_error", "harness_error"},
        {"topic_role_violation", "topic_role_violation"}, {"malformed_command", "malformed_command"}};
    for (const auto& [ended, judged] : ends) {
        SCOPED_TRACE(ended);
        HandMadeTrace made("overloaded-" + ended, continuation_plan());
        made.trace().set_meta("mode", "realtime");
        made.trace().set_meta("run", realtime_run_facts(overloaded));
        made.drive();
        made.finish(TraceOutcome{ended == "interrupted" ? "interrupted" : "error", ended, "what happened", 20 * kS});
        const CaseResult result = made.judged().result;
        EXPECT_EQ(result.error_kind, judged);
        EXPECT_FALSE(case_passed(result));
        if (judged == "rig_overloaded") {
            EXPECT_NE(result.error.find("; the run also ended in " + ended + ": what happened"), std::string::npos)
                << result.error;
        } else {
            EXPECT_EQ(result.error, "what happened");
        }
    }
}

TEST(Judge, AnUnfinishedTraceIsReadableAsInterrupted) {
    const fs::path dir = rig::testing::fresh_dir("judge-unfinished");
    {
        TraceFile trace(dir / "trace.sqlite");
        trace.set_meta("case", "unfinished");
        trace.set_meta("judging", to_json(continuation_plan()).dump());
        for (TimeNs t = 0; t < 10 * kS; t += 10 * kMs) trace.append(t, 0, "device/wheel_encoder/count", {{"count_pulses", t / kMs}});
        // Destroyed unfinished, as when an exception unwinds past the run.
    }
    const RecordedTrace trace = read_trace(dir / "trace.sqlite");
    EXPECT_EQ(trace.meta.at("outcome"), "interrupted");
    const CaseResult result = judge_trace(trace).result;
    EXPECT_EQ(result.error_kind, "interrupted");
    EXPECT_NEAR(result.sim_seconds, 9.99, 1e-9);
}

// A write that fails on the run's own thread (a discovery row when the disk is
// full) is caught by the run, which then finishes the trace. When SQLite rolled
// the batch back, finish() refuses, and its error must still say what failed:
// "a write failed earlier" alone sent a CI log reader looking for a rig bug.
// In a child process, so that the file-size limit (RLIMIT_FSIZE: writes past it
// fail with EFBIG, as on a full disk) binds only it.
TEST(TraceFile, AWriteThatFailedOnTheRunsThreadIsNamedWhenFinishRefuses) {
    const fs::path dir = rig::testing::fresh_dir("trace-write-failed");
    const fs::path report = dir / "report.txt";
    const pid_t child = ::fork();
    ASSERT_NE(child, -1);
    if (child == 0) {
        std::signal(SIGXFSZ, SIG_IGN);  // a write past the limit fails instead of killing the process
        std::ofstream out(report);      // opened before the limit
        const rlimit limit{256 * 1024, 256 * 1024};
        ::setrlimit(RLIMIT_FSIZE, &limit);
        std::string first, second;
        try {
            TraceFile trace(dir / "trace.sqlite");
            for (TimeNs t = 0; t < kS; t += 10 * kMs) trace.append(t, 0, "device/wheel_encoder/count", {{"count_pulses", t}});
            rig::DiscoveredEndpoint huge{"controller", "01.0f", std::string(8 * 1024 * 1024, 't'), "T", true, false};
            try {
                trace.record_discoveries(kS, {huge});
            } catch (const std::exception& error) {
                first = error.what();
            }
            trace.finish(TraceOutcome{"error", "harness_error", first, kS});
        } catch (const std::exception& error) {
            second = error.what();
        }
        out << first << "\n" << second << "\n";
        out.flush();
        ::_exit(0);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
    std::ifstream in(report);
    std::string first, second;
    std::getline(in, first);
    std::getline(in, second);
    const std::string trace_name = "trace " + (dir / "trace.sqlite").string() + ": ";
    if (first.empty()) {
        // SQLite kept the row's pages in its cache (it spills them to the log
        // with 4 KiB pages, not with the trace's 16 KiB ones): the write failed
        // in finish()'s commit, which must say so, naming the file.
        ASSERT_EQ(second.rfind(trace_name, 0), 0u) << second;
        EXPECT_GT(second.size(), trace_name.size()) << second;
        // Nothing after the last committed batch is there, and no outcome
        // claims the run completed (here not even the first batch was committed).
        try {
            EXPECT_NE(read_trace(dir / "trace.sqlite").meta.at("outcome"), "completed");
        } catch (const std::exception& error) {
            EXPECT_EQ(std::string(error.what()).rfind(trace_name, 0), 0u) << error.what();
        }
        return;
    }
    const std::string cause = first.substr(first.rfind(": ") + 2);
    EXPECT_FALSE(cause.empty()) << first;
    // Either SQLite kept the batch and the trace finished with the error as its
    // outcome, or it rolled the batch back and finish names the first failure.
    if (!second.empty()) {
        EXPECT_NE(second.find("a write failed earlier (" + cause + ")"), std::string::npos) << second;
    } else {
        const RecordedTrace trace = read_trace(dir / "trace.sqlite");
        EXPECT_EQ(trace.meta.at("error"), first);
    }
}

// The trace judged again after `sql` changed it.
CaseResult judged_after_editing(HandMadeTrace& made, const char* sql) {
    sqlite3* db = nullptr;
    EXPECT_EQ(sqlite3_open(made.path().c_str(), &db), SQLITE_OK);
    EXPECT_EQ(sqlite3_exec(db, sql, nullptr, nullptr, nullptr), SQLITE_OK) << sql;
    sqlite3_close(db);
    return made.judged().result;
}

TEST(Judge, ATraceChangedAfterItsRunIsNotJudgedAsTheRuns) {
    HandMadeTrace made("edited", continuation_plan());
    made.drive();
    made.finish();
    EXPECT_EQ(made.judged().result.error, "");
    const CaseResult result =
        judged_after_editing(made, "UPDATE samples SET json = replace(json, '-25.0', '-24.0') WHERE rowid = 1");
    EXPECT_EQ(result.error_kind, "harness_error");
    EXPECT_NE(result.error.find("changed after the run"), std::string::npos) << result.error;
}

TEST(Judge, WhatIsNotATraceIsRefusedNamingIt) {
    const fs::path dir = rig::testing::fresh_dir("judge-not-a-trace");
    std::ofstream(dir / "notes.txt") << "not a database\n";
    for (const fs::path& path : {dir / "notes.txt", dir / "missing.sqlite", dir}) {
        try {
            read_trace(path);
            ADD_FAILURE() << path << " was read as a trace";
        } catch (const std::runtime_error& error) {
            EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
        }
    }
    // Another trace format: say so rather than misjudge it.
    {
        TraceFile trace(dir / "old.sqlite");
        trace.set_meta("trace_format", "1");
        trace.finish(TraceOutcome{});
    }
    try {
        read_trace(dir / "old.sqlite");
        ADD_FAILURE() << "a format-1 trace was read";
    } catch (const std::runtime_error& error) {
        EXPECT_NE(std::string(error.what()).find("trace format 1"), std::string::npos) << error.what();
    }
}

// Samples recorded from their IDL type are stored as CDR bytes beside the JSON
// text the writer renders from them (harness/trace/trace_cdr.h). The text, and
// so the digest, is what a trace written as text has; the judge reads values
// decoded from the bytes; the views people query still read the text.
msg::HydraulicsTruth hydraulics_at(int i) {
    msg::HydraulicsTruth sample;
    sample.time_ns(i * 10 * kMs);
    sample.main_flow_l_min(20.0 + i / 3.0);
    sample.valve_opening_pct(i % 7 == 0 ? std::nan("") : 1e-7 * i);
    sample.sections_spraying_mask(static_cast<std::uint16_t>(i % 8));
    sample.nozzles_spraying(static_cast<std::uint16_t>(i % 25));
    return sample;
}

std::vector<std::vector<std::string>> query(const fs::path& file, const std::string& sql) {
    sqlite3* db = nullptr;
    EXPECT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    std::vector<std::vector<std::string>> rows;
    const auto collect = [](void* out, int columns, char** values, char**) {
        auto& table = *static_cast<std::vector<std::vector<std::string>>*>(out);
        table.emplace_back();
        for (int i = 0; i < columns; ++i) table.back().push_back(values[i] != nullptr ? values[i] : "NULL");
        return 0;
    };
    EXPECT_EQ(sqlite3_exec(db, sql.c_str(), collect, &rows, nullptr), SQLITE_OK) << sql;
    sqlite3_close(db);
    return rows;
}

TEST(TraceBytes, SamplesStoredAsBytesKeepTheTextTracesDigestAndAreReadAsItsValues) {
    const fs::path dir = rig::testing::fresh_dir("trace-bytes");
    const std::string topic = rig::topics::kHydraulicsTruth;
    std::string typed_sha256, text_sha256;
    {
        TraceFile typed(dir / "typed.sqlite");
        const std::uint32_t slot = typed.topic_slot(topic, &sample_codec<msg::HydraulicsTruth>());
        TraceFile text(dir / "text.sqlite");
        for (int i = 0; i < 5000; ++i) {
            typed.append_sample(i * 10 * kMs, i, slot, hydraulics_at(i));
            text.append_text(i * 10 * kMs, i, topic, to_json_text(hydraulics_at(i)));
        }
        typed_sha256 = typed.finish(TraceOutcome{"completed", "", "", 50 * kS});
        text_sha256 = text.finish(TraceOutcome{"completed", "", "", 50 * kS});
    }
    EXPECT_EQ(typed_sha256, text_sha256);
    EXPECT_EQ(query(dir / "typed.sqlite", "select json from samples order by rowid"),
              query(dir / "text.sqlite", "select json from samples order by rowid"));

    const RecordedTrace trace = read_trace(dir / "typed.sqlite");
    EXPECT_EQ(trace.meta.at("trace_format"), "3");
    EXPECT_EQ(trace.recomputed_sha256, typed_sha256);
    EXPECT_EQ(trace.recomputed_cdr_sha256, trace.meta.at("cdr_sha256"));
    EXPECT_EQ(trace.sample_types.at(topic), "rig::msg::HydraulicsTruth");
    const std::vector<RecordedSample>& samples = trace.samples(topic);
    ASSERT_EQ(samples.size(), 5000u);
    for (int i = 0; i < 5000; ++i) {
        ASSERT_FALSE(trace.rows.at(topic)[static_cast<std::size_t>(i)].cdr.empty());
        ASSERT_EQ(samples[static_cast<std::size_t>(i)].json, nlohmann::json::parse(to_json_text(hydraulics_at(i)))) << i;
        ASSERT_EQ(samples[static_cast<std::size_t>(i)].round, i);
    }
    // The views of docs/trace-format.md read the text, as before.
    const auto rows = query(dir / "typed.sqlite",
                            "select t_s, main_flow_l_min, valve_opening_pct, nozzles_spraying from hydraulics "
                            "where t_s > 40 limit 20");
    ASSERT_EQ(rows.size(), 20u);
    EXPECT_EQ(rows[0], (std::vector<std::string>{"40.01", "1353.66666666667", "0.0004001", "1"}));
    EXPECT_EQ(rows[3][2], "NULL");  // i = 4004, a multiple of 7: not a number, stored as null
}

TEST(TraceBytes, ChangedBytesAreNotJudgedAsTheRuns) {
    HandMadeTrace made("edited-bytes", continuation_plan());
    made.drive();
    const std::uint32_t slot =
        made.trace().topic_slot(rig::topics::kHydraulicsTruth, &sample_codec<msg::HydraulicsTruth>());
    for (int i = 0; i < 100; ++i) made.trace().append_sample(25 * kS + i * 10 * kMs, 0, slot, hydraulics_at(i));
    made.finish();
    EXPECT_EQ(made.judged().result.error, "");
    const CaseResult result = judged_after_editing(made,
                                                   "UPDATE samples SET cdr = zeroblob(length(cdr)) WHERE rowid = "
                                                   "(SELECT min(rowid) FROM samples WHERE cdr IS NOT NULL)");
    EXPECT_EQ(result.error_kind, "harness_error");
    EXPECT_NE(result.error.find("samples' bytes give digest"), std::string::npos) << result.error;
}

// A rig killed with SIGKILL mid-run leaves its trace readable up to its last
// committed batch, bytes and all. In a child process, killed once it has
// written more than two batches (set_meta waits for the writer thread).
TEST(TraceBytes, ATraceKilledMidRunIsReadableUpToItsLastBatch) {
    const fs::path dir = rig::testing::fresh_dir("trace-killed");
    int ready[2];
    ASSERT_EQ(::pipe(ready), 0);
    const pid_t child = ::fork();
    ASSERT_NE(child, -1);
    if (child == 0) {
        ::close(ready[0]);
        TraceFile trace(dir / "trace.sqlite");
        const std::uint32_t slot =
            trace.topic_slot(rig::topics::kHydraulicsTruth, &sample_codec<msg::HydraulicsTruth>());
        for (int i = 0; i < 10000; ++i) trace.append_sample(i * 10 * kMs, 0, slot, hydraulics_at(i));
        trace.set_meta("written", "10000");
        const char byte = 'k';
        if (::write(ready[1], &byte, 1) != 1) ::_exit(1);
        for (;;) ::pause();
    }
    ::close(ready[1]);
    char byte = 0;
    ASSERT_EQ(::read(ready[0], &byte, 1), 1);
    ::close(ready[0]);
    ASSERT_EQ(::kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "status " << status;

    const RecordedTrace trace = read_trace(dir / "trace.sqlite");
    EXPECT_EQ(trace.meta.at("outcome"), "running");
    const std::vector<RecordedSample>& samples = trace.samples(rig::topics::kHydraulicsTruth);
    // Whole batches only: the open one died with the rig.
    ASSERT_GE(samples.size(), 4096u);
    EXPECT_LT(samples.size(), 10000u);
    EXPECT_EQ(samples.size() % 4096, 0u);
    for (std::size_t i = 0; i < samples.size(); ++i) {
        ASSERT_EQ(samples[i].json, nlohmann::json::parse(to_json_text(hydraulics_at(static_cast<int>(i))))) << i;
    }
}

TEST(JudgingPlan, RoundTripsThroughJsonAndNamesAMissingKey) {
    const BreakpointJudgingPlan plan = continuation_plan();
    const BreakpointJudgingPlan back = breakpoint_judging_plan_from_json(to_json(plan));
    EXPECT_EQ(to_json(back), to_json(plan));
    nlohmann::json broken = to_json(plan);
    broken["flow"].erase("window_to_ns");
    try {
        breakpoint_judging_plan_from_json(broken);
        ADD_FAILURE() << "accepted a plan without flow.window_to_ns";
    } catch (const std::runtime_error& error) {
        EXPECT_NE(std::string(error.what()).find("flow.window_to_ns"), std::string::npos) << error.what();
    }
}

TEST(TopicRoles, TruthIsTheRigsDeviceDataTooTheClockToo) {
    EXPECT_TRUE(topic_role_violation("reader", "truth/vehicle"));
    EXPECT_TRUE(topic_role_violation("writer", "truth/hydraulics"));
    EXPECT_TRUE(topic_role_violation("writer", "device/gnss/nmea"));
    EXPECT_TRUE(topic_role_violation("writer", "rig/clock/tick"));
    EXPECT_FALSE(topic_role_violation("reader", "device/gnss/nmea"));
    EXPECT_FALSE(topic_role_violation("writer", "actuator/section_valves/open"));
    EXPECT_FALSE(topic_role_violation("writer", "controller/status"));
    EXPECT_FALSE(topic_role_violation("writer", "rig/clock/ack"));
    EXPECT_FALSE(topic_role_violation("writer", "team/diagnostics"));  // a controller's own topic
}

}  // namespace
