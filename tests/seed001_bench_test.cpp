// Seed 001's bench path (docs/seed001-boundary.md "Bench path") as a bench
// user runs it, in real time on the wall clock: Table 8's drive out at 1.5 m/s
// with the AD300's RMC and the L4's lines on serial lines (ptys), once read by
// the reference controller started by the rig (`rig-boundary-controller
// --clock realtime --nmea-serial --laser-serial`), once by a Pi outside the
// rig (tests/boundary_board_player.cpp, `controller: external`) that attaches
// from attach.json and publishes its PWM duties on DDS. Both are judged like
// the lockstep case (its limit widened by one PWM period, the case file says
// why), and the rig's own lateness must leave the
// verdict valid. No assertion is on speed: the lateness bound is the case's
// (100 ms, seed 000's), far above what the idle rig shows (under 5 ms).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "rig/host/child_process.h"
#include "rig/runtime/clock.h"
#include "run_support.h"

namespace fs = std::filesystem;
using rig::testing::fresh_dir;
using rig::testing::read_all;

namespace {

const std::string kCaseName = "seed001-bench-drive-out-wired";
const fs::path kCaseFile = fs::path(RIG_SOURCE_DIR) / "cases" / "bench-wired" / "seed001-drive-out-wired.yaml";

struct BenchRun {
    std::string exit;
    std::string rig_log;
    std::string board_log;
    nlohmann::json result;  // results.json cases[0]
    nlohmann::json attach;  // attach.json (external board only)
};

// `rig run` on `case_file`, with the Pi player beside it when `with_board`;
// waits for both, bounded far above what the run needs (15 s of case time).
BenchRun run_bench(const fs::path& dir, const fs::path& case_file, bool with_board,
                   const std::vector<std::string>& board_args = {}) {
    const fs::path out = dir / "out";
    const fs::path attach_file = out / "cases" / kCaseName / "attach.json";
    rig::ChildProcess rig_run({RIG_BINARY_DIR "/bin/rig", "run", case_file.string(), "--out", out.string()},
                              dir / "rig.log");
    std::optional<rig::ChildProcess> board;
    if (with_board) {
        std::vector<std::string> argv = {RIG_BOUNDARY_PLAYER, "--attach", attach_file.string()};
        argv.insert(argv.end(), board_args.begin(), board_args.end());
        board.emplace(argv, dir / "board.log");
    }
    const rig::RealtimeClock clock;
    BenchRun run;
    for (;;) {
        if (auto ended = rig_run.exit_description()) {
            run.exit = *ended;
            break;
        }
        if (rig::ns_to_seconds(clock.now_ns()) > 300.0) {
            run.exit = "still running after 300 s: " + rig_run.stop();
            break;
        }
        clock.sleep_until_ns(clock.now_ns() + rig::seconds_to_ns(0.1));
    }
    // The player sees the rig close the lines and ends by itself.
    if (board) run.board_log = "player " + board->stop(std::chrono::milliseconds(10000)) + "\n";
    run.rig_log = read_all(dir / "rig.log");
    run.board_log += read_all(dir / "board.log");
    const std::string results = read_all(out / "results.json");
    if (!results.empty()) run.result = nlohmann::json::parse(results)["cases"][0];
    const std::string attach = read_all(attach_file);
    if (!attach.empty()) run.attach = nlohmann::json::parse(attach);
    return run;
}

// What both runs must show: judged and passed on the case's limit,
// the spray shut off past the edge at every station, the rig on time.
void expect_judged_and_passed(const BenchRun& run) {
    ASSERT_TRUE(run.result.is_object()) << run.exit << "\n" << run.rig_log << run.board_log;
    const nlohmann::json& result = run.result;
    EXPECT_EQ(result["verdict"], "passed") << result.dump(2) << run.rig_log << run.board_log;
    EXPECT_EQ(run.exit, "process exited with status 0") << run.rig_log;
    EXPECT_EQ(result["mode"], "realtime");
    const nlohmann::json& metrics = result["metrics"];
    ASSERT_TRUE(metrics.contains("drive_out_excess_mean_m")) << result.dump(2);
    // Every station under the boom was wet inside and dry beyond the excess:
    // the nozzles opened on the RMC from the line and closed at the edge.
    EXPECT_EQ(metrics["drive_out_excess_stations"].get<double>(), 8.0) << metrics.dump(2);
    EXPECT_EQ(metrics["drive_out_excess_stations_dry"].get<double>(), 0.0) << metrics.dump(2);
    EXPECT_LE(metrics["drive_out_excess_mean_m"].get<double>(), result["limits"]["drive_out_excess_mean_m"].get<double>());
    // The rig's lateness was watched on every timed emission and kept the verdict valid.
    const nlohmann::json& realtime = result["realtime"];
    const std::string wiring = realtime["wiring"];
    EXPECT_NE(wiring.find("gnss serial /dev/pts/"), std::string::npos) << wiring;
    EXPECT_NE(wiring.find("laser serial /dev/pts/"), std::string::npos) << wiring;
    const nlohmann::json& lateness = realtime["rig_lateness"];
    EXPECT_EQ(lateness["overloaded"], "") << lateness.dump(2);
    EXPECT_GT(lateness["emissions"].get<int>(), 1000) << lateness.dump(2);
    for (const char* device : {"boundary_plant", "ad300", "l4_laser"}) {
        ASSERT_TRUE(lateness["devices"].contains(device)) << lateness.dump(2);
        EXPECT_GT(lateness["devices"][device]["emissions"].get<int>(), 100) << device;
    }
}

}  // namespace

