// External boards (`wiring: { controller: external }`, docs/modbus-register-map.md
// "External boards"): `rig run` as a bench user runs it, with tests/board_player
// as the board. The rig must say where to attach (stdout and attach.json) before
// case time starts, wait for the board, fail a board that goes quiet on Modbus
// at once naming the silence, and fail a board that never comes as
// board_not_attached; every ending writes results.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "rig/host/child_process.h"
#include "rig/runtime/clock.h"
#include "run_support.h"

namespace fs = std::filesystem;
using rig::testing::fresh_dir;
using rig::testing::read_all;

namespace {

// The bench's wired case, the Table 5/6 continuation in real time, with the
// board outside the rig: the reference controller's section dropped, the
// wiring's controller made external.
const std::string kCaseName = "continuation-6kmh-wired-rtu";

// That case, with `board_section` (a `board:` mapping) added unless it is empty.
fs::path write_case(const fs::path& dir, const std::string& board_section) {
    const fs::path file = dir / (kCaseName + ".yaml");
    std::string text = read_all(RIG_SOURCE_DIR "/cases/bench-wired/" + kCaseName + ".yaml");
    const std::size_t controller = text.find("\ncontroller:");
    if (controller == std::string::npos) throw std::runtime_error("the wired case has no controller section");
    text.erase(controller + 1);  // it is the file's last section
    const std::size_t wiring = text.find("\nwiring:\n");
    if (wiring == std::string::npos) throw std::runtime_error("the wired case has no wiring section");
    text.insert(wiring + std::string("\nwiring:\n").size(), "  controller: external\n");
    std::ofstream(file) << text << board_section;
    return file;
}

struct BoardRun {
    std::string exit;
    std::string rig_log;
    std::string board_log;
    nlohmann::json result;  // results.json cases[0]
    nlohmann::json attach;  // attach.json
};

// `rig run` on the case, with a board player given `board_args` (none: no board).
// Waits for both, bounded far above what any of these runs needs.
BoardRun run_with_board(const fs::path& dir, const fs::path& case_file, std::optional<std::vector<std::string>> board_args) {
    const fs::path out = dir / "out";
    const fs::path attach_file = out / "cases" / kCaseName / "attach.json";
    rig::ChildProcess rig_run({RIG_BINARY_DIR "/bin/rig", "run", case_file.string(), "--out", out.string()},
                              dir / "rig.log");
    std::optional<rig::ChildProcess> board;
    if (board_args) {
        std::vector<std::string> argv = {RIG_BOARD_PLAYER, "--attach", attach_file.string()};
        argv.insert(argv.end(), board_args->begin(), board_args->end());
        board.emplace(argv, dir / "board.log");
    }
    const rig::RealtimeClock clock;
    BoardRun run;
    for (;;) {
        if (auto ended = rig_run.exit_description()) {
            run.exit = *ended;
            break;
        }
        if (rig::ns_to_seconds(clock.now_ns()) > 400.0) {
            run.exit = "still running after 400 s: " + rig_run.stop();
            break;
        }
        clock.sleep_until_ns(clock.now_ns() + rig::seconds_to_ns(0.1));
    }
    // The board sees the rig close its wires and ends by itself.
    if (board) board->stop(std::chrono::milliseconds(10000));
    run.rig_log = read_all(dir / "rig.log");
    run.board_log = read_all(dir / "board.log");
    const std::string results = read_all(out / "results.json");
    if (!results.empty()) run.result = nlohmann::json::parse(results)["cases"][0];
    const std::string attach = read_all(attach_file);
    if (!attach.empty()) run.attach = nlohmann::json::parse(attach);
    return run;
}

std::string port_path(const nlohmann::json& attach, const std::string& role) {
    for (const nlohmann::json& port : attach.value("ports", nlohmann::json::array())) {
        if (port.value("role", "") == role) return port.value("path", "");
    }
    return {};
}

}  // namespace

