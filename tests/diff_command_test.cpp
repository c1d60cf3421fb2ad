// `rig diff` (docs/diff.md) on real runs of one short lockstep case (the
// golden static-flow test, 18 s simulated), each run once in process: the
// same controller twice is the same behaviour; the reference controller with
// other PID gains parts first on an actuator topic, named with its instant;
// another seed parts first on a device or truth topic, and the case or the
// rig is named, not the controller. Then the page, and bad inputs, each
// refused with exit status 2 naming what is wrong.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include <nlohmann/json.hpp>

#include "run_support.h"
#include "tool_support.h"

namespace {

namespace fs = std::filesystem;
using rig::testing::read_all;
using rig::testing::run_shell;

const fs::path kRig = fs::path(RIG_BINARY_DIR) / "bin" / "rig";
const fs::path kCaseFile = fs::path(RIG_SOURCE_DIR) / "tests" / "golden" / "cases" / "static-flow.yaml";
const std::string kCaseName = "golden-static-flow";
// The line of the case that sets the controller, and the same with PID gains
// five times the reference controller's own.
const std::string kControllerLine = "controller: { target_flow_l_min: 20, min_spray_speed_km_h: 0 }";
const std::string kChangedControllerLine =
    "controller: { target_flow_l_min: 20, min_spray_speed_km_h: 0, pid: { kp: 1.0, ki: 0.9, kd: 0.005 } }";

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// Whether `text` holds `part`; when not, the message shows the whole text.
::testing::AssertionResult says(const std::string& text, const std::string& part) {
    if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess() << "\"" << part << "\" in:\n" << text;
    return ::testing::AssertionFailure() << "no \"" << part << "\" in:\n" << text;
}

// Whether `text` holds every one of `parts`; when not, the message names the first missing.
::testing::AssertionResult says_all(const std::string& text, std::initializer_list<std::string> parts) {
    for (const std::string& part : parts) {
        if (!says(text, part)) return says(text, part);
    }
    return ::testing::AssertionSuccess();
}

// A golden trace (tests/golden/traces/NAME.sqlite.gz) unpacked to `file`.
bool unpacked_golden_trace(const std::string& name, const fs::path& file) {
    const fs::path packed = fs::path(RIG_SOURCE_DIR) / "tests" / "golden" / "traces" / (name + ".sqlite.gz");
    return run_shell("gzip -dc " + quoted(packed) + " > " + quoted(file)).exit_code == 0;
}

rig::testing::ShellResult rig(const std::string& arguments) { return run_shell(kRig.string() + " " + arguments + " 2>&1"); }

// The runs every test compares, made once: the case twice, the case with the
// changed controller, and the case with another seed.
class RigDiff : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir_ = new fs::path(rig::testing::fresh_dir("rig_diff"));
        std::string text = read_all(kCaseFile);
        const std::size_t at = text.find(kControllerLine);
        ASSERT_NE(at, std::string::npos) << kCaseFile << " no longer has the line " << kControllerLine;
        const fs::path changed_case = *dir_ / "static-flow-changed-controller.yaml";
        std::ofstream(changed_case) << text.replace(at, kControllerLine.size(), kChangedControllerLine);
        for (const auto& [out, arguments] : {std::pair{"same-1", quoted(kCaseFile)},
                                             std::pair{"same-2", quoted(kCaseFile)},
                                             std::pair{"changed-controller", quoted(changed_case)},
                                             std::pair{"other-seed", quoted(kCaseFile) + " --seed 3"}}) {
            const auto run = rig("run " + arguments + " --in-process --quiet --out " + quoted(*dir_ / out));
            ASSERT_EQ(run.exit_code, 0) << out << ":\n" << run.output;
        }
    }
    static void TearDownTestSuite() { delete dir_; }

    static fs::path run(const std::string& name) { return *dir_ / name; }
    static fs::path trace(const std::string& name) { return *dir_ / name / "cases" / kCaseName / "trace.sqlite"; }

    static fs::path* dir_;
};
fs::path* RigDiff::dir_ = nullptr;

