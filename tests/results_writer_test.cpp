// The results contract (docs/design.md): results.json shape, well-formed escaped
// JUnit XML, the judge's wording and the expected-failure logic.
#include "harness/judge/verdict.h"
#include "harness/output/atomic_file.h"
#include "harness/output/xml_text.h"
#include "harness/report/results_writer.h"
#include "tool_support.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>

#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace rig::harness {
namespace {

namespace fs = std::filesystem;

CaseResult passing_case() {
    CaseResult result;
    result.name = "breakpoint-6kmh-fusion-s1";
    result.file = "cases/bp.yaml";
    result.passed = true;
    result.seed = 1;
    result.metrics = {{"breakpoint_error_m", 0.0929}, {"approach_time_s", 37.2}};
    result.limits = {{"breakpoint_error_m", 0.16}};
    result.trace_sha256 = std::string(64, 'a');
    result.trace_path = "out/breakpoint-6kmh-fusion-s1.trace";
    result.sim_seconds = 62.5;
    result.wall_seconds = 0.8;
    return result;
}

CaseResult failing_case() {
    CaseResult result;
    result.name = "overlap-<&\"'>";
    result.file = "cases/a&b.yaml";
    result.passed = false;
    result.seed = 18446744073709551615u;
    result.metrics = {{"overlap_m", 3.61}, {"breakpoint_error_m", std::numeric_limits<double>::quiet_NaN()}};
    result.limits = {{"overlap_m", 3.3}, {"breakpoint_error_m", 0.16}};
    result.failures = judge(result.metrics, result.limits);
    result.sim_seconds = 40.0;
    result.wall_seconds = 0.5;
    return result;
}

CaseResult errored_case() {
    CaseResult result;
    result.name = "plant-dies";
    result.file = "cases/dies.yaml";
    result.passed = false;
    result.error = "node 'plant' stopped answering <tick 12> & exited \"137\"\x01\xff";
    result.error_kind = "node_unresponsive";
    result.failures = {"error: node_unresponsive: " + result.error};  // as judge_case() gives it
    result.wall_seconds = 10.0;
    return result;
}

CaseResult expected_failure_case() {
    CaseResult result;
    result.name = "rtk-only-dropout";
    result.file = "cases/neg.yaml";
    result.metrics = {{"breakpoint_error_m", 0.79}};
    result.limits = {{"breakpoint_error_m", 0.16}};
    const CaseVerdict verdict = judge_case(result.metrics, result.limits, {"breakpoint_error_m"});
    result.passed = verdict.passed;
    result.expected_failure = verdict.expected_failure;
    result.failures = verdict.failures;
    return result;
}

std::vector<CaseResult> all_cases() { return {passing_case(), failing_case(), errored_case(), expected_failure_case()}; }

// ------------------------------------------------------------------ judge

TEST(Judge, FormatsLimitBreaksAndMissingMetrics) {
    const std::map<std::string, double> limits = {
        {"overlap_m", 3.3}, {"breakpoint_error_m", 0.16}, {"missed_m", 0.0}, {"flow_error_pct", 3.0}};
    const std::map<std::string, double> metrics = {{"overlap_m", 3.61},
                                                   {"missed_m", 0.0},  // equal to the limit: passes
                                                   {"flow_error_pct", std::nan("")},
                                                   {"unlimited_s", 1e9}};
    EXPECT_EQ(judge(metrics, limits), (std::vector<std::string>{"breakpoint_error_m missing", "flow_error_pct missing",
                                                                "overlap_m 3.61 > 3.3"}));
}

TEST(Judge, PrintsEnoughDigitsToTellValueFromLimit) {
    EXPECT_EQ(judge({{"overlap_m", 3.3000001}}, {{"overlap_m", 3.3}}),
              (std::vector<std::string>{"overlap_m 3.3000001 > 3.3"}));
    EXPECT_EQ(judge({{"missed_m", 1e-9}}, {{"missed_m", 0.0}}), (std::vector<std::string>{"missed_m 1e-09 > 0"}));
    EXPECT_TRUE(judge({{"overlap_m", 3.3}}, {{"overlap_m", 3.3}}).empty());
}

TEST(Judge, ExpectedFailuresMustBeExactlyTheBrokenLimits) {
    const std::vector<std::string> breaks_bp = {"breakpoint_error_m 0.79 > 0.16"};
    const std::vector<std::string> breaks_both = {"breakpoint_error_m 0.79 > 0.16", "overlap_m 3.61 > 3.3"};

    // No expectations: pass only without failures.
    EXPECT_TRUE(passes_with_expectation({}, {}));
    EXPECT_FALSE(passes_with_expectation(breaks_bp, {}));
    // Exactly the expected metric broke.
    EXPECT_TRUE(passes_with_expectation(breaks_bp, {"breakpoint_error_m"}));
    // The expected one held.
    EXPECT_FALSE(passes_with_expectation({}, {"breakpoint_error_m"}));
    // Another one broke too.
    EXPECT_FALSE(passes_with_expectation(breaks_both, {"breakpoint_error_m"}));
    // Only one of two expected broke.
    EXPECT_FALSE(passes_with_expectation(breaks_bp, {"breakpoint_error_m", "overlap_m"}));
    EXPECT_TRUE(passes_with_expectation(breaks_both, {"overlap_m", "breakpoint_error_m"}));
    // A missing metric is not the expected limit break.
    EXPECT_FALSE(passes_with_expectation({"breakpoint_error_m missing"}, {"breakpoint_error_m"}));

    EXPECT_EQ(unmet_expectations(breaks_both, {"breakpoint_error_m", "missed_m"}),
              (std::vector<std::string>{"overlap_m 3.61 > 3.3 (not expected)",
                                        "expected missed_m to break its limit, but it held"}));
    EXPECT_EQ(unmet_expectations({"breakpoint_error_m missing"}, {"breakpoint_error_m"}),
              (std::vector<std::string>{"breakpoint_error_m missing (expected a limit break)"}));
}

TEST(Judge, JudgeCaseExplainsANegativeCaseThatDidNotFail) {
    const CaseVerdict held = judge_case({{"breakpoint_error_m", 0.05}}, {{"breakpoint_error_m", 0.16}},
                                        {"breakpoint_error_m"});
    EXPECT_FALSE(held.passed);
    EXPECT_TRUE(held.expected_failure);
    EXPECT_EQ(held.failures, (std::vector<std::string>{"expected breakpoint_error_m to break its limit, but it held"}));

    const CaseVerdict broke = judge_case({{"breakpoint_error_m", 0.79}}, {{"breakpoint_error_m", 0.16}},
                                         {"breakpoint_error_m"});
    EXPECT_TRUE(broke.passed);
    EXPECT_EQ(broke.failures, (std::vector<std::string>{"breakpoint_error_m 0.79 > 0.16"}));

    const CaseVerdict plain = judge_case({{"breakpoint_error_m", 0.05}}, {{"breakpoint_error_m", 0.16}}, {});
    EXPECT_TRUE(plain.passed);
    EXPECT_FALSE(plain.expected_failure);
    EXPECT_TRUE(plain.failures.empty());
}

TEST(Judge, NotMeasuredBecauseOfTheControllerIsABreakACaseMayExpect) {
    const std::map<std::string, double> limits = {{"flow_adjust_time_s", 1.7}, {"overlap_m", 3.3}};
    const std::map<std::string, std::string> why = {{"flow_adjust_time_s", "never settled: the flow left the band"}};
    const auto failures = judge({{"overlap_m", 1.0}}, why, limits);
    ASSERT_EQ(failures.size(), 1u);
    EXPECT_EQ(failures[0], "flow_adjust_time_s not measured: never settled: the flow left the band");
    // Expected: exactly that break passes as such; a merely missing metric never does.
    EXPECT_TRUE(passes_with_expectation(failures, {"flow_adjust_time_s"}));
    EXPECT_FALSE(passes_with_expectation(judge({{"overlap_m", 1.0}}, limits), {"flow_adjust_time_s"}));
}

TEST(Judge, AnErroredCasePassesOnlyWhenItIsTheErrorItExpects) {
    VerdictInputs crashed;
    crashed.limits = {{"missed_m", 0.0}};
    crashed.metrics = {{"missed_m", 12.0}};  // from the partial trace: reported, not judged
    crashed.error_kind = "node_exited";
    crashed.error = "node 'controller': process killed by signal 6";
    CaseVerdict verdict = judge_case(crashed);
    EXPECT_FALSE(verdict.passed);
    EXPECT_FALSE(verdict.expected_failure);
    EXPECT_EQ(verdict.failures, (std::vector<std::string>{"error: node_exited: node 'controller': process killed by signal 6"}));

    crashed.expect_error = "node_exited";
    verdict = judge_case(crashed);
    EXPECT_TRUE(verdict.passed);
    EXPECT_TRUE(verdict.expected_failure);

    crashed.expect_error = "node_unresponsive";
    verdict = judge_case(crashed);
    EXPECT_FALSE(verdict.passed);
    EXPECT_EQ(verdict.failures.back(), "expected the run to end in node_unresponsive, got node_exited");

    VerdictInputs ran_through;
    ran_through.limits = {{"missed_m", 0.0}};
    ran_through.metrics = {{"missed_m", 0.0}};
    ran_through.expect_error = "node_exited";
    verdict = judge_case(ran_through);
    EXPECT_FALSE(verdict.passed);
    EXPECT_EQ(verdict.failures.back(), "expected the run to end in node_exited, but it ran to its end");

    // The result of an expected error counts as passed; any other error fails.
    CaseResult result = passing_case();
    result.error = "node 'controller': gone";
    result.error_kind = "node_exited";
    result.expected_error = "node_exited";
    EXPECT_TRUE(case_passed(result));
    result.expected_error = "";
    EXPECT_FALSE(case_passed(result));
}

TEST(Summary, CountsCasesWithErrorsAsFailed) {
    std::vector<CaseResult> results = all_cases();
    results[2].passed = true;  // an error wins over a stray `passed`
    const RunSummary summary = summarize(results);
    EXPECT_EQ(summary.passed, 2);
    EXPECT_EQ(summary.failed, 2);
    EXPECT_DOUBLE_EQ(summary.sim_seconds, 102.5);
    EXPECT_DOUBLE_EQ(summary.wall_seconds, 11.3);
}

TEST(Summary, GivesTheLockstepSpeedApartFromRealTimeCases) {
    std::vector<CaseResult> results = all_cases();  // lockstep: 62.5 + 40 s simulated
    CaseResult wired = passing_case();
    wired.name = "wired-6kmh";
    wired.mode = "realtime";
    wired.sim_seconds = 30.0;
    results.push_back(wired);
    RunSummary summary = summarize(results);
    EXPECT_DOUBLE_EQ(summary.lockstep_sim_seconds, 102.5);
    EXPECT_DOUBLE_EQ(summary.realtime_sim_seconds, 30.0);
    EXPECT_FALSE(summary.lockstep_wall_seconds.has_value());  // only the run that ran them knows
    const std::string without_walls = result_table(results, summary, /*color=*/false);
    EXPECT_EQ(without_walls.find("lockstep"), std::string::npos) << without_walls;

    summary.wall_seconds = 33.0;
    summary.lockstep_wall_seconds = 2.0;
    summary.realtime_wall_seconds = 31.0;
    const std::string table = result_table(results, summary, /*color=*/false);
    EXPECT_NE(table.find("simulated 132.5 s in 33.0 s wall (lockstep 102.5 s in 2.0 s, 51.2x; real time 30.0 s in 31.0 s)"),
              std::string::npos)
        << table;
    const nlohmann::json json = results_json(results, summary)["summary"];
    EXPECT_DOUBLE_EQ(json["lockstep"]["sim_seconds"].get<double>(), 102.5);
    EXPECT_DOUBLE_EQ(json["lockstep"]["x_real_time"].get<double>(), 51.25);
    EXPECT_DOUBLE_EQ(json["realtime"]["wall_seconds"].get<double>(), 31.0);

    // Lockstep cases alone: the speed on the same line.
    results.pop_back();
    RunSummary lockstep_only = summarize(results);
    lockstep_only.lockstep_wall_seconds = 2.0;
    EXPECT_NE(result_table(results, lockstep_only, false).find(" s wall, 51.2x real time\n"), std::string::npos);
}

// ------------------------------------------------------------------ results.json

TEST(ResultsJson, MatchesTheDesignContract) {
    const std::vector<CaseResult> results = all_cases();
    const nlohmann::json json = results_json(results, summarize(results));

    EXPECT_EQ(json["schema_version"], kResultsSchemaVersion);
    EXPECT_TRUE(json["rig"]["version"].is_string());
    EXPECT_TRUE(json["rig"]["commit"].is_string());
    ASSERT_TRUE(json.contains("cases"));
    ASSERT_TRUE(json["cases"].is_array());
    ASSERT_EQ(json["cases"].size(), 4u);
    for (const nlohmann::json& entry : json["cases"]) {
        SCOPED_TRACE(entry.dump());
        EXPECT_TRUE(entry["name"].is_string());
        EXPECT_TRUE(entry["passed"].is_boolean());
        EXPECT_TRUE(entry["seed"].is_number_unsigned());
        EXPECT_TRUE(entry["metrics"].is_object());
        EXPECT_TRUE(entry["limits"].is_object());
        EXPECT_TRUE(entry["failures"].is_array());
        for (const nlohmann::json& failure : entry["failures"]) EXPECT_TRUE(failure.is_string());
        EXPECT_TRUE(entry["trace_sha256"].is_string());
    }
    const nlohmann::json& first = json["cases"][0];
    EXPECT_EQ(first["name"], "breakpoint-6kmh-fusion-s1");
    EXPECT_EQ(first["passed"], true);
    EXPECT_EQ(first["seed"], 1u);
    EXPECT_DOUBLE_EQ(first["metrics"]["breakpoint_error_m"].get<double>(), 0.0929);
    EXPECT_DOUBLE_EQ(first["limits"]["breakpoint_error_m"].get<double>(), 0.16);
    EXPECT_EQ(first["failures"], nlohmann::json::array());
    EXPECT_EQ(first["trace_sha256"], std::string(64, 'a'));
    EXPECT_TRUE(first["error"].is_null());

    const nlohmann::json& second = json["cases"][1];
    EXPECT_EQ(second["passed"], false);
    EXPECT_EQ(second["seed"], 18446744073709551615u);
    EXPECT_EQ(second["failures"], (nlohmann::json{"breakpoint_error_m missing", "overlap_m 3.61 > 3.3"}));
    // NaN is not JSON: it is written as null.
    const nlohmann::json reparsed = nlohmann::json::parse(json.dump());
    EXPECT_TRUE(reparsed["cases"][1]["metrics"]["breakpoint_error_m"].is_null());

    EXPECT_EQ(json["cases"][2]["passed"], false);
    EXPECT_TRUE(json["cases"][2]["error"].is_string());
    EXPECT_EQ(json["cases"][3]["passed"], true);
    EXPECT_EQ(json["cases"][3]["expected_failure"], true);

    const nlohmann::json& summary = json["summary"];
    EXPECT_EQ(summary["passed"], 2);
    EXPECT_EQ(summary["failed"], 2);
    EXPECT_TRUE(summary["passed"].is_number_integer());
    EXPECT_TRUE(summary["sim_seconds"].is_number());
    EXPECT_TRUE(summary["wall_seconds"].is_number());
    EXPECT_DOUBLE_EQ(summary["sim_seconds"].get<double>(), 102.5);
}

// ------------------------------------------------------------------ junit.xml

// A small well-formedness check (enough for what junit_xml emits): one root,
// balanced tags, quoted attributes without raw '<' or '&', text without raw '<',
// every '&' an entity or character reference, no forbidden control characters.
::testing::AssertionResult is_well_formed_xml(const std::string& xml) {
    std::size_t pos = 0;
    std::vector<std::string> open;
    int roots = 0;
    auto check_references = [](std::string_view text) {
        for (std::size_t i = 0; i < text.size(); ++i) {
            const auto byte = static_cast<unsigned char>(text[i]);
            if (byte < 0x20 && byte != '\n' && byte != '\t' && byte != '\r') return false;
            if (text[i] != '&') continue;
            const std::size_t end = text.find(';', i);
            if (end == std::string_view::npos) return false;
            const std::string_view entity = text.substr(i + 1, end - i - 1);
            const bool named = entity == "amp" || entity == "lt" || entity == "gt" || entity == "quot" ||
                               entity == "apos";
            const bool numeric = entity.size() > 1 && entity[0] == '#' &&
                                 entity.substr(1).find_first_not_of("0123456789") == std::string_view::npos;
            if (!named && !numeric) return false;
        }
        return true;
    };
    if (xml.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>", 0) != 0) {
        return ::testing::AssertionFailure() << "no XML declaration";
    }
    pos = xml.find("?>") + 2;
    while (pos < xml.size()) {
        const std::size_t tag_start = xml.find('<', pos);
        const std::string_view text(xml.data() + pos, (tag_start == std::string::npos ? xml.size() : tag_start) - pos);
        if (!check_references(text) || text.find('>') != std::string_view::npos) {
            return ::testing::AssertionFailure() << "bad text: " << text;
        }
        if (open.empty() && text.find_first_not_of(" \n") != std::string_view::npos) {
            return ::testing::AssertionFailure() << "text outside the root";
        }
        if (tag_start == std::string::npos) break;
        // Find the tag's end, skipping quoted attribute values.
        std::size_t cursor = tag_start + 1;
        bool in_quotes = false;
        for (; cursor < xml.size(); ++cursor) {
            if (xml[cursor] == '"') in_quotes = !in_quotes;
            if (in_quotes && xml[cursor] == '<') return ::testing::AssertionFailure() << "raw '<' in an attribute";
            if (!in_quotes && xml[cursor] == '>') break;
        }
        if (cursor == xml.size()) return ::testing::AssertionFailure() << "unterminated tag";
        const std::string tag = xml.substr(tag_start + 1, cursor - tag_start - 1);
        if (!check_references(tag)) return ::testing::AssertionFailure() << "bad reference in tag: " << tag;
        if (tag.front() == '/') {
            if (open.empty() || open.back() != tag.substr(1)) {
                return ::testing::AssertionFailure() << "mismatched </" << tag.substr(1) << ">";
            }
            open.pop_back();
        } else {
            const std::string name = tag.substr(0, tag.find_first_of(" /"));
            if (open.empty() && ++roots > 1) return ::testing::AssertionFailure() << "two root elements";
            if (tag.back() != '/') open.push_back(name);
        }
        pos = cursor + 1;
    }
    if (!open.empty()) return ::testing::AssertionFailure() << "unclosed <" << open.back() << ">";
    if (roots != 1) return ::testing::AssertionFailure() << "no root element";
    return ::testing::AssertionSuccess();
}

TEST(JunitXml, IsWellFormedAndEscaped) {
    const std::vector<CaseResult> results = all_cases();
    const std::string xml = junit_xml(results, summarize(results));
    EXPECT_TRUE(is_well_formed_xml(xml)) << xml;

    EXPECT_NE(xml.find("<testsuites name=\"rig\" tests=\"4\" failures=\"1\" errors=\"1\""), std::string::npos) << xml;
    // The name `overlap-<&"'>` in an attribute.
    EXPECT_NE(xml.find("name=\"overlap-&lt;&amp;&quot;&apos;&gt;\""), std::string::npos) << xml;
    EXPECT_NE(xml.find("<property name=\"case_file\" value=\"cases/a&amp;b.yaml\"/>"), std::string::npos);
    EXPECT_NE(xml.find("<failure type=\"limit\" message=\"breakpoint_error_m missing\">breakpoint_error_m missing\n"
                       "overlap_m 3.61 &gt; 3.3\n</failure>"),
              std::string::npos)
        << xml;
    // Error text: escaped, control character and invalid UTF-8 replaced by U+FFFD.
    EXPECT_NE(xml.find("<error type=\"node_unresponsive\" message=\"node &apos;plant&apos; stopped answering &lt;tick 12&gt; &amp; exited "
                       "&quot;137&quot;\xEF\xBF\xBD\xEF\xBF\xBD\">"),
              std::string::npos)
        << xml;
    // One testcase per case.
    std::size_t testcases = 0;
    for (std::size_t at = xml.find("<testcase "); at != std::string::npos; at = xml.find("<testcase ", at + 1)) {
        ++testcases;
    }
    EXPECT_EQ(testcases, 4u);
}

// The same odd names and error text, against the schema Jenkins's xunit plugin
// checks JUnit files with (xmllint from libxml2-utils, which scripts/setup installs).
// xmllint's verdict on `text` against the Jenkins schema: "" when it validates, else what it said
// (or that xmllint is missing).
std::string schema_problems(const std::string& text) {
    if (const auto installed = rig::testing::tool_installed("xmllint", "libxml2-utils"); !installed) {
        return installed.message();
    }
    const fs::path xml = fs::temp_directory_path() / ("results_writer_test_junit_" + std::to_string(::getpid()) + ".xml");
    std::ofstream(xml) << text;
    const std::string command = "xmllint --noout --schema '" RIG_SOURCE_DIR "/tests/data/jenkins-junit-10.xsd' '" +
                                xml.string() + "' 2>&1";
    std::string output;
    int status = -1;
    if (FILE* pipe = ::popen(command.c_str(), "r")) {
        char buffer[512];
        while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
        status = ::pclose(pipe);
    }
    fs::remove(xml);
    const bool valid = WIFEXITED(status) && WEXITSTATUS(status) == 0 && output.find("validates") != std::string::npos;
    return valid ? "" : "xmllint: " + output;
}

TEST(JunitXml, IsValidAgainstTheJenkinsSchema) {
    const std::vector<CaseResult> results = all_cases();
    RunSummary summary = summarize(results);
    summary.started_utc = "2026-11-24T12:05:09";
    EXPECT_EQ(schema_problems(junit_xml(results, summary)), "");
    const fs::path xml = fs::temp_directory_path() / ("results_writer_test_junit_" + std::to_string(::getpid()) + ".xml");
    std::ofstream(xml) << junit_xml(results, summary);
    std::ifstream written(xml);
    const std::string text((std::istreambuf_iterator<char>(written)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("timestamp=\"2026-11-24T12:05:09\""), std::string::npos) << text;
    // The classname is the case file's folder.
    EXPECT_NE(text.find("<testcase classname=\"cases\" name=\"plant-dies\""), std::string::npos) << text;
    fs::remove(xml);
}

TEST(JunitXml, ChecksItsOwnChecker) {
    EXPECT_FALSE(is_well_formed_xml("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<a>x & y</a>\n"));
    EXPECT_FALSE(is_well_formed_xml("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<a b=\"<\"></a>\n"));
    EXPECT_FALSE(is_well_formed_xml("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<a><b></a></b>\n"));
    EXPECT_TRUE(is_well_formed_xml("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<a b=\"&amp;\">&lt;<c/></a>\n"));
}

// ------------------------------------------------------------------ invalid: the rig overloaded

// A real-time case whose rig passed its lateness bound (judge.cpp gives it
// error_kind rig_overloaded): neither passed nor the controller's failure.
CaseResult overloaded_case() {
    CaseResult result;
    result.name = "wired-6kmh";
    result.file = "cases/wired.yaml";
    result.mode = "realtime";
    result.metrics = {{"missed_m", 4.0}};
    result.limits = {{"missed_m", 0.0}};
    result.error_kind = "rig_overloaded";
    result.error = "the rig was overloaded: gnss_g970 emitted 153.2 ms after its deadline at t = 3.400 s";
    const CaseVerdict verdict = judge_case(VerdictInputs{result.metrics, {}, result.limits, {}, "", result.error_kind,
                                                         result.error});
    result.passed = verdict.passed;
    result.failures = verdict.failures;
    result.rig_lateness = {{"bound", {{"late_after_ms", 10.0}, {"max_late_pct", 1.0}, {"max_lateness_ms", 100.0}}},
                           {"emissions", 950},
                           {"late", 3},
                           {"late_pct", 0.316},
                           {"max_ms", 153.2},
                           {"worst_device", "gnss_g970"},
                           {"worst_at_s", 3.4},
                           {"injected_stall", nullptr},
                           {"overloaded", "gnss_g970 emitted 153.2 ms after its deadline at t = 3.400 s"}};
    return result;
}

TEST(Invalid, AnOverloadedRunIsNeitherPassedNorAControllerFailure) {
    std::vector<CaseResult> results = all_cases();
    results.push_back(overloaded_case());
    EXPECT_FALSE(case_passed(results.back()));
    EXPECT_TRUE(case_invalid(results.back()));
    for (std::size_t i = 0; i + 1 < results.size(); ++i) EXPECT_FALSE(case_invalid(results[i])) << i;
    const RunSummary summary = summarize(results);
    EXPECT_EQ(summary.passed, 2);
    EXPECT_EQ(summary.failed, 2);
    EXPECT_EQ(summary.invalid, 1);

    const nlohmann::json json = results_json(results, summary);
    EXPECT_EQ(json["summary"]["invalid"], 1);
    EXPECT_EQ(json["summary"]["total"], 5);
    EXPECT_EQ(json["cases"][0]["verdict"], "passed");
    EXPECT_EQ(json["cases"][1]["verdict"], "failed");
    EXPECT_EQ(json["cases"][2]["verdict"], "failed");
    EXPECT_EQ(json["cases"][3]["verdict"], "passed");
    const nlohmann::json& invalid = json["cases"][4];
    EXPECT_EQ(invalid["verdict"], "invalid");
    EXPECT_EQ(invalid["passed"], false);
    EXPECT_EQ(invalid["error_kind"], "rig_overloaded");
    EXPECT_EQ(invalid["realtime"]["rig_lateness"]["worst_device"], "gnss_g970");
    EXPECT_DOUBLE_EQ(invalid["realtime"]["rig_lateness"]["max_ms"].get<double>(), 153.2);

    // junit.xml: skipped with the reason, counted neither as a failure nor as an error.
    const std::string xml = junit_xml(results, summary);
    EXPECT_TRUE(is_well_formed_xml(xml)) << xml;
    EXPECT_NE(xml.find("<testsuites name=\"rig\" tests=\"5\" failures=\"1\" errors=\"1\""), std::string::npos) << xml;
    EXPECT_NE(xml.find("<testsuite name=\"wired-6kmh\" package=\"cases\" tests=\"1\" failures=\"0\" errors=\"0\" skipped=\"1\""),
              std::string::npos)
        << xml;
    EXPECT_EQ(schema_problems(xml), "");
    EXPECT_NE(xml.find("<skipped message=\"invalid: the rig was overloaded: gnss_g970 emitted 153.2 ms"),
              std::string::npos)
        << xml;

    // The console: its own word, and a count of its own on the last line.
    const std::string table = result_table(results, summary, /*color=*/false);
    EXPECT_NE(table.find("wired-6kmh                 INVALID"), std::string::npos) << table;
    EXPECT_TRUE(table.ends_with("\n2 passed, 2 failed, 1 invalid (rig overloaded: not judged)\n")) << table;
    const std::string report = result_report(results, summary);
    EXPECT_NE(report.find("rig lateness: latest emission 153.2 ms (gnss_g970, due at t = 3.400 s); 3 of 950 "
                          "emissions (0.32 %) more than 10 ms late; bound: at most 100 ms, at most 1 % late"),
              std::string::npos)
        << report;
}

// A self-test case that exists to show the overload detection (expect: { error:
// rig_overloaded }) passes when the rig was overloaded: it is not invalid.
TEST(Invalid, ACaseExpectingTheOverloadPassesWithIt) {
    CaseResult result = overloaded_case();
    result.expected_error = "rig_overloaded";
    const CaseVerdict verdict = judge_case(VerdictInputs{result.metrics, {}, result.limits, {}, result.expected_error,
                                                         result.error_kind, result.error});
    result.passed = verdict.passed;
    EXPECT_TRUE(case_passed(result));
    EXPECT_FALSE(case_invalid(result));
    const RunSummary summary = summarize({result});
    EXPECT_EQ(summary.passed, 1);
    EXPECT_EQ(summary.invalid, 0);
}

// Without an overload, the last line keeps its form (CI log readers parse it).
TEST(Invalid, TheLastLineIsUnchangedWithoutInvalidCases) {
    const std::vector<CaseResult> results = all_cases();
    EXPECT_TRUE(result_table(results, summarize(results), false).ends_with("\n2 passed, 2 failed\n"));
    EXPECT_EQ(results_json(results, summarize(results))["summary"]["invalid"], 0);
}

// ------------------------------------------------------------------ table and files

TEST(ResultTable, ShowsVerdictsMetricsAndFailures) {
    const std::vector<CaseResult> results = all_cases();
    const std::string table = result_table(results, summarize(results), /*color=*/false);
    EXPECT_EQ(table.find('\033'), std::string::npos);
    EXPECT_NE(table.find("breakpoint-6kmh-fusion-s1  PASS"), std::string::npos) << table;
    EXPECT_NE(table.find("rtk-only-dropout           XFAIL-OK"), std::string::npos) << table;
    EXPECT_NE(table.find("breakpoint_error_m 0.0929 / 0.16"), std::string::npos) << table;
    EXPECT_NE(table.find("overlap_m 3.61 > 3.3"), std::string::npos) << table;
    EXPECT_NE(table.find("breakpoint_error_m 0.79 > 0.16 (expected)"), std::string::npos) << table;
    EXPECT_NE(table.find("error: node_unresponsive: node 'plant' stopped answering"), std::string::npos) << table;
    // Last line alone: the count CI log readers look for.
    EXPECT_TRUE(table.ends_with("\n2 passed, 2 failed\n")) << table;

    const std::string colored = result_table(results, summarize(results), /*color=*/true);
    EXPECT_NE(colored.find("\033[32mPASS"), std::string::npos);
    EXPECT_NE(colored.find("\033[1;31mFAIL"), std::string::npos);
}

TEST(WriteResults, WritesAllThreeFilesAndNoTemporaries) {
    std::random_device entropy;
    const fs::path out = fs::temp_directory_path() /
                         ("results_writer_test_" + std::to_string(::getpid()) + "_" + std::to_string(entropy())) /
                         "nested";
    const std::vector<CaseResult> results = all_cases();
    write_results(out, results, summarize(results));
    write_results(out, results, summarize(results));  // overwriting works too

    std::vector<std::string> names;
    for (const fs::directory_entry& entry : fs::directory_iterator(out)) names.push_back(entry.path().filename());
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"junit.xml", "report.txt", "results.json"}));

    std::ifstream json_file(out / "results.json");
    const nlohmann::json json = nlohmann::json::parse(json_file);
    EXPECT_EQ(json["summary"]["failed"], 2);
    // The invalid byte in the error text was replaced, not a reason to fail.
    EXPECT_NE(json["cases"][2]["error"].get<std::string>().find("\xEF\xBF\xBD"), std::string::npos);

    std::ifstream report_file(out / "report.txt");
    const std::string report((std::istreambuf_iterator<char>(report_file)), std::istreambuf_iterator<char>());
    EXPECT_NE(report.find("== plant-dies (cases/dies.yaml)"), std::string::npos) << report;
    EXPECT_NE(report.find("approach_time_s = 37.2"), std::string::npos) << report;

    std::error_code ignored;
    fs::remove_all(out.parent_path(), ignored);
}

}  // namespace
}  // namespace rig::harness