// The board attaches from attach.json, the case clock starts after it has, and
// it passes the wired breakpoint continuation on its own firmware, judged with
// the paper's limits as the reference controller is.
TEST(ExternalBoardRealTime, ABoardWrittenFromTheDocsAttachesAndPasses) {
    const fs::path dir = fresh_dir("external-board-pass");
    // Timeouts generous against a loaded machine's stalls (the defaults are 1 s and 2 s).
    const BoardRun run = run_with_board(dir, write_case(dir, "board: { failsafe_timeout_s: 2, silence_timeout_s: 5 }\n"),
                                        std::vector<std::string>{"--target-l-min", "20", "--gnss-latency-s", "0.1"});
    const std::string context = run.rig_log + "\n--- board:\n" + run.board_log;
    EXPECT_EQ(run.exit, "process exited with status 0") << context;
    ASSERT_TRUE(run.result.is_object()) << context;
    EXPECT_TRUE(run.result["passed"].get<bool>()) << run.result.dump(2) << context;
    // Judged as a continuation: the breakpoint was reached once, the flow
    // settled, nothing was missed (passed says each is within its limit).
    const nlohmann::json& metrics = run.result["metrics"];
    EXPECT_EQ(metrics.value("breakpoint_reached_count", 0.0), 1.0) << metrics.dump(2);
    for (const char* judged : {"breakpoint_error_m", "flow_adjust_time_s", "flow_error_pct", "missed_m", "overlap_m"}) {
        EXPECT_TRUE(metrics.contains(judged)) << judged << " not measured: " << metrics.dump(2);
    }
    EXPECT_EQ(run.result["limits"].value("flow_adjust_time_s", 0.0), 1.7) << run.result["limits"].dump();

    // Where to attach: one stdout line naming both ports, and attach.json.
    const std::string nmea = port_path(run.attach, "gnss_nmea");
    const std::string modbus = port_path(run.attach, "modbus_rtu");
    EXPECT_EQ(nmea.rfind("/dev/pts/", 0), 0u) << run.attach.dump(2);
    EXPECT_EQ(modbus.rfind("/dev/pts/", 0), 0u) << run.attach.dump(2);
    EXPECT_NE(run.rig_log.find("attach: gnss_nmea=" + nmea + " modbus_rtu=" + modbus + " (case " + kCaseName),
              std::string::npos)
        << run.rig_log;
    EXPECT_EQ(run.attach["attach_timeout_s"], 60.0);

    // Both attach events were seen, and the case time started after them.
    const nlohmann::json& board_io = run.result["realtime"]["board_io"];
    ASSERT_TRUE(board_io.is_object()) << run.result.dump(2);
    ASSERT_EQ(board_io["attach"]["seen"].size(), 2u) << board_io.dump(2);
    EXPECT_NE(board_io["attach"]["seen"][0].get<std::string>().find("gnss_nmea " + nmea + " opened by pid"),
              std::string::npos);
    EXPECT_GE(run.result["startup_wall_seconds"].get<double>(), board_io["attach"]["waited_s"].get<double>());
    // The board polled all along; counts per kind are there.
    EXPECT_GT(board_io["valid_requests"].get<int>(), 500) << board_io.dump(2);
    EXPECT_EQ(board_io["failsafe"]["timeout_s"], 2.0) << board_io.dump(2);
    for (const char* kind : {"bad_crc", "wrong_address", "malformed", "response_not_sent"}) {
        EXPECT_TRUE(board_io["dropped"].contains(kind)) << kind;
    }
    for (const char* kind : {"illegal_function", "illegal_data_address", "illegal_data_value"}) {
        EXPECT_EQ(board_io["refused"][kind], 0) << kind << board_io.dump(2);
    }
    // The board read the NMEA line (it counts the sentences it parsed).
    EXPECT_NE(run.board_log.find("GGA"), std::string::npos) << run.board_log;
    // The HTML report shows the board I/O.
    EXPECT_NE(read_all(dir / "out" / "report.html").find("Board I/O (Modbus)"), std::string::npos);
}