TEST(Seed001BenchRealTime, ReferenceControllerOnSerialLinesPassesTheDriveOut) {
    const fs::path dir = fresh_dir("seed001-bench-process");
    const BenchRun run = run_bench(dir, kCaseFile, /*with_board=*/false);
    expect_judged_and_passed(run);
    EXPECT_EQ(run.result["controller_mode"], "process");
    // The controller was handed the lines' far ends, and read them: a line
    // whose bytes wait unread would have failed the run as wire_unread.
    const std::string log = read_all(dir / "out" / "cases" / kCaseName / "controller.log");
    EXPECT_EQ(log.find("rejected"), std::string::npos) << log;
}

// The shipped wired case with its controller outside the rig.
fs::path external_case(const fs::path& dir) {
    std::string text = read_all(kCaseFile);
    const std::string wiring = "\nwiring:\n";
    const std::size_t at = text.find(wiring);
    if (at == std::string::npos) throw std::runtime_error("the wired case has no wiring section");
    text.insert(at + wiring.size(), "  controller: external\n");
    const fs::path case_file = dir / "drive-out-external.yaml";
    std::ofstream(case_file) << text;
    return case_file;
}

TEST(Seed001BenchRealTime, AnExternalPiAttachedToTheLinesPassesTheDriveOut) {
    const fs::path dir = fresh_dir("seed001-bench-external");
    const BenchRun run = run_bench(dir, external_case(dir), /*with_board=*/true);
    expect_judged_and_passed(run);
    EXPECT_EQ(run.result["controller_mode"], "external");
    // Where to attach: both lines, and the domain the Pi publishes its duties in.
    std::set<std::string> roles;
    for (const nlohmann::json& port : run.attach["ports"]) roles.insert(port["role"].get<std::string>());
    EXPECT_EQ(roles, (std::set<std::string>{"gnss_nmea", "laser_serial"})) << run.attach.dump(2);
    EXPECT_TRUE(run.attach["dds_domain"].is_number()) << run.attach.dump(2);
    EXPECT_NE(run.rig_log.find("attach: gnss_nmea=/dev/pts/"), std::string::npos) << run.rig_log;
    // The player ran to the end of the case and left when the rig closed the lines.
    EXPECT_NE(run.board_log.find("boundary_board_player: RMC on /dev/pts/"), std::string::npos) << run.board_log;
    EXPECT_NE(run.board_log.find("player process exited with status 0"), std::string::npos) << run.board_log;
}

// A Pi that opened the laser line but never reads it: the rig fails the case
// as wire_unread naming that line, as it does seed 000's GNSS line, with
// results written, instead of streaming into it until the case's wall bound.
TEST(Seed001BenchRealTime, APiThatNeverReadsTheLaserLineFailsNamingIt) {
    const fs::path dir = fresh_dir("seed001-bench-laser-unread");
    const BenchRun run = run_bench(dir, external_case(dir), /*with_board=*/true, {"--leave-laser-unread", "1"});
    ASSERT_TRUE(run.result.is_object()) << run.exit << "\n" << run.rig_log << run.board_log;
    EXPECT_EQ(run.result["verdict"], "failed") << run.result.dump(2);
    EXPECT_EQ(run.result["error_kind"], "wire_unread") << run.result.dump(2);
    const std::string error = run.result["error"].is_string() ? run.result["error"].get<std::string>() : "";
    const std::string laser = [&] {
        for (const nlohmann::json& port : run.attach["ports"]) {
            if (port["role"] == "laser_serial") return port["path"].get<std::string>();
        }
        return std::string("(no laser port in attach.json)");
    }();
    EXPECT_NE(error.find("nobody reads the laser line " + laser), std::string::npos) << error;
    EXPECT_EQ(run.exit, "process exited with status 1") << run.rig_log;
}

// The rig's own lateness on a boundary case (docs/metrics.md "Verdicts"): the
// wired case with the rig's loop stalled 0.5 s at t = 3 s (`rig_faults`, the
// overload detection's self-test) is invalid (rig_overloaded), not a failure
// of the controller, whatever the controller did; exit status 3.
TEST(Seed001BenchRealTime, AStalledRigMakesTheBoundaryCaseInvalidNotFailed) {
    const fs::path dir = fresh_dir("seed001-bench-stall");
    std::string text = read_all(kCaseFile);
    const std::string bound = "\nrealtime: ";
    const std::size_t at = text.find(bound);
    ASSERT_NE(at, std::string::npos);
    text.insert(at + 1, "rig_faults: { master_stall_at_s: 3, master_stall_for_s: 0.5 }\n");
    const fs::path case_file = dir / "drive-out-stalled.yaml";
    std::ofstream(case_file) << text;

    const BenchRun run = run_bench(dir, case_file, /*with_board=*/false);
    ASSERT_TRUE(run.result.is_object()) << run.exit << "\n" << run.rig_log;
    EXPECT_EQ(run.result["verdict"], "invalid") << run.result.dump(2);
    EXPECT_EQ(run.result["error_kind"], "rig_overloaded") << run.result.dump(2);
    const nlohmann::json& lateness = run.result["realtime"]["rig_lateness"];
    EXPECT_GE(lateness["max_ms"].get<double>(), 490.0) << lateness.dump(2);
    EXPECT_GE(lateness["worst_at_s"].get<double>(), 3.0) << lateness.dump(2);
    // Its metrics are still reported, for what they are worth.
    EXPECT_TRUE(run.result["metrics"].contains("drive_out_excess_mean_m")) << run.result.dump(2);
    EXPECT_EQ(run.exit, "process exited with status 3") << run.rig_log;
}
