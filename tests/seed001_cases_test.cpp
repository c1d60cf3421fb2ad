// Seed 001's boundary cases as whole runs through `rig run` (harness + the
// 2-D plant, AD300 and L4 nodes + rig-boundary-controller over DDS on
// loopback) and `rig judge`: the reference controller passes, a faulty one
// fails on exactly its named metric, the judge reproduces every metric from
// the traces, the same seed gives the same trace, and a broken boundary case
// file is refused before anything runs, naming the key.
#include <gtest/gtest.h>

#include "results_support.h"
#include "run_support.h"
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>

namespace {

namespace fs = std::filesystem;

const fs::path kCases = fs::path(RIG_SOURCE_DIR) / "cases";

fs::path fresh_dir(const std::string& name) {
    return rig::testing::fresh_dir("seed001-cases-" + std::to_string(::getpid()) + "-" + name);
}

int rig(const std::string& args, const fs::path& log) { return rig::testing::run_rig(args, log, 600); }

using rig::testing::failing_metrics;
using rig::testing::find_case;
using rig::testing::load_results;

TEST(Seed001Cases, ReferencePassesFaultyFailsOnItsMetricAndTheJudgeAgrees) {
    const fs::path out = fresh_dir("verdicts");
    const std::string files = "'" + (kCases / "seed001-table8-boundary" / "drive-out.yaml").string() + "' '" +
                              (kCases / "seed001-faulty-controllers" / "wrong-antenna-offset.yaml").string() + "' '" +
                              (kCases / "seed001-faulty-controllers" / "no-course-rotation.yaml").string() + "' '" +
                              (kCases / "seed001-table8-boundary" / "along-centre-outside.yaml").string() + "' '" +
                              (kCases / "seed001-faulty-controllers" / "ignore-centre-rule.yaml").string() + "'";
    const int status = rig("run " + files + " --seed 1 --jobs 2 --out '" + (out / "run").string() + "'", out / "run.log");
    ASSERT_EQ(status, 0) << rig::testing::read_all(out / "run.log");
    const nlohmann::json results = load_results(out / "run");

    const nlohmann::json& reference = find_case(results, "seed001-table8-drive-out-seed1");
    EXPECT_TRUE(reference.at("passed").get<bool>()) << reference.dump(2);
    EXPECT_TRUE(reference.at("failures").empty());
    // Driving out, the reference controller stops the spray past the edge by
    // the loop's delay (0.05-0.28 s at 1.5 m/s) plus half the fan band, not
    // before the edge and not a metre after it.
    const double excess = reference.at("metrics").at("drive_out_excess_mean_m").get<double>();
    EXPECT_GT(excess, 0.05);
    EXPECT_LT(excess, 0.5);
    EXPECT_EQ(reference.at("metrics").at("drive_out_excess_stations").get<double>(), 8.0);

    // The wrong antenna offset (1 m) shuts the nozzles about 1 m late: caught on drive-out.
    const nlohmann::json& offset = find_case(results, "seed001-faulty-wrong-antenna-offset");
    EXPECT_TRUE(offset.at("expected_failure").get<bool>()) << offset.dump(2);
    EXPECT_EQ(failing_metrics(offset), std::set<std::string>{"drive_out_excess_mean_m"});
    EXPECT_GT(offset.at("metrics").at("drive_out_excess_mean_m").get<double>(), excess + 0.8);

    const nlohmann::json& rotation = find_case(results, "seed001-faulty-no-course-rotation");
    EXPECT_TRUE(rotation.at("expected_failure").get<bool>()) << rotation.dump(2);
    EXPECT_EQ(failing_metrics(rotation), std::set<std::string>{"boundary_overrun_mean_m"});

    // Table 8 "along, boom centre outside": Sec. 4.2's second rule keeps all
    // six nozzles shut, though three are inside: nothing delivered, nothing wet.
    const nlohmann::json& along = find_case(results, "seed001-table8-along-centre-outside-seed1");
    EXPECT_TRUE(along.at("passed").get<bool>()) << along.dump(2);
    EXPECT_EQ(along.at("metrics").at("centre_out_spray_ml").get<double>(), 0.0);
    EXPECT_GT(along.at("metrics").at("centre_out_samples").get<double>(), 100.0);
    EXPECT_EQ(along.at("metrics").at("boundary_overrun_stations_dry").get<double>(), 11.0);

    // Without the rule the inside nozzles spray on after the centre has left,
    // until nozzle 0 (1.25 m left of it, crossing at 60 deg) is out itself,
    // 1.25 cot 60 deg = 0.72 m on: caught on centre_out_close_m.
    const nlohmann::json& centre = find_case(results, "seed001-faulty-ignore-centre-rule");
    EXPECT_TRUE(centre.at("expected_failure").get<bool>()) << centre.dump(2);
    EXPECT_EQ(failing_metrics(centre), std::set<std::string>{"centre_out_close_m"});
    EXPECT_GT(centre.at("metrics").at("centre_out_close_m").get<double>(), 0.72);

    // Every metric and verdict again from the traces alone.
    EXPECT_EQ(rig("judge '" + (out / "run").string() + "' --check --out '" + (out / "rejudged").string() + "'",
                  out / "judge.log"),
              0)
        << rig::testing::read_all(out / "judge.log");
}

// Issue 29: a duty message with 7 entries for 6 nozzles fails the case as
// malformed_command, naming the topic, the instant it was sent and what was
// wrong; the trace keeps the command. The shipped case expects it (and
// passes); the same case without its expectation fails, and results.json,
// junit.xml and report.txt say why.
TEST(Seed001Cases, ADutyMessageWithAnExtraEntryFailsTheCaseNamingTopicInstantAndCount) {
    const fs::path out = fresh_dir("malformed");
    const fs::path shipped = kCases / "seed001-faulty-controllers" / "extra-duty-entry.yaml";
    std::string text = rig::testing::read_all(shipped);
    const std::string name_line = "name: seed001-faulty-extra-duty-entry";
    const std::string expect_line = "expect: { error: malformed_command }";
    ASSERT_NE(text.find(name_line), std::string::npos) << text;
    ASSERT_NE(text.find(expect_line), std::string::npos) << text;
    text.replace(text.find(name_line), name_line.size(), "name: extra-duty-entry-unexpected");
    text.erase(text.find(expect_line), expect_line.size());
    std::ofstream(out / "unexpected.yaml") << text;
    const int status = rig("run '" + shipped.string() + "' '" + (out / "unexpected.yaml").string() +
                               "' --jobs 2 --out '" + (out / "run").string() + "'",
                           out / "run.log");
    EXPECT_EQ(status, 1) << "the unexpected one fails the run:\n" << rig::testing::read_all(out / "run.log");
    const nlohmann::json results = load_results(out / "run");

    const nlohmann::json& expected = find_case(results, "seed001-faulty-extra-duty-entry");
    EXPECT_TRUE(expected.at("passed").get<bool>()) << expected.dump(2);
    EXPECT_EQ(expected.at("error_kind"), "malformed_command") << expected.dump(2);
    const std::string error = expected.at("error").get<std::string>();
    const std::regex named(R"(^node 'controller': actuator/nozzle_pwm/duty at t=([0-9]+\.[0-9]{3}) s: 7 duty entries for 6 nozzles)");
    std::smatch at;
    ASSERT_TRUE(std::regex_search(error, at, named)) << error;
    // The command that turned the nozzles on at the north edge (5 s in), kept as the trace's last duty message.
    const fs::path trace = out / "run" / "cases" / "seed001-faulty-extra-duty-entry" / "trace.sqlite";
    const std::string last = rig::testing::read_all_command(
        "sqlite3 '" + trace.string() +
        "' \"select t_ns, json_array_length(json, '$.duty_pct') from samples where topic = 'actuator/nozzle_pwm/duty' "
        "order by t_ns desc, round desc limit 1\"");
    const auto bar = last.find('|');
    ASSERT_NE(bar, std::string::npos) << last;
    EXPECT_NEAR(static_cast<double>(std::stoll(last.substr(0, bar))) / 1e9, std::stod(at[1]), 0.0005) << last;
    EXPECT_EQ(std::stoi(last.substr(bar + 1)), 7) << last;
    EXPECT_GT(std::stod(at[1]), 3.0) << error;

    const nlohmann::json& unexpected = find_case(results, "extra-duty-entry-unexpected");
    EXPECT_FALSE(unexpected.at("passed").get<bool>()) << unexpected.dump(2);
    EXPECT_EQ(unexpected.at("verdict"), "failed");
    EXPECT_EQ(unexpected.at("error_kind"), "malformed_command");
    // Same seed, same command at the same instant (the error's first line; the controller's log follows it).
    const auto first_line = [](const std::string& message) { return message.substr(0, message.find('\n')); };
    EXPECT_EQ(first_line(unexpected.at("error").get<std::string>()), first_line(error));
    const std::string junit = rig::testing::read_all(out / "run" / "junit.xml");
    EXPECT_NE(junit.find("<error type=\"malformed_command\" message=\"node &apos;controller&apos;: "
                         "actuator/nozzle_pwm/duty at t="),
              std::string::npos)
        << junit;
    const std::string report = rig::testing::read_all(out / "run" / "report.txt");
    EXPECT_NE(report.find("error (malformed_command): node 'controller': actuator/nozzle_pwm/duty at t="), std::string::npos)
        << report;

    // `rig judge` gives the same verdicts from the traces alone.
    EXPECT_EQ(rig("judge '" + (out / "run").string() + "' --check --out '" + (out / "rejudged").string() + "'",
                  out / "judge.log"),
              1)
        << rig::testing::read_all(out / "judge.log");
    EXPECT_NE(rig::testing::read_all(out / "judge.log").find("re-judged: every metric, verdict and digest as recorded"),
              std::string::npos)
        << rig::testing::read_all(out / "judge.log");
}

// The boom centre crossing out of the area at 60 deg, each case on its own ten
// seeds: the reference controller closes within the loop's delay budget on
// every one, and a controller acting 0.3 s late or believing the boom centre
// 1 m nearer the antenna fails on centre_out_close_m alone on every one. The
// catalogue drives the exact route (`guidance: off`, docs/guidance.md), so the
// reference it is set against here does too: the same seed, the same fixes.
TEST(Seed001Cases, TheCentreCrossingCatchesALateOrMisplacedCentreOnEverySeed) {
    const fs::path out = fresh_dir("centre-crossing");
    const fs::path exact_reference = out / "centre-crosses-out.yaml";
    std::ofstream(exact_reference) << rig::testing::read_all(kCases / "seed001-table8-boundary" / "centre-crosses-out.yaml")
                                   << "\nguidance: off\n";
    const std::string files =
        "'" + exact_reference.string() + "' '" +
        (kCases / "seed001-faulty-controllers" / "late-at-centre-crossing.yaml").string() + "' '" +
        (kCases / "seed001-faulty-controllers" / "wrong-antenna-offset-centre-crossing.yaml").string() + "'";
    const int status = rig("run " + files + " --jobs 2 --out '" + (out / "run").string() + "'", out / "run.log");
    ASSERT_EQ(status, 0) << rig::testing::read_all(out / "run.log");
    const nlohmann::json results = load_results(out / "run");
    constexpr double kSpeedMS = 1.5;
    constexpr double kPwmPeriodS = 1.0 / 9.0;
    constexpr double kJudgeStepM = kSpeedMS * 0.005;
    for (int seed = 1; seed <= 10; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const std::string suffix = "-seed" + std::to_string(seed);
        const nlohmann::json& reference = find_case(results, "seed001-table8-centre-crosses-out" + suffix);
        EXPECT_TRUE(reference.at("passed").get<bool>()) << reference.dump(2);
        EXPECT_EQ(reference.at("metrics").at("centre_out_crossings").get<double>(), 1.0);
        const double reference_m = reference.at("metrics").at("centre_out_close_m").get<double>();
        // At least RMC latency + stroke after the crossing (the UTM error's
        // 1.2 cm early is 0.009 s of it): the rule acts after the truth crossing.
        EXPECT_GT(reference_m, 0.0);

        const nlohmann::json& late = find_case(results, "seed001-faulty-late-at-centre-crossing" + suffix);
        EXPECT_TRUE(late.at("expected_failure").get<bool>()) << late.dump(2);
        EXPECT_EQ(failing_metrics(late), std::set<std::string>{"centre_out_close_m"});
        // The same seed gives the same fixes, so the same decision: 0.3 s
        // later, give or take where the PWM latch falls (one period).
        const double late_m = late.at("metrics").at("centre_out_close_m").get<double>();
        EXPECT_GE(late_m - reference_m, kSpeedMS * (0.3 - kPwmPeriodS) - kJudgeStepM);
        EXPECT_LE(late_m - reference_m, kSpeedMS * (0.3 + kPwmPeriodS) + kJudgeStepM);

        const nlohmann::json& offset = find_case(results, "seed001-faulty-wrong-antenna-offset-centre-crossing" + suffix);
        EXPECT_TRUE(offset.at("expected_failure").get<bool>()) << offset.dump(2);
        EXPECT_EQ(failing_metrics(offset), std::set<std::string>{"centre_out_close_m"});
        // The centre it believes trails the true one by 1 m of travel.
        EXPECT_GT(offset.at("metrics").at("centre_out_close_m").get<double>(), 1.0);
    }
}

TEST(Seed001Cases, SameSeedSameTraceAnotherSeedAnotherTrace) {
    const fs::path out = fresh_dir("digest");
    const fs::path file = kCases / "seed001-table8-boundary" / "drive-in.yaml";
    const std::string first = rig::testing::run_digest(file, 2, out / "run0", 600);
    const std::string again = rig::testing::run_digest(file, 2, out / "run1", 600);
    const std::string other = rig::testing::run_digest(file, 3, out / "run2", 600);
    ASSERT_FALSE(first.empty());
    EXPECT_EQ(first, again);
    // Another seed moves the epochs and the PWM phase: another trace.
    EXPECT_NE(first, other);
}

TEST(Seed001Cases, ABrokenBoundaryCaseIsRefusedNamingTheKey) {
    const fs::path out = fresh_dir("broken");
    std::string text = rig::testing::read_all(kCases / "seed001-table8-boundary" / "drive-out.yaml");
    const std::string good = "- straight: { length_m: 16.0, speed_m_s: 1.5 }";
    const auto at = text.find(good);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, good.size(), "- straight: { length_m: -16.0, speed_m_s: 1.5 }");
    std::ofstream(out / "broken.yaml") << text;
    const int status = rig("run '" + (out / "broken.yaml").string() + "' --out '" + (out / "run").string() + "'",
                           out / "run.log");
    const std::string log = rig::testing::read_all(out / "run.log");
    EXPECT_NE(status, 0) << log;
    EXPECT_NE(log.find("broken.yaml"), std::string::npos) << log;
    EXPECT_NE(log.find("route"), std::string::npos) << log;
    EXPECT_NE(log.find("segment 0"), std::string::npos) << log;
    EXPECT_FALSE(fs::exists(out / "run" / "cases")) << "nothing may run";
}

}  // namespace

// rig-boundary-controller's wired mode (the bench path's serial lines) runs on
// the wall clock only: asked for in lockstep it refuses before joining DDS.
TEST(Seed001Cases, TheControllersWiredModeRefusesVirtualTime) {
    const fs::path dir = fresh_dir("wired-lockstep");
    std::ofstream(dir / "controller.yaml") << "{}\n";
    const rig::testing::ShellResult refused = rig::testing::run_shell(
        "'" RIG_BINARY_DIR "/bin/rig-boundary-controller' --domain 0 --config '" + (dir / "controller.yaml").string() +
        "' --nmea-serial /dev/null 2>&1");
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_NE(refused.output.find("wired mode runs on the wall clock: add --clock realtime"), std::string::npos)
        << refused.output;
}