TEST_F(RigDiff, OneSeedAndTheSameControllerIsTheSameBehaviour) {
    const auto diff = rig("diff " + quoted(run("same-1")) + " " + quoted(run("same-2")));
    EXPECT_EQ(diff.exit_code, 0) << diff.output;
    EXPECT_TRUE(says_all(diff.output, {"same behaviour", "seed: 2 in both",
                                       "metrics (A: its results.json; B: its results.json)"}));
    EXPECT_FALSE(says(diff.output, "the runs part"));
    EXPECT_FALSE(says(diff.output, "differs"));

    // The bare traces the same, their metrics judged from them.
    const auto traces = rig("diff " + quoted(trace("same-1")) + " " + quoted(trace("same-2")));
    EXPECT_EQ(traces.exit_code, 0) << traces.output;
    EXPECT_TRUE(says_all(traces.output, {"same behaviour", "judged from its trace", "flow_adjust_time_s"}));

    // A case's directory names its trace; a run directory without results.json
    // (a sweep's) its cases.
    const auto case_dirs = rig("diff " + quoted(trace("same-1").parent_path()) + " " + quoted(trace("same-2").parent_path()));
    EXPECT_EQ(case_dirs.exit_code, 0) << case_dirs.output;
    const fs::path without_results = *dir_ / "same-2-without-results";
    fs::create_directories(without_results / "cases");
    fs::copy(run("same-2") / "cases", without_results / "cases", fs::copy_options::recursive);
    const auto without = rig("diff " + quoted(run("same-1")) + " " + quoted(without_results));
    EXPECT_EQ(without.exit_code, 0) << without.output;
    EXPECT_TRUE(says(without.output, "metrics (A: its results.json; B: judged from its trace)"));
}

TEST_F(RigDiff, AChangedControllerIsNamedByTheFirstActuatorTopicThatPartsAndItsInstant) {
    const auto diff = rig("diff " + quoted(run("same-1")) + " " + quoted(run("changed-controller")) + " " + kCaseName);
    EXPECT_EQ(diff.exit_code, 1) << diff.output;
    EXPECT_TRUE(says_all(diff.output, {"who changed: the controller", "case file: differs first at line", "(in controller:)"}));
    std::smatch actuator;
    ASSERT_TRUE(std::regex_search(diff.output, actuator,
                                  std::regex(R"(first actuator topic to part: (actuator/\S+) at t = ([0-9.]+) s)")))
        << diff.output;
    // The gains act once spraying starts (10 s into the case) and the PID runs;
    // before, both controllers do the same valve reset and pre-adjustment.
    const double at_s = std::stod(actuator[2]);
    EXPECT_GE(at_s, 10.0) << diff.output;
    EXPECT_LE(at_s, 18.0) << diff.output;
    // The first topic to part is the controller's, and no device or truth
    // topic parts before the actuator command does.
    std::smatch first;
    ASSERT_TRUE(std::regex_search(diff.output, first, std::regex(R"(the runs part at t = ([0-9.]+) s on (\S+) \((\w+)\))")))
        << diff.output;
    EXPECT_TRUE(first[3] == "actuator" || first[3] == "controller") << diff.output;
    const std::size_t list = diff.output.find("topics that part, in order");
    ASSERT_NE(list, std::string::npos) << diff.output;
    const std::size_t actuator_row = diff.output.find("  actuator  ", list);
    ASSERT_NE(actuator_row, std::string::npos) << diff.output;
    const std::string before_actuator = diff.output.substr(list, actuator_row - list);
    EXPECT_FALSE(says(before_actuator, "  device  "));
    EXPECT_FALSE(says(before_actuator, "  truth  "));
    // Both values of the first parting sample are printed, and both runs' metrics.
    EXPECT_TRUE(std::regex_search(diff.output, std::regex(R"(\n  A at t = [0-9.]+ s: \S)"))) << diff.output;
    EXPECT_TRUE(std::regex_search(diff.output, std::regex(R"(\n  B at t = [0-9.]+ s: \S)"))) << diff.output;
    EXPECT_TRUE(says_all(diff.output, {"  differs in: ", "flow_adjust_time_s"}));
}

TEST_F(RigDiff, AnotherSeedPartsOnADeviceOrTruthTopicFirstAndNamesTheCaseOrTheRig) {
    const auto diff = rig("diff " + quoted(trace("same-1")) + " " + quoted(trace("other-seed")));
    EXPECT_EQ(diff.exit_code, 1) << diff.output;
    EXPECT_TRUE(says_all(diff.output, {"seed: A 2, B 3", "who changed: the case or the rig, not the controller",
                                       "the seeds differ"}));
    EXPECT_TRUE(std::regex_search(diff.output, std::regex(R"(the runs part at t = [0-9.]+ s on (device|truth)/\S+ \((device|truth)\))")))
        << diff.output;
}