// A board that stops polling mid-case: the case fails at once as board_silent,
// naming how long and since when; the fail-safe de-energised the outputs first.
TEST(ExternalBoardRealTime, ABoardThatStopsPollingFailsNamingTheSilence) {
    const fs::path dir = fresh_dir("external-board-silent");
    // Quiet after 15 s of polling (after its valve reset, on the first pass).
    const BoardRun run = run_with_board(dir, write_case(dir, "board: { silence_timeout_s: 2, failsafe_timeout_s: 1 }\n"),
                                   std::vector<std::string>{"--stop-polling-after-s", "15"});
    const std::string context = run.rig_log + "\n--- board:\n" + run.board_log;
    ASSERT_TRUE(run.result.is_object()) << context;
    EXPECT_FALSE(run.result["passed"].get<bool>());
    EXPECT_EQ(run.result["error_kind"], "board_silent") << run.result.dump(2);
    const std::string error = run.result["error"].is_string() ? run.result["error"].get<std::string>() : "";
    const std::string silent_for = "the Modbus master has been silent for ";
    const std::size_t at = error.find(silent_for);
    ASSERT_NE(at, std::string::npos) << error;
    // Found once the silence passed the timeout (the rig looks after every step,
    // at least every 10 ms; a loaded machine may be late by a little).
    const double silent_s = std::stod(error.substr(at + silent_for.size()));
    EXPECT_GE(silent_s, 2.0) << error;
    EXPECT_LT(silent_s, 4.0) << error;
    EXPECT_NE(error.find("board.silence_timeout_s = 2.00 s"), std::string::npos) << error;
    EXPECT_NE(error.find("its last valid request came at case time t="), std::string::npos) << error;
    // Within the timeout of the silence: the case ended about 2 s after the last
    // request, far before its 38 s (the margin is for a loaded machine).
    const double sim_s = run.result["sim_seconds"].get<double>();
    EXPECT_LT(sim_s, 30.0) << error;
    EXPECT_GT(sim_s, 10.0) << error;
    const nlohmann::json& board_io = run.result["realtime"]["board_io"];
    EXPECT_EQ(board_io["failsafe"]["trips"], 1) << board_io.dump(2);
    EXPECT_EQ(board_io["failsafe"]["mode"], "safe");
}

// No board at all: board_not_attached after the case's attach timeout, results written.
TEST(ExternalBoardRealTime, ABoardThatNeverAttachesFailsAsNotAttached) {
    const fs::path dir = fresh_dir("external-board-absent");
    const BoardRun run = run_with_board(dir, write_case(dir, "board: { attach_timeout_s: 1 }\n"), std::nullopt);
    EXPECT_EQ(run.exit, "process exited with status 1") << run.rig_log;
    ASSERT_TRUE(run.result.is_object()) << run.rig_log;
    EXPECT_EQ(run.result["error_kind"], "board_not_attached") << run.result.dump(2);
    const std::string error = run.result["error"].is_string() ? run.result["error"].get<std::string>() : "";
    EXPECT_NE(error.find("not attached within board.attach_timeout_s = 1.0 s"), std::string::npos) << error;
    EXPECT_NE(error.find("no process opened the GNSS NMEA line /dev/pts/"), std::string::npos) << error;
    EXPECT_NE(error.find("no valid Modbus request came on /dev/pts/"), std::string::npos) << error;
    // No case time passed: the clock never started.
    EXPECT_EQ(run.result["sim_seconds"].get<double>(), 0.0);
    EXPECT_EQ(run.attach["attach_timeout_s"], 1.0);
    EXPECT_NE(run.rig_log.find("attach: gnss_nmea=/dev/pts/"), std::string::npos) << run.rig_log;
}
