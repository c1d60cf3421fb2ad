// Golden traces (tests/golden/, made by scripts/golden-traces): small recorded
// runs of both systems, one per scenario, kept with the results.json their run
// wrote. `rig judge --check` on them must find every metric, verdict and
// digest as recorded, so a change to the judge or the reports that moves a
// number fails here in seconds. Nothing here starts DDS: the traces are the
// judge's only input.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "run_support.h"

namespace {

namespace fs = std::filesystem;
using rig::testing::run_shell;

const fs::path kGolden = fs::path(RIG_SOURCE_DIR) / "tests" / "golden";
const std::string kRig = RIG_BINARY_DIR "/bin/rig";

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// A run directory as `rig run` left it: results.json and cases/NAME/trace.sqlite.
fs::path unpacked_run(const std::string& name) {
    const fs::path run = rig::testing::fresh_dir(name) / "run";
    fs::create_directories(run / "cases");
    fs::copy_file(kGolden / "results.json", run / "results.json");
    for (const fs::directory_entry& packed : fs::directory_iterator(kGolden / "traces")) {
        const std::string case_name = packed.path().filename().string().substr(
            0, packed.path().filename().string().size() - std::string(".sqlite.gz").size());
        fs::create_directories(run / "cases" / case_name);
        const auto unpacked = run_shell("gzip -dc " + quoted(packed.path()) + " > " +
                                        quoted(run / "cases" / case_name / "trace.sqlite") + " 2>&1");
        EXPECT_EQ(unpacked.exit_code, 0) << packed.path() << ": " << unpacked.output;
    }
    return run;
}

nlohmann::json read_json(const fs::path& file) {
    std::ifstream in(file);
    return nlohmann::json::parse(in);
}

TEST(GoldenTraces, EveryGoldenTraceIsJudgedAsItsRunRecorded) {
    const fs::path run = unpacked_run("golden-traces");
    const nlohmann::json results = read_json(run / "results.json");
    // One trace per golden case, and both systems among them.
    std::size_t case_files = 0;
    for (const fs::directory_entry& file : fs::directory_iterator(kGolden / "cases")) {
        case_files += file.path().extension() == ".yaml" ? 1 : 0;
    }
    ASSERT_EQ(results.at("cases").size(), case_files) << "run scripts/golden-traces after adding a golden case";
    std::set<std::string> systems;
    for (const nlohmann::json& one : results.at("cases")) {
        const fs::path trace = run / "cases" / one.at("name").get<std::string>() / "trace.sqlite";
        ASSERT_TRUE(fs::exists(trace)) << trace;
        const auto system = run_shell("sqlite3 " + quoted(trace) + " \"select value from meta where key = 'system'\"");
        ASSERT_EQ(system.exit_code, 0) << system.output;
        systems.insert(system.output.substr(0, system.output.find('\n')));
    }
    EXPECT_EQ(systems, (std::set<std::string>{"breakpoint", "boundary"}));

    const auto judged = run_shell(kRig + " judge " + quoted(run) + " --check --out " + quoted(run.parent_path() / "again") +
                                  " 2>&1");
    EXPECT_EQ(judged.exit_code, 0) << judged.output;
    EXPECT_NE(judged.output.find("re-judged: every metric, verdict and digest as recorded"), std::string::npos)
        << judged.output;
    // The reports are written from the traces alone too.
    EXPECT_TRUE(fs::exists(run.parent_path() / "again" / "report.html"));
    EXPECT_EQ(read_json(run.parent_path() / "again" / "results.json").at("cases").size(), case_files);
}

// The check can fail: one metric of one case recorded differently is named.
TEST(GoldenTraces, ANumberJudgedDifferentlyFailsTheCheckNamingIt) {
    const fs::path run = unpacked_run("golden-traces-changed");
    nlohmann::json results = read_json(run / "results.json");
    nlohmann::json* changed = nullptr;
    for (nlohmann::json& one : results.at("cases")) {
        if (one.at("metrics").contains("overlap_m")) changed = &one;
    }
    ASSERT_NE(changed, nullptr) << "a golden continuation case judges overlap_m";
    nlohmann::json& overlap = (*changed)["metrics"]["overlap_m"];
    if (overlap.is_object()) {
        overlap["value"] = overlap.at("value").get<double>() + 0.05;
    } else {
        overlap = overlap.get<double>() + 0.05;
    }
    std::ofstream(run / "results.json") << results.dump(1);
    const auto judged = run_shell(kRig + " judge " + quoted(run) + " --check 2>&1");
    EXPECT_EQ(judged.exit_code, 1) << judged.output;
    EXPECT_NE(judged.output.find("overlap_m"), std::string::npos) << judged.output;
    EXPECT_NE(judged.output.find(changed->at("name").get<std::string>()), std::string::npos) << judged.output;
}

}  // namespace