TEST_F(RigDiff, ThePageDrawsTheKeySignalsOfBothRunsWhereTheyPart) {
    ASSERT_TRUE(rig::testing::tool_installed("gnuplot", "gnuplot-nox"));
    const fs::path page = *dir_ / "diff.html";
    const auto diff = rig("diff " + quoted(run("same-1")) + " " + quoted(run("changed-controller")) + " --html " +
                          quoted(page) + " --window 2");
    EXPECT_EQ(diff.exit_code, 1) << diff.output;
    EXPECT_TRUE(says(diff.output, "page: " + page.string()));
    const std::string html = read_all(page);
    for (const std::string signal : {"main-pipeline flow (truth)", "valve opening (truth)",
                                     "sections commanded open (bit i: section i)", "sections spraying (bit i: section i)"}) {
        EXPECT_TRUE(says(html, "<title>" + signal + "</title>"));
    }
    EXPECT_TRUE(says(html, "<svg"));
    EXPECT_FALSE(says(html, "<script"));
    EXPECT_FALSE(says(html, "could not be drawn"));
    EXPECT_TRUE(says_all(html, {"the runs part", "first actuator topic to part"}));
}

TEST_F(RigDiff, SeedOnesKeySignalsAreEachNozzlesDuty) {
    // A golden seed-001 trace against itself: the same behaviour, drawn whole.
    ASSERT_TRUE(rig::testing::tool_installed("gnuplot", "gnuplot-nox"));
    const fs::path trace = *dir_ / "boundary.sqlite";
    ASSERT_TRUE(unpacked_golden_trace("golden-boundary-drive-out", trace));
    const fs::path page = *dir_ / "boundary.html";
    const auto diff = rig("diff " + quoted(trace) + " " + quoted(trace) + " --html " + quoted(page));
    EXPECT_EQ(diff.exit_code, 0) << diff.output;
    EXPECT_TRUE(says(diff.output, "same behaviour"));
    const std::string html = read_all(page);
    for (int nozzle = 0; nozzle < 6; ++nozzle) {
        EXPECT_TRUE(says(html, "<title>nozzle " + std::to_string(nozzle) + " duty (commanded)</title>"));
    }
    EXPECT_TRUE(says(html, "the runs do not part"));
}

TEST_F(RigDiff, BadInputIsRefusedNamingWhatAndWhere) {
    const fs::path missing = *dir_ / "no-such-trace.sqlite";
    auto refused = rig("diff " + quoted(trace("same-1")) + " " + quoted(missing));
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_TRUE(says(refused.output, missing.string() + ": no such file or directory"));

    refused = rig("diff " + quoted(trace("same-1")) + " " + quoted(kCaseFile));
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_TRUE(says(refused.output, kCaseFile.string()));

    refused = rig("diff " + quoted(run("same-1")) + " " + quoted(trace("same-2")));
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_TRUE(says(refused.output, "is a run directory and"));

    refused = rig("diff " + quoted(run("same-1")) + " " + quoted(run("same-2")) + " no-such-case");
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_TRUE(says_all(refused.output, {"no case no-such-case", kCaseName}));

    refused = rig("diff " + quoted(trace("same-1")));
    EXPECT_EQ(refused.exit_code, 2) << refused.output;

    refused = rig("diff " + quoted(trace("same-1")) + " " + quoted(trace("same-2")) + " --window 0");
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_TRUE(says(refused.output, "--window"));

    // An empty file is an SQLite database without the trace's tables.
    const fs::path empty = *dir_ / "empty.sqlite";
    std::ofstream{empty};
    refused = rig("diff " + quoted(trace("same-1")) + " " + quoted(empty));
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_TRUE(says(refused.output, empty.string()));

    // A trace of another case: one of the golden traces.
    const fs::path other = *dir_ / "other-case.sqlite";
    ASSERT_TRUE(unpacked_golden_trace("golden-boundary-drive-out", other));
    refused = rig("diff " + quoted(trace("same-1")) + " " + quoted(other));
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_TRUE(says_all(refused.output, {"compares two runs of one case", "golden-boundary-drive-out"}));
}

}  // namespace
