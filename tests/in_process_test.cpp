// Software-in-the-loop (issue 11): the reference controller loaded as a plugin
// and stepped inside the rig's process gives the trace process mode gives, bit
// for bit; what cannot run in process says so and runs as a process; the rig
// still judges an in-process controller's topic roles; bad plugins are refused
// by name.
#include <gtest/gtest.h>

#include <cstdlib>
#include <regex>

#include <nlohmann/json.hpp>

#include "rig/host/node_plugin_loader.h"
#include "run_support.h"

namespace {

using rig::testing::fresh_dir;
using rig::testing::read_all;
using rig::testing::read_all_command;

const std::filesystem::path kRig = std::filesystem::path(RIG_BINARY_DIR) / "bin" / "rig";
const std::filesystem::path kCases = std::filesystem::path(RIG_SOURCE_DIR) / "cases";

struct RunResult {
    int exit_code = -1;
    std::string output;
    nlohmann::json results;
};

RunResult rig_run(const std::string& args, const std::filesystem::path& out) {
    RunResult run;
    const std::string command = kRig.string() + " run " + args + " --out " + out.string() + " 2>&1; echo \"exit=$?\"";
    run.output = read_all_command(command);
    std::smatch exit_code;
    if (std::regex_search(run.output, exit_code, std::regex("exit=(\\d+)\\s*$"))) run.exit_code = std::stoi(exit_code[1]);
    if (std::filesystem::exists(out / "results.json")) run.results = nlohmann::json::parse(read_all(out / "results.json"));
    return run;
}

const nlohmann::json& only_case(const RunResult& run) {
    static const nlohmann::json none;
    if (!run.results.contains("cases") || run.results["cases"].size() != 1) {
        ADD_FAILURE() << "expected one case in results.json; rig said:\n" << run.output;
        return none;
    }
    return run.results["cases"][0];
}

TEST(InProcess, SameCaseAndSeedGiveTheSameTraceInBothModes) {
    const std::filesystem::path dir = fresh_dir("in_process_same_digest");
    const std::string case_file = (kCases / "table5-6-continuation" / "continuation-6kmh.yaml").string();
    const RunResult process = rig_run(case_file, dir / "process");
    const RunResult in_process = rig_run(case_file + " --in-process", dir / "in-process");
    ASSERT_EQ(process.exit_code, 0) << process.output;
    ASSERT_EQ(in_process.exit_code, 0) << in_process.output;
    const nlohmann::json& a = only_case(process);
    const nlohmann::json& b = only_case(in_process);
    EXPECT_EQ(a.value("controller_mode", ""), "process");
    EXPECT_EQ(b.value("controller_mode", ""), "in_process");
    EXPECT_TRUE(a.value("passed", false));
    EXPECT_TRUE(b.value("passed", false));
    ASSERT_FALSE(a.value("trace_sha256", "").empty());
    EXPECT_EQ(a.value("trace_sha256", ""), b.value("trace_sha256", "")) << "the in-process trace differs";
    EXPECT_EQ(a["metrics"], b["metrics"]);
    // In process the samples are handed over without DDS (rig/runtime/dds_context.h
    // LocalBus): the same instants and the same rounds as over DDS.
    EXPECT_EQ(a.value("instants", 0), b.value("instants", 0));
    EXPECT_GT(a.value("rounds", 0), 0);
    EXPECT_EQ(a.value("rounds", 0), b.value("rounds", 0));
}

TEST(InProcess, TheFusionCaseGivesTheSameTraceInBothModesAndRunToRun) {
    // Every device of seed 000 and the reference plugin, its samples handed
    // over in the rig's process (rig/runtime/dds_context.h LocalBus).
    const std::filesystem::path dir = fresh_dir("in_process_fusion_digest");
    const std::string case_file = (kCases / "table3-fusion" / "table3-fusion-6kmh-s1.yaml").string();
    const RunResult process = rig_run(case_file, dir / "process");
    const RunResult first = rig_run(case_file + " --in-process", dir / "first");
    const RunResult second = rig_run(case_file + " --in-process", dir / "second");
    ASSERT_EQ(process.exit_code, 0) << process.output;
    ASSERT_EQ(first.exit_code, 0) << first.output;
    ASSERT_EQ(second.exit_code, 0) << second.output;
    const std::string digest = only_case(process).value("trace_sha256", "");
    ASSERT_FALSE(digest.empty());
    EXPECT_EQ(only_case(first).value("controller_mode", ""), "in_process");
    EXPECT_EQ(only_case(first).value("trace_sha256", ""), digest);
    EXPECT_EQ(only_case(second).value("trace_sha256", ""), digest);
    EXPECT_EQ(only_case(first).value("rounds", 0), only_case(process).value("rounds", 0));
}

TEST(InProcess, AForgedTruthTopicIsCaughtInProcessToo) {
    // The plugin's participant lives in the rig's process: it must still be
    // judged as the controller's, not taken for the rig's own.
    const std::filesystem::path dir = fresh_dir("in_process_forged_truth");
    const RunResult run =
        rig_run((kCases / "faulty-controllers" / "forges-truth-topic.yaml").string() + " --seed 1 --in-process", dir);
    ASSERT_EQ(run.exit_code, 0) << run.output;  // the expected failure happened: the case passes
    const nlohmann::json& result = only_case(run);
    EXPECT_EQ(result.value("controller_mode", ""), "in_process");
    EXPECT_EQ(result.value("error_kind", ""), "topic_role_violation") << run.output;
}

// A malformed actuator command (issue 29) ends the case the same way whether
// the controller is a process or a plugin: same error, same instant, same trace.
TEST(InProcess, AMalformedCommandFailsTheCaseAsInProcessMode) {
    const std::filesystem::path dir = fresh_dir("in_process_malformed");
    const std::string case_file = (kCases / "faulty-controllers" / "wrong-section-count.yaml").string() + " --seed 1";
    const RunResult process = rig_run(case_file, dir / "process");
    const RunResult in_process = rig_run(case_file + " --in-process", dir / "in-process");
    ASSERT_EQ(process.exit_code, 0) << process.output;  // the expected failure happened: the case passes
    ASSERT_EQ(in_process.exit_code, 0) << in_process.output;
    const nlohmann::json& a = only_case(process);
    const nlohmann::json& b = only_case(in_process);
    EXPECT_EQ(b.value("controller_mode", ""), "in_process");
    EXPECT_EQ(a.value("error_kind", ""), "malformed_command") << a.dump(2);
    EXPECT_EQ(b.value("error_kind", ""), "malformed_command") << b.dump(2);
    const auto first_line = [](const std::string& message) { return message.substr(0, message.find('\n')); };
    const std::string error = first_line(b.value("error", ""));
    EXPECT_NE(error.find("node 'controller': actuator/section_valves/open at t="), std::string::npos) << error;
    EXPECT_EQ(first_line(a.value("error", "")), error);
    ASSERT_FALSE(a.value("trace_sha256", "").empty());
    EXPECT_EQ(a.value("trace_sha256", ""), b.value("trace_sha256", "")) << "the in-process trace differs";
}

TEST(InProcess, AFaultThatWouldKillTheRigRunsAsAProcessAndSaysWhy) {
    const std::filesystem::path dir = fresh_dir("in_process_refused");
    const RunResult run = rig_run((kCases / "faulty-controllers" / "crashes-mid-case.yaml").string() + " --seed 1 --in-process", dir);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const nlohmann::json& result = only_case(run);
    EXPECT_EQ(result.value("controller_mode", ""), "process");
    EXPECT_NE(result.value("in_process_refused", "").find("crash_at_s"), std::string::npos) << result.dump(2);
    EXPECT_EQ(result.value("error_kind", ""), "node_exited");
}

TEST(InProcess, ACaseAskingInProcessInRealTimeIsRefusedAtLoadNamingTheKey) {
    const std::filesystem::path dir = fresh_dir("in_process_realtime");
    std::string text = read_all(kCases / "bench-wired" / "continuation-6kmh-wired-rtu.yaml");
    const std::size_t controller = text.find("\ncontroller:\n");
    ASSERT_NE(controller, std::string::npos);
    text.insert(controller + std::string("\ncontroller:\n").size(), "  in_process: true\n");
    const std::filesystem::path case_file = dir / "realtime-in-process.yaml";
    std::ofstream(case_file) << text;
    const RunResult run = rig_run(case_file.string(), dir / "out");
    EXPECT_NE(run.exit_code, 0);
    EXPECT_NE(run.output.find("realtime-in-process.yaml"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("in_process"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("lockstep"), std::string::npos) << run.output;
}

TEST(InProcess, TheReferenceControllersKeysAreCheckedThroughItsPluginWithTheirLine) {
    const std::filesystem::path dir = fresh_dir("in_process_config_check");
    std::string text = read_all(kCases / "table5-6-continuation" / "continuation-6kmh.yaml");
    const std::size_t controller = text.find("\ncontroller:\n");
    ASSERT_NE(controller, std::string::npos);
    text.insert(controller + std::string("\ncontroller:\n").size(), "  threshold_meters: 5\n");
    const std::filesystem::path case_file = dir / "bad-key.yaml";
    std::ofstream(case_file) << text;
    const RunResult run = rig_run(case_file.string(), dir / "out");
    EXPECT_NE(run.exit_code, 0);
    EXPECT_NE(run.output.find("bad-key.yaml:"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("threshold_meters"), std::string::npos) << run.output;
}

TEST(NodePluginLoader, RefusesWhatIsNotARigPluginByName) {
    try {
        rig::NodePluginLibrary::open(RIG_NOT_A_PLUGIN);
        FAIL() << "loaded a library without the plugin entry points";
    } catch (const std::runtime_error& error) {
        EXPECT_NE(std::string(error.what()).find("not a rig node plugin"), std::string::npos) << error.what();
        EXPECT_NE(std::string(error.what()).find("not_a_plugin"), std::string::npos) << error.what();
    }
    try {
        rig::NodePluginLibrary::open("/nonexistent/plugin.so");
        FAIL() << "opened a file that does not exist";
    } catch (const std::runtime_error& error) {
        EXPECT_NE(std::string(error.what()).find("/nonexistent/plugin.so: no such file"), std::string::npos) << error.what();
    }
    // A text file named .so: dlopen's own reason, with the file's name.
    const std::filesystem::path fake = fresh_dir("in_process_fake_so") / "fake.so";
    std::ofstream(fake) << "not an ELF file\n";
    try {
        rig::NodePluginLibrary::open(fake);
        FAIL() << "loaded a text file";
    } catch (const std::runtime_error& error) {
        EXPECT_NE(std::string(error.what()).find("fake.so: cannot load"), std::string::npos) << error.what();
    }
}

TEST(NodePluginLoader, TheReferencePluginMatchesThisRigsAbi) {
    const auto library = rig::NodePluginLibrary::open(RIG_REFERENCE_PLUGIN);
    EXPECT_TRUE(library->has_config_check());
    // A section with an unknown key: the error names the file, line and key.
    const std::string error = library->check_config(rig::NodePluginCaseText{
        "case.yaml", "name: x\ncontroller:\n  positioning: fusion\n  no_such_key: 1\n", "controller"});
    EXPECT_NE(error.find("case.yaml:4"), std::string::npos) << error;
    EXPECT_NE(error.find("no_such_key"), std::string::npos) << error;
    EXPECT_EQ(library->check_config(rig::NodePluginCaseText{"case.yaml", "name: x\n", "controller"}), "");
}

}  // namespace
