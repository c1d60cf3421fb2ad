// `rig bench` (issue 11): it runs, prints one table with the DDS floor and the
// modes in both placements, and writes bench.json with what it measured. Behaviour only: the
// numbers are the machine's (a loaded CI runner's are not a claim), so nothing
// here asserts a speed.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "run_support.h"

namespace {

using rig::testing::fresh_dir;
using rig::testing::read_all;
using rig::testing::read_all_command;

TEST(SpeedBench, PrintsTheFloorAndBothModesAndWritesBenchJson) {
    const std::filesystem::path dir = fresh_dir("speed_bench");
    const std::string output = read_all_command(
        std::string(RIG_BINARY_DIR) + "/bin/rig bench " + RIG_SOURCE_DIR +
        "/cases/table5-6-continuation/continuation-6kmh.yaml --repeat 1 --pingpong-rounds 50 --out " + dir.string() +
        " 2>&1; echo \"exit=$?\"");
    EXPECT_NE(output.find("exit=0"), std::string::npos) << output;
    // Both placements (rig/host/cpu_lease.h): the floor and process mode on one leased CPU and on any.
    EXPECT_NE(output.find("DDS ping-pong, 2 processes, 1 CPU"), std::string::npos) << output;
    EXPECT_NE(output.find("process mode, 1 CPU (default)"), std::string::npos) << output;
    EXPECT_NE(output.find("in process (SIL), 1 CPU"), std::string::npos) << output;
    EXPECT_NE(output.find("DDS ping-pong, 2 processes, any CPU"), std::string::npos) << output;
    EXPECT_NE(output.find("process mode, any CPU (--no-pin)"), std::string::npos) << output;
    EXPECT_NE(output.find("trace digests identical in every run of every mode"), std::string::npos) << output;

    ASSERT_TRUE(std::filesystem::exists(dir / "bench.json")) << output;
    const nlohmann::json bench = nlohmann::json::parse(read_all(dir / "bench.json"));
    EXPECT_TRUE(bench.at("digests_identical").get<bool>());
    for (const char* floor : {"pingpong", "pingpong_unpinned"}) {
        SCOPED_TRACE(floor);
        EXPECT_EQ(bench.at(floor).at("rounds").get<int>(), 50);
        EXPECT_GT(bench.at(floor).at("p50_us").get<double>(), 0.0);
    }
    EXPECT_TRUE(bench.at("thread_id_cache").get<bool>());
    EXPECT_NE(output.find("context switches a round"), std::string::npos) << output;
    // Every round of process mode hands off to the controller's process and back.
    EXPECT_GT(bench.at("process").at("context_switches_per_round").get<double>(), 1.0);
    EXPECT_GT(bench.at("pingpong").at("context_switches_per_round").get<double>(), 1.0);
    for (const char* mode : {"process", "process_unpinned", "in_process"}) {
        SCOPED_TRACE(mode);
        const nlohmann::json& figures = bench.at(mode);
        // One run of a 66.7 s case on the 100 Hz device grid: thousands of rounds.
        EXPECT_GT(figures.at("rounds").get<std::uint64_t>(), 6000u);
        EXPECT_GT(figures.at("us_per_round").get<double>(), 0.0);
        EXPECT_GT(figures.at("x_real_time").get<double>(), 0.0);
        EXPECT_GT(figures.at("trace_bytes_per_sim_minute").get<double>(), 0.0);
        EXPECT_GT(figures.at("startup_p50_s").get<double>(), 0.0);
    }
    // Allocations a round on the lockstep's thread (rig/host/heap_count.h): the
    // rig executable counts them. In process the samples are handed over with
    // no DDS write, history or take on that thread (rig::LocalBus), so a round
    // allocates less than process mode's, whose every sample goes through Fast DDS.
    EXPECT_NE(output.find("heap allocations a round while stepping"), std::string::npos) << output;
    EXPECT_GT(bench.at("process").at("allocations_per_round").get<double>(), 0.0);
    EXPECT_LT(bench.at("in_process").at("allocations_per_round").get<double>(),
              bench.at("process").at("allocations_per_round").get<double>());
    // Every mode recorded the same samples (their digests are the same, above):
    // the same trace size, but for the pages of `meta`, whose text says the mode
    // and the controller's command, so that in process mode it may take a page
    // or two of 4 KiB more in a file of about 7 MB (0.5 % is 8 such pages).
    const double process_bytes = bench.at("process").at("trace_bytes_per_sim_minute").get<double>();
    for (const char* mode : {"in_process", "process_unpinned"}) {
        SCOPED_TRACE(mode);
        EXPECT_NEAR(bench.at(mode).at("trace_bytes_per_sim_minute").get<double>(), process_bytes, 0.005 * process_bytes);
    }
}

TEST(SpeedBench, WithDdsSecurityAddsTheSecuredFloorAndProcessModeWithTheSameDigest) {
    const std::filesystem::path dir = fresh_dir("speed_bench_dds_security");
    const std::string output = read_all_command(
        std::string(RIG_BINARY_DIR) + "/bin/rig bench " + RIG_SOURCE_DIR +
        "/cases/table5-6-continuation/continuation-6kmh.yaml --repeat 1 --pingpong-rounds 50 --dds-security --out " +
        dir.string() + " 2>&1; echo \"exit=$?\"");
    EXPECT_NE(output.find("exit=0"), std::string::npos) << output;
    EXPECT_NE(output.find("DDS ping-pong, DDS-Security"), std::string::npos) << output;
    EXPECT_NE(output.find("process mode, DDS-Security"), std::string::npos) << output;
    EXPECT_NE(output.find("us per round in process mode"), std::string::npos) << output;
    EXPECT_NE(output.find("trace digests identical in every run of every mode"), std::string::npos) << output;
    ASSERT_TRUE(std::filesystem::exists(dir / "bench.json")) << output;
    const nlohmann::json bench = nlohmann::json::parse(read_all(dir / "bench.json"));
    EXPECT_TRUE(bench.at("digests_identical").get<bool>());
    EXPECT_EQ(bench.at("pingpong_dds_security").at("rounds").get<int>(), 50);
    EXPECT_GT(bench.at("pingpong_dds_security").at("p50_us").get<double>(), 0.0);
    EXPECT_EQ(bench.at("process_dds_security").at("rounds"), bench.at("process").at("rounds"));
    EXPECT_GT(bench.at("process_dds_security").at("us_per_round").get<double>(), 0.0);
    EXPECT_TRUE(std::filesystem::exists(dir / "security" / "controller" / "cert.pem"));
}

TEST(SpeedBench, ARealTimeCaseIsRefusedNamingWhy) {
    const std::filesystem::path dir = fresh_dir("speed_bench_realtime");
    const std::string output = read_all_command(std::string(RIG_BINARY_DIR) + "/bin/rig bench " + RIG_SOURCE_DIR +
                                                "/cases/bench-wired/continuation-6kmh-wired-rtu.yaml --out " +
                                                dir.string() + " 2>&1; echo \"exit=$?\"");
    EXPECT_NE(output.find("exit=2"), std::string::npos) << output;
    EXPECT_NE(output.find("real-time case runs at 1x"), std::string::npos) << output;
}

}  // namespace
