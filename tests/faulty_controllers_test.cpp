// The catalogue of faulty controllers (cases/faulty-controllers/,
// docs/faulty-controllers.md) as whole runs through `rig run` (harness +
// rig-controller over DDS on loopback), on the first of its seeds (the demo runs
// all five): every faulty controller must fail exactly as its `expect` says, the
// controls must pass, `rig judge --check` must reproduce every metric from the
// traces, and a faulty case without its expectation must fail the run.
#include <gtest/gtest.h>

#include "run_support.h"
#include <unistd.h>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const fs::path kCatalogue = fs::path(RIG_SOURCE_DIR) / "cases" / "faulty-controllers";

fs::path fresh_dir(const std::string& name) {
    return rig::testing::fresh_dir("faulty-controllers-" + std::to_string(::getpid()) + "-" + name);
}

using rig::testing::read_all;

using rig::testing::read_all_command;

// Runs `rig ARGS` with its output in `log`; returns the exit status (-1 if it did not exit normally).
int rig(const std::string& args, const fs::path& log) {
    const std::string command =
        "timeout -k 10 600 '" RIG_BINARY_DIR "/bin/rig' " + args + " > '" + log.string() + "' 2>&1";
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
int rig_run(const fs::path& target, const fs::path& out, const fs::path& log, const std::string& extra = "") {
    return rig("run '" + target.string() + "' --out '" + out.string() + "' " + extra, log);
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

TEST(FaultyControllers, EachFailsOnItsNamedMetricOrErrorAndTheControlsPass) {
    const fs::path out = fresh_dir("catalogue");
    const int status = rig_run(kCatalogue, out / "run", out / "rig.log", "--seed 1 --jobs 2");
    ASSERT_EQ(status, 0) << "rig run cases/faulty-controllers --seed 1:\n" << read_all(out / "rig.log");
    const nlohmann::json results = load_results(out / "run");
    EXPECT_EQ(results.at("summary").at("failed"), 0);

    // Expected signature of every faulty controller: the metrics it breaks, or its error.
    const std::map<std::string, std::set<std::string>> broken = {
        {"never-resumes", {"missed_m", "flow_adjust_time_s", "flow_error_pct"}},
        {"never-sprays", {"missed_m", "flow_adjust_time_s", "flow_error_pct"}},
        {"sections-flicker", {"missed_m", "flow_adjust_time_s", "flow_error_pct"}},
        {"no-hysteresis-compensation", {"missed_m"}},
        {"opens-twice-as-early", {"overlap_m"}},
        {"valve-held", {"flow_adjust_time_s", "flow_error_pct"}},
        {"pid-gains-x5", {"flow_adjust_time_s", "flow_error_pct"}},
        {"wrong-pulses-per-litre", {"flow_adjust_time_s", "flow_error_pct"}},
        {"wrong-l4", {"breakpoint_store_error_m"}},
        {"stale-fix-through-dropout", {"breakpoint_error_m"}},
        {"boom-height-read-once", {"breakpoint_error_m"}},
    };
    const std::map<std::string, std::string> errors = {
        {"crashes-mid-case", "node_exited"},
        {"stops-answering", "node_unresponsive"},
        {"reads-truth-topic", "topic_role_violation"},
        {"forges-truth-topic", "topic_role_violation"},
        {"wrong-section-count", "malformed_command"},
    };
    ASSERT_EQ(results.at("cases").size(), broken.size() + errors.size() + 4) << results.dump(2);
    for (const auto& [name, metrics] : broken) {
        const nlohmann::json* one = find_case(results, name + "-seed1");
        ASSERT_NE(one, nullptr) << name;
        EXPECT_TRUE(one->at("passed").get<bool>()) << one->dump(2);
        EXPECT_TRUE(one->at("expected_failure").get<bool>()) << name;
        EXPECT_EQ(failing_metrics(*one), metrics) << one->dump(2);
        EXPECT_TRUE(one->at("error").is_null()) << one->dump(2);
    }
    for (const auto& [name, kind] : errors) {
        const nlohmann::json* one = find_case(results, name + "-seed1");
        ASSERT_NE(one, nullptr) << name;
        EXPECT_TRUE(one->at("passed").get<bool>()) << one->dump(2);
        EXPECT_EQ(one->at("error_kind"), kind) << one->dump(2);
    }
    for (const char* control : {"reference-controller-seed1", "reference-controller-identification-seed1",
                                "reference-controller-calibration-gap-seed1", "reference-controller-boom-lowered-seed1"}) {
        const nlohmann::json* one = find_case(results, control);
        ASSERT_NE(one, nullptr) << control;
        EXPECT_TRUE(one->at("passed").get<bool>()) << one->dump(2);
        EXPECT_FALSE(one->at("expected_failure").get<bool>()) << control;
    }

    // Not near misses: the span after the breakpoint (to the strip's end, 9 m
    // past it) is missed by the controller that never resumes, the whole 33 m
    // strip by the one that never sprays.
    EXPECT_NEAR(find_case(results, "never-resumes-seed1")->at("metrics").at("missed_m").get<double>(), 9.0, 0.1);
    EXPECT_NEAR(find_case(results, "never-sprays-seed1")->at("metrics").at("missed_m").get<double>(), 33.0, 0.1);
    EXPECT_GT(find_case(results, "stale-fix-through-dropout-seed1")->at("metrics").at("breakpoint_error_m").get<double>(), 1.0);
    // The boom lowered on the approach (h 1.0 -> 0) moves the nozzle line 0.30 m
    // back from the antenna (Eq. 6: L4 1.45 -> 1.75 m): the controller that kept
    // its power-on reading declares the breakpoint that much earlier than the
    // reference controller on the same seed.
    const auto signed_error_m = [&](const char* name) {
        return find_case(results, name)->at("metrics").at("breakpoint_error_signed_m").get<double>();
    };
    EXPECT_NEAR(signed_error_m("boom-height-read-once-seed1") - signed_error_m("reference-controller-boom-lowered-seed1"),
                -0.30, 0.05);
    // Role violations name the topic and the participant.
    const std::string reader_error = find_case(results, "reads-truth-topic-seed1")->at("error").get<std::string>();
    EXPECT_NE(reader_error.find("node 'controller': reads truth topic truth/vehicle"), std::string::npos) << reader_error;
    // Its hello hides the reader: only discovery can tell it, and says so on every run.
    EXPECT_NE(reader_error.find(", seen by discovery)"), std::string::npos) << reader_error;
    const std::string forger_error = find_case(results, "forges-truth-topic-seed1")->at("error").get<std::string>();
    EXPECT_NE(forger_error.find("node 'controller': writes truth topic truth/hydraulics"), std::string::npos)
        << forger_error;

    // The section command for a fourth section fails the case at the instant it
    // was sent, named; the trace keeps it as the last section command.
    const std::string malformed_error = find_case(results, "wrong-section-count-seed1")->at("error").get<std::string>();
    const std::regex malformed_text(
        R"(node 'controller': actuator/section_valves/open at t=([0-9]+\.[0-9]{3}) s: )"
        R"(open_mask 15 sets bit 3, but the boom has 3 sections \(bits 0-2\))");
    std::smatch malformed_at;
    ASSERT_TRUE(std::regex_search(malformed_error, malformed_at, malformed_text)) << malformed_error;
    const fs::path malformed_trace = out / "run" / "cases" / "wrong-section-count-seed1" / "trace.sqlite";
    const std::string last_sections = read_all_command(
        "sqlite3 '" + malformed_trace.string() +
        "' \"select t_ns, json from samples where topic = 'actuator/section_valves/open' order by t_ns desc, round desc limit 1\"");
    const auto last_bar = last_sections.find('|');
    ASSERT_NE(last_bar, std::string::npos) << last_sections;
    EXPECT_NEAR(static_cast<double>(std::stoll(last_sections.substr(0, last_bar))) / 1e9, std::stod(malformed_at[1]), 0.0005)
        << last_sections;
    EXPECT_NE(last_sections.find(R"("open_mask":15)"), std::string::npos) << last_sections;
    // When the first pass starts spraying (10.64 s on seed 1, after the 10 s wait), not at t = 0.
    EXPECT_GT(std::stod(malformed_at[1]), 5.0) << malformed_error;

    // The crashed controller's trace keeps every sample up to the crash (20 s), and says why it ends.
    const fs::path crashed = out / "run" / "cases" / "crashes-mid-case-seed1" / "trace.sqlite";
    const std::string rows = read_all_command("sqlite3 '" + crashed.string() +
                                              "' \"select count(*), max(t_ns) from samples; "
                                              "select value from meta where key in ('outcome', 'error_kind') order by key\"");
    std::istringstream lines(rows);
    std::string counts, error_kind, outcome;
    std::getline(lines, counts);
    std::getline(lines, error_kind);
    std::getline(lines, outcome);
    const auto bar = counts.find('|');
    ASSERT_NE(bar, std::string::npos) << rows;
    EXPECT_GT(std::stoll(counts.substr(0, bar)), 5000) << rows;
    EXPECT_NEAR(static_cast<double>(std::stoll(counts.substr(bar + 1))) / 1e9, 20.0, 0.05) << rows;
    EXPECT_EQ(outcome, "error");
    EXPECT_EQ(error_kind, "node_exited");

    // Re-judging the traces alone gives every metric, verdict and digest exactly.
    const int rejudged = rig("judge '" + (out / "run").string() + "' --check --out '" + (out / "rejudged").string() + "'",
                             out / "judge.log");
    EXPECT_EQ(rejudged, 0) << read_all(out / "judge.log");
    EXPECT_NE(read_all(out / "judge.log").find("re-judged: every metric, verdict and digest as recorded"),
              std::string::npos)
        << read_all(out / "judge.log");
    EXPECT_EQ(load_results(out / "rejudged").at("cases").size(), results.at("cases").size());
}

TEST(FaultyControllers, ANoCompensationControllerWithoutItsExpectationFailsTheRun) {
    const fs::path out = fresh_dir("unexpected");
    // The same case file without its `expect:` line.
    const std::string original = read_all(kCatalogue / "no-hysteresis-compensation.yaml");
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

    const int status = rig_run(case_file, out / "run", out / "rig.log", "--seed 1");
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

// A controller that declares a truth topic in its hello fails when the hellos
// are checked, before time starts: on every run with no instant run, so the
// same trace (when discovery told it, the trace held 0 or 13 samples of the
// first instant depending on when the announcement arrived), and with the same
// reason: what discovery saw during start-up waits for the hello check (it
// once spoke first in about 1 run of 5).
TEST(FaultyControllers, ADeclaredForgedTopicFailsBeforeTimeStartsWithTheSameTraceEveryRun) {
    const fs::path out = fresh_dir("declared-forgery");
    std::string digest;
    for (int run = 0; run < 4; ++run) {
        const fs::path dir = out / ("run" + std::to_string(run));
        const int status = rig_run(kCatalogue / "forges-truth-topic.yaml", dir, out / "rig.log", "--seed 2");
        ASSERT_EQ(status, 0) << read_all(out / "rig.log");
        const nlohmann::json only = load_results(dir).at("cases").at(0);
        EXPECT_EQ(only.at("error").get<std::string>(),
                  "node 'controller': writes truth topic truth/hydraulics (declared in its hello)")
            << only.dump(2);
        EXPECT_EQ(only.at("rounds"), 0) << only.dump(2);
        if (run == 0) digest = only.at("trace_sha256").get<std::string>();
        EXPECT_EQ(only.at("trace_sha256").get<std::string>(), digest) << "run " << run;
    }
}

}  // namespace
