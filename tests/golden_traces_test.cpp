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

// The output's last line, without its newline.
std::string last_line(const std::string& output) {
    std::string text = output;
    while (!text.empty() && text.back() == '\n') text.pop_back();
    return text.substr(text.rfind('\n') + 1);
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
    // Its own exit status: the judging changed, not the controller (every case passed).
    EXPECT_EQ(judged.exit_code, 5) << judged.output;
    EXPECT_NE(judged.output.find("overlap_m"), std::string::npos) << judged.output;
    EXPECT_NE(judged.output.find(changed->at("name").get<std::string>()), std::string::npos) << judged.output;
    EXPECT_EQ(last_line(judged.output),
              "re-judged: 1 difference(s) from the results recorded: the judging changed, whatever the verdicts (exit status 5)");
}

// A case that failed, re-judged as it was recorded: exit status 1 as `rig run`,
// told apart from a changed judging (5) on the last line.
TEST(GoldenTraces, AFailureJudgedAsRecordedExitsOneAndADifferenceFiveWhateverTheVerdicts) {
    const fs::path run = unpacked_run("golden-traces-failed");
    // The run's plan (meta, outside the digest) gets an overlap limit of 0 m, which the repeated strip breaks.
    const fs::path trace = run / "cases" / "golden-breakpoint-continuation" / "trace.sqlite";
    const auto tightened = run_shell("sqlite3 " + quoted(trace) +
                                     " \"update meta set value = json_set(value, '$.limits.overlap_m', 0.0) where key = 'judging'\" 2>&1");
    ASSERT_EQ(tightened.exit_code, 0) << tightened.output;
    // What a run with that plan records.
    const auto recorded = run_shell(kRig + " judge " + quoted(run) + " --out " + quoted(run.parent_path() / "recorded") + " 2>&1");
    ASSERT_EQ(recorded.exit_code, 1) << recorded.output;
    fs::copy_file(run.parent_path() / "recorded" / "results.json", run / "results.json", fs::copy_options::overwrite_existing);

    const auto same = run_shell(kRig + " judge " + quoted(run) + " --check 2>&1");
    EXPECT_EQ(same.exit_code, 1) << same.output;
    EXPECT_EQ(last_line(same.output),
              "re-judged: every metric, verdict and digest as recorded; 1 case(s) failed, as recorded (exit status 1)");

    // The same failed run with one number recorded differently: 5, the failure notwithstanding.
    nlohmann::json results = read_json(run / "results.json");
    for (nlohmann::json& one : results.at("cases")) {
        if (one.at("name") == "golden-breakpoint-continuation") one["metrics"]["overlap_m"] = 99.0;
    }
    std::ofstream(run / "results.json") << results.dump(1);
    const auto differing = run_shell(kRig + " judge " + quoted(run) + " --check 2>&1");
    EXPECT_EQ(differing.exit_code, 5) << differing.output;
    EXPECT_NE(last_line(differing.output).find("(exit status 5)"), std::string::npos) << differing.output;
}

}  // namespace
