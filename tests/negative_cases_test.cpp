// Whole runs of the negative cases through `rig run` (harness + rig-controller
// over DDS on loopback): a case with `expect: { fail: [...] }` passes only when
// exactly those metrics break their limits, and the same case without its
// expectation fails the run. Each run takes a few seconds of wall time.
#include <gtest/gtest.h>

#include "run_support.h"
#include <unistd.h>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const fs::path kNegativeDir = fs::path(RIG_SOURCE_DIR) / "cases" / "negative";

fs::path fresh_dir(const std::string& name) {
    return rig::testing::fresh_dir("negative-cases-" + std::to_string(::getpid()) + "-" + name);
}

using rig::testing::read_all;

// Runs `rig run TARGET --out OUT`; returns the exit status (-1 if it did not exit normally).
int rig_run(const fs::path& target, const fs::path& out, const fs::path& log) {
    const std::string command = "timeout -k 10 300 '" RIG_BINARY_DIR "/bin/rig' run '" + target.string() +
                                "' --out '" + out.string() + "' > '" + log.string() + "' 2>&1";
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

nlohmann::json load_results(const fs::path& out) {
    std::ifstream in(out / "results.json");
    if (!in) {
        ADD_FAILURE() << "no results.json in " << out;
        return nlohmann::json::object();
    }
    return nlohmann::json::parse(in);
}

const nlohmann::json* find_case(const nlohmann::json& results, const std::string& name) {
    for (const auto& c : results.at("cases")) {
        if (c.at("name") == name) return &c;
    }
    return nullptr;
}

// The metric each failure line names ("missed_m 0.42 > 0" -> "missed_m").
std::set<std::string> failing_metrics(const nlohmann::json& one_case) {
    std::set<std::string> metrics;
    for (const auto& failure : one_case.at("failures")) {
        const std::string line = failure.get<std::string>();
        metrics.insert(line.substr(0, line.find(' ')));
    }
    return metrics;
}

TEST(NegativeCases, SuitePassesWhenExactlyTheExpectedMetricsBreak) {
    const fs::path out = fresh_dir("suite");
    const int status = rig_run(kNegativeDir, out / "run", out / "rig.log");
    ASSERT_EQ(status, 0) << "rig run cases/negative:\n" << read_all(out / "rig.log");
    const nlohmann::json results = load_results(out / "run");
    ASSERT_EQ(results.at("cases").size(), 2u) << results.dump(2);
    EXPECT_EQ(results.at("summary").at("passed"), 2);
    EXPECT_EQ(results.at("summary").at("failed"), 0);

    const nlohmann::json* no_compensation = find_case(results, "continuation-6kmh-no-compensation");
    ASSERT_NE(no_compensation, nullptr) << results.dump(2);
    EXPECT_EQ(no_compensation->at("passed"), true);
    EXPECT_EQ(no_compensation->at("expected_failure"), true);
    EXPECT_EQ(failing_metrics(*no_compensation), (std::set<std::string>{"missed_m"})) << no_compensation->dump(2);
    EXPECT_GT(no_compensation->at("metrics").at("missed_m").get<double>(), 0.0);

    const nlohmann::json* gains_x5 = find_case(results, "continuation-6kmh-gains-x5");
    ASSERT_NE(gains_x5, nullptr) << results.dump(2);
    EXPECT_EQ(gains_x5->at("passed"), true);
    EXPECT_EQ(gains_x5->at("expected_failure"), true);
    EXPECT_EQ(failing_metrics(*gains_x5), (std::set<std::string>{"flow_adjust_time_s"})) << gains_x5->dump(2);
    EXPECT_GT(gains_x5->at("metrics").at("flow_adjust_time_s").get<double>(),
              gains_x5->at("limits").at("flow_adjust_time_s").get<double>());
    // Not a near miss: it swings for seconds, more than twice the 1.3 s the
    // paper's gains take on the same plant (continuation-6kmh).
    EXPECT_GT(gains_x5->at("metrics").at("flow_adjust_time_s").get<double>(), 2.6);
}

TEST(NegativeCases, NoCompensationWithoutItsExpectationFailsTheRun) {
    const fs::path out = fresh_dir("unexpected");
    // The same case file without its `expect:` line.
    const std::string original = read_all(kNegativeDir / "continuation-6kmh-no-compensation.yaml");
    std::istringstream lines(original);
    std::ostringstream stripped;
    int removed = 0;
    for (std::string line; std::getline(lines, line);) {
        if (line.rfind("expect:", 0) == 0) {
            ++removed;
            continue;
        }
        stripped << line << '\n';
    }
    ASSERT_EQ(removed, 1) << "the case file no longer has one top-level expect: line";
    const fs::path case_file = out / "no-compensation-unexpected.yaml";
    std::ofstream(case_file) << stripped.str();

    const int status = rig_run(case_file, out / "run", out / "rig.log");
    EXPECT_EQ(status, 1) << "rig run must fail:\n" << read_all(out / "rig.log");
    const nlohmann::json results = load_results(out / "run");
    ASSERT_EQ(results.at("cases").size(), 1u) << results.dump(2);
    const nlohmann::json& only = results.at("cases").at(0);
    EXPECT_EQ(only.at("passed"), false);
    EXPECT_EQ(only.at("expected_failure"), false);
    EXPECT_EQ(results.at("summary").at("failed"), 1);
    const std::regex missed(R"(missed_m [0-9.eE+-]+ > 0)");
    const auto& failures = only.at("failures");
    EXPECT_TRUE(std::any_of(failures.begin(), failures.end(),
                            [&](const nlohmann::json& f) { return std::regex_match(f.get<std::string>(), missed); }))
        << only.dump(2);
}

}  // namespace
