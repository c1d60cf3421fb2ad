// The contract's conformance test (docs/controller-contract.md, "Conformance"):
// the example's lockstep case, run once with the example controller (Fast DDS,
// through the SDK) and once with tests/conformance/cyclone_follower (Cyclone
// DDS's C API, written from the IDL and the contract alone, the same algorithm
// ported to C). The Cyclone run must be judged passed, and both runs must leave
// the same trace digest: every sample of every topic, the rig's and the
// controller's, at the same instant and round, bit for bit. That holds only if
// the follower kept the protocol exactly (counted delivery, rounds, acks, next
// wake) and its DDS carried every sample; a controller that answered a tick
// before its inputs were in, or published a round late, changes the digest.
#include <gtest/gtest.h>

#include "../run_support.h"

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;
using rig::testing::read_all;

const fs::path kExampleCase = RIG_SOURCE_DIR "/examples/rtk-breakpoint-controller/case.yaml";

// The example's case with its controller.command replaced by `command` (a YAML
// flow list), written into `dir`: the same case, the same seed.
fs::path case_with_command(const fs::path& dir, const std::string& command) {
    const std::string text = read_all(kExampleCase);
    const std::regex command_line(R"(command: \[[^\]]*\])");
    EXPECT_TRUE(std::regex_search(text, command_line)) << kExampleCase << " has no controller.command list";
    const fs::path file = dir / "case.yaml";
    std::ofstream(file) << std::regex_replace(text, command_line, "command: " + command);
    return file;
}

struct RunOutcome {
    int exit_code = -1;
    nlohmann::json result;  // results.json's one case
    std::string log;        // rig's and the controller's output, for failure messages
};

RunOutcome rig_run(const fs::path& case_file, const fs::path& out) {
    const std::string command = "timeout -k 10 300 '" RIG_BINARY_DIR "/bin/rig' run '" + case_file.string() +
                                "' --out '" + out.string() + "' > '" + (out.string() + ".log") + "' 2>&1";
    const int status = std::system(command.c_str());
    RunOutcome run;
    run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    run.log = read_all(out.string() + ".log") + read_all(out / "cases" / "rtk-breakpoint-controller" / "controller.log");
    if (fs::exists(out / "results.json")) {
        run.result = nlohmann::json::parse(read_all(out / "results.json"))["cases"][0];
    }
    return run;
}

// The RTPS vendor id (first 4 hex digits of the GUID prefix) of the
// participant named `controller`, from the trace's discovery record.
std::string controller_vendor(const fs::path& out) {
    const fs::path trace = out / "cases" / "rtk-breakpoint-controller" / "trace.sqlite";
    return rig::testing::read_all_command(
        "sqlite3 '" + trace.string() +
        "' \"select distinct substr(guid_prefix, 1, 4) from discovery where participant = 'controller'\"");
}

TEST(CycloneConformance, ACycloneFollowerIsJudgedAndLeavesTheFastDdsExamplesTraceDigest) {
    const fs::path dir = rig::testing::fresh_dir("cyclone-conformance");
    fs::create_directories(dir / "cyclone");
    fs::create_directories(dir / "fastdds");
    // The follower under strace: what the kernel sees it send (loopback only,
    // docs/design.md "DDS and the network"; Cyclone's own defaults would multicast).
    const fs::path strace_log = dir / "cyclone" / "strace.log";
    const fs::path cyclone_case = case_with_command(
        dir / "cyclone", "[ strace, -f, -qq, -e, 'trace=sendto,sendmsg,sendmmsg,connect', -o, '" + strace_log.string() +
                             "', '" RIG_CYCLONE_FOLLOWER "', --cyclone-config, '" RIG_CYCLONE_LOOPBACK_CONFIG "' ]");
    const fs::path fastdds_case = case_with_command(dir / "fastdds", "[ '" RIG_CONFORMANCE_EXAMPLE_CONTROLLER "' ]");

    const RunOutcome cyclone = rig_run(cyclone_case, dir / "cyclone" / "out");
    ASSERT_TRUE(cyclone.result.is_object()) << cyclone.log;
    EXPECT_EQ(cyclone.exit_code, 0) << cyclone.log;
    EXPECT_TRUE(cyclone.result["passed"].get<bool>()) << cyclone.result.dump(2) << cyclone.log;
    // Judged from truth, as the example is (Table 4's limits at 6 km/h).
    EXPECT_EQ(cyclone.result["metrics"]["breakpoint_reached_count"].get<double>(), 1.0) << cyclone.result.dump(2);
    EXPECT_LT(cyclone.result["metrics"]["breakpoint_error_m"].get<double>(), 0.55) << cyclone.result.dump(2);
    EXPECT_LT(cyclone.result["metrics"]["breakpoint_store_error_m"].get<double>(), 0.10) << cyclone.result.dump(2);

    const std::set<std::string> destinations = rig::testing::strace_destinations(strace_log);
    EXPECT_TRUE(destinations.count("127.0.0.1")) << "strace saw no send at all: " << read_all(strace_log).substr(0, 2000);
    for (const std::string& destination : destinations) {
        EXPECT_EQ(destination, "127.0.0.1") << "the Cyclone follower sent to " << destination << " (" << strace_log << ")";
    }
    // The controller's participant was Cyclone's: its GUID prefix starts with
    // the RTPS vendor id 01.10 (Eclipse Cyclone DDS), the Fast DDS run's with 01.0f.
    EXPECT_EQ(controller_vendor(dir / "cyclone" / "out"), "0110\n");

    const RunOutcome fastdds = rig_run(fastdds_case, dir / "fastdds" / "out");
    ASSERT_TRUE(fastdds.result.is_object()) << fastdds.log;
    EXPECT_EQ(controller_vendor(dir / "fastdds" / "out"), "010f\n");
    EXPECT_TRUE(fastdds.result["passed"].get<bool>()) << fastdds.result.dump(2) << fastdds.log;

    // Same case, same seed: the same trace, bit for bit.
    const std::string digest = cyclone.result["trace_sha256"].get<std::string>();
    EXPECT_EQ(digest.size(), 64u);
    EXPECT_EQ(digest, fastdds.result["trace_sha256"].get<std::string>())
        << "metrics, Cyclone: " << cyclone.result["metrics"].dump() << "\nmetrics, Fast DDS: " << fastdds.result["metrics"].dump();
    EXPECT_EQ(cyclone.result["metrics"], fastdds.result["metrics"]);
}

}  // namespace
