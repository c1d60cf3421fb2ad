// Whole runs through `bin/rig` (DESIGN.md "Time", "Results contract"):
//  * the same case and seed give the same trace, bit for bit; another seed does not;
//  * a controller that stops answering fails the case by its name, in bounded time;
//  * a broken case file stops the run before anything starts, naming file, line and key;
//  * the bench path in real time: the wired continuation case (NMEA on a pty,
//    Modbus RTU on a pty pair) passes the paper's limits and reports its jitter.
#include <gtest/gtest.h>

#include "run_support.h"

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "controller/nmea_parser.h"
#include "rig/child_process.h"
#include "rig/serial_port.h"

namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) { return rig::testing::fresh_dir("whole-run-" + name); }

using rig::testing::read_all;

struct RunOutcome {
    int exit_code = -1;
    std::string log;
    nlohmann::json results;
};

// `rig run <args> --out DIR`, bounded by `timeout`.
RunOutcome rig_run(const std::string& args, const fs::path& out) {
    fs::create_directories(out);
    const std::string command = "timeout -k 10 300 '" RIG_BINARY_DIR "/bin/rig' run " + args + " --out '" +
                                out.string() + "' > '" + (out / "rig.log").string() + "' 2>&1";
    const int status = std::system(command.c_str());
    RunOutcome outcome;
    outcome.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    outcome.log = read_all(out / "rig.log");
    if (fs::exists(out / "results.json")) outcome.results = nlohmann::json::parse(read_all(out / "results.json"));
    return outcome;
}

const std::string kShortCase = "'" RIG_SOURCE_DIR "/tests/data/short-fusion.yaml'";

TEST(WholeRun, SameSeedGivesTheSameTraceAndAnotherSeedDoesNot) {
    const fs::path dir = fresh_dir("determinism");
    const RunOutcome first = rig_run(kShortCase + " --seed 5", dir / "first");
    const RunOutcome second = rig_run(kShortCase + " --seed 5", dir / "second");
    const RunOutcome other = rig_run(kShortCase + " --seed 6", dir / "other");
    ASSERT_EQ(first.exit_code, 0) << first.log;
    ASSERT_EQ(second.exit_code, 0) << second.log;
    ASSERT_EQ(other.exit_code, 0) << other.log;
    const std::string digest = first.results["cases"][0]["trace_sha256"];
    EXPECT_EQ(digest.size(), 64u);
    EXPECT_EQ(second.results["cases"][0]["trace_sha256"], digest);
    EXPECT_NE(other.results["cases"][0]["trace_sha256"], digest);
}

TEST(WholeRun, ControllerThatStopsAnsweringFailsByNameInBoundedTime) {
    const fs::path dir = fresh_dir("stall");
    // The short case with a controller that wedges 3 s into simulated time, and a
    // 2 s bound on each acknowledgement.
    std::string text = read_all(RIG_SOURCE_DIR "/tests/data/short-fusion.yaml");
    text += "timeouts: { node_ack_s: 2 }\n";
    const std::string controller_line = "controller: { positioning: fusion, threshold_m: 5.0 }";
    const auto at = text.find(controller_line);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, controller_line.size(),
                 "controller: { positioning: fusion, threshold_m: 5.0, command: [ '" RIG_BINARY_DIR
                 "/bin/rig-controller', '--stall-at-s', '3' ] }");
    std::ofstream(dir / "stalling.yaml") << text;

    const auto started = std::chrono::steady_clock::now();
    const RunOutcome outcome = rig_run("'" + (dir / "stalling.yaml").string() + "'", dir / "out");
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    EXPECT_EQ(outcome.exit_code, 1) << outcome.log;
    ASSERT_TRUE(outcome.results.contains("cases")) << outcome.log;
    const nlohmann::json& result = outcome.results["cases"][0];
    EXPECT_FALSE(result["passed"].get<bool>());
    const std::string error = result["error"].is_string() ? result["error"].get<std::string>() : "";
    EXPECT_NE(error.find("node 'controller'"), std::string::npos) << error;
    EXPECT_NE(error.find("did not acknowledge"), std::string::npos) << error;
    // Bounded: the 2 s acknowledgement bound plus start-up and shutdown, far from
    // the 600 s case bound (generous for a loaded machine).
    EXPECT_LT(wall_s, 60.0);
}

TEST(WholeRun, BrokenCaseFileStopsTheRunNamingFileLineAndKey) {
    const fs::path dir = fresh_dir("broken");
    std::string text = read_all(RIG_SOURCE_DIR "/tests/data/short-fusion.yaml");
    text += "hydraulics: { pump_flow_l_min: -3 }\n";
    std::ofstream(dir / "broken.yaml") << text;
    const RunOutcome outcome = rig_run("'" + (dir / "broken.yaml").string() + "'", dir / "out");
    EXPECT_EQ(outcome.exit_code, 2) << outcome.log;
    EXPECT_NE(outcome.log.find("broken.yaml:"), std::string::npos) << outcome.log;
    EXPECT_NE(outcome.log.find("hydraulics.pump_flow_l_min: must be > 0"), std::string::npos) << outcome.log;
    EXPECT_NE(outcome.log.find("nothing was run"), std::string::npos) << outcome.log;
    EXPECT_FALSE(fs::exists(dir / "out" / "results.json")) << "nothing may run, nothing may be written";
}

TEST(WholeRun, WiredControllerInRealTimePassesThePapersLimits) {
    const fs::path dir = fresh_dir("wired");
    const RunOutcome outcome =
        rig_run("'" RIG_SOURCE_DIR "/cases/bench-wired/continuation-6kmh-wired-rtu.yaml'", dir / "out");
    ASSERT_EQ(outcome.exit_code, 0) << outcome.log;
    const nlohmann::json& result = outcome.results["cases"][0];
    EXPECT_TRUE(result["passed"].get<bool>()) << result.dump(2);
    EXPECT_EQ(result["mode"], "realtime");
    const nlohmann::json& realtime = result["realtime"];
    const std::string wiring = realtime["wiring"];
    EXPECT_NE(wiring.find("gnss serial /dev/pts/"), std::string::npos) << wiring;
    EXPECT_NE(wiring.find("board_io modbus_rtu /dev/pts/"), std::string::npos) << wiring;
    // Every device emitted, with its jitter measured.
    for (const char* device : {"gnss_g970", "wheel_encoder", "main_flow_meter", "board_io"}) {
        ASSERT_TRUE(realtime["emission_jitter"].contains(device)) << realtime.dump(2);
        EXPECT_GT(realtime["emission_jitter"][device]["samples"].get<int>(), 10) << device;
        EXPECT_GE(realtime["emission_jitter"][device]["max_ms"].get<double>(),
                  realtime["emission_jitter"][device]["p50_ms"].get<double>());
    }
    // Only nodes that had deadlines are listed, each with samples behind its figures.
    for (const auto& [device, stats] : realtime["emission_jitter"].items()) {
        EXPECT_GT(stats["samples"].get<int>(), 0) << device;
    }
    // The controller's claims came over the Modbus indicators: it stored and reached one breakpoint.
    EXPECT_EQ(result["metrics"]["breakpoint_reached_count"].get<double>(), 1.0);
    for (const char* metric : {"flow_adjust_time_s", "flow_error_pct", "overlap_m", "missed_m", "breakpoint_error_m"}) {
        EXPECT_TRUE(result["metrics"].contains(metric)) << metric;
    }
}

// `rig emulate gnss`: a case's receiver onto a pseudo-terminal, read back by a
// program that only speaks serial, decoded by the controller's parser.
TEST(BenchEmulate, GnssStreamOfACaseGoesOutOnAPty) {
    const fs::path dir = fresh_dir("emulate");
    const fs::path link = dir / "gnss0";
    rig::ChildProcess emulator({RIG_BINARY_DIR "/bin/rig", "emulate", "gnss",
                                RIG_SOURCE_DIR "/cases/table3-fusion/table3-fusion-6kmh-s1.yaml", "--pty", "--link",
                                link.string(), "--seconds", "6"},
                               dir / "emulate.log");
    for (int i = 0; i < 500 && !fs::exists(link); ++i) rig::RealtimeClock().sleep_until_ns(rig::seconds_to_ns(0.01));
    ASSERT_TRUE(fs::exists(link)) << read_all(dir / "emulate.log");
    rig::SerialPort port(link.string());
    int gga = 0;
    int rmc = 0;
    for (int lines = 0; lines < 40 && (gga < 3 || rmc < 3); ++lines) {
        const std::optional<std::string> line = port.read_line(std::chrono::milliseconds(3000));
        ASSERT_TRUE(line.has_value()) << "no NMEA within 3 s; " << read_all(dir / "emulate.log");
        const auto parsed = rig::nmea::parse_sentence(*line);
        ASSERT_TRUE(parsed.ok()) << *line;
        if (const auto* fix = std::get_if<rig::nmea::GgaData>(&parsed.sentence->data)) {
            ++gga;
            ASSERT_TRUE(fix->position.has_value()) << *line;
            EXPECT_NEAR(fix->position->lat_deg, 40.18, 0.01) << *line;  // the case's field
            EXPECT_NEAR(fix->position->lon_deg, 116.44, 0.01) << *line;
            EXPECT_EQ(fix->fix_quality.value_or(0), 4) << *line;  // RTK fixed
        } else if (std::holds_alternative<rig::nmea::RmcData>(parsed.sentence->data)) {
            ++rmc;
        }
    }
    EXPECT_GE(gga, 3);
    EXPECT_GE(rmc, 3);
    EXPECT_EQ(emulator.stop(std::chrono::milliseconds(15000)), "process exited with status 0")
        << read_all(dir / "emulate.log");
}

}  // namespace
