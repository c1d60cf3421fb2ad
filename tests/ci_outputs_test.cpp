// What a CI reads from a run (docs/design.md "Results"), from a real `rig run`
// of a small suite: a passing case, a failing one, an expected failure and one
// whose controller dies.
//  * junit.xml is valid against Jenkins xunit's JUnit schema
//    (tests/data/jenkins-junit-10.xsd, checked by xmllint), with the case's
//    folder as classname, its facts as its suite's properties, a timestamp and
//    the hostname, and the expected failure marked;
//  * results.json has its schema version, the rig's version and commit, and
//    trace paths relative to --out that still point at the traces once the
//    folder is moved (as a CI archives it), also after `rig judge --out`.
#include <gtest/gtest.h>

#include "run_support.h"
#include "tool_support.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;
using rig::testing::read_all;

const fs::path kSchema = fs::path(RIG_SOURCE_DIR) / "tests" / "data" / "jenkins-junit-10.xsd";

// Runs a shell command with its output in `log`; the exit status (-1 if it did not exit).
int run_logged(const std::string& command, const fs::path& log) {
    const int status = std::system((command + " > '" + log.string() + "' 2>&1").c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int rig(const std::string& args, const fs::path& log) {
    return run_logged("timeout -k 10 300 '" RIG_BINARY_DIR "/bin/rig' " + args, log);
}

// xmllint's verdict on `xml` against the Jenkins schema: its exit status (0: valid).
int xmllint_schema(const fs::path& xml, const fs::path& log) {
    EXPECT_TRUE(rig::testing::tool_installed("xmllint", "libxml2-utils"));
    return run_logged("xmllint --noout --schema '" + kSchema.string() + "' '" + xml.string() + "'", log);
}

// short-fusion.yaml (a 9 s case) as `name`, with `replace` swapped for `with`
// and `extra` lines appended.
void write_case(const fs::path& file, const std::string& name, const std::string& replace, const std::string& with,
                const std::string& extra = "") {
    std::string text = read_all(RIG_SOURCE_DIR "/tests/data/short-fusion.yaml");
    text.replace(text.find("name: short-fusion"), std::string("name: short-fusion").size(), "name: " + name);
    if (!replace.empty()) {
        const auto at = text.find(replace);
        ASSERT_NE(at, std::string::npos) << replace;
        text.replace(at, replace.size(), with);
    }
    std::ofstream(file) << text << extra;
}

class CiOutputs : public ::testing::Test {
protected:
    // One run of the four-case suite, shared by the tests (each run costs DDS start-ups).
    static void SetUpTestSuite() {
        dir_ = rig::testing::fresh_dir("ci-outputs-" + std::to_string(::getpid()));
        const fs::path suite = dir_ / "ci-suite";
        fs::create_directories(suite);
        write_case(suite / "passes.yaml", "passes", "", "");
        // A breakpoint error of a tenth of a millimetre: no controller meets it.
        const std::string limits = "limits: { breakpoint_error_m: 0.16 }";
        write_case(suite / "fails.yaml", "fails", limits, "limits: { breakpoint_error_m: 0.0001 }");
        write_case(suite / "expected-failure.yaml", "expected-failure", limits,
                   "limits: { breakpoint_error_m: 0.0001 }", "expect: { fail: [ breakpoint_error_m ] }\n");
        write_case(suite / "controller-dies.yaml", "controller-dies",
                   "controller: { positioning: fusion, threshold_m: 5.0 }",
                   "controller: { positioning: fusion, threshold_m: 5.0, faults: { crash_at_s: 2 } }");
        out_ = dir_ / "out";
        exit_code_ = rig("run '" + suite.string() + "' --jobs 2 --out '" + out_.string() + "'", dir_ / "run.log");
        log_ = read_all(dir_ / "run.log");
        junit_ = read_all(out_ / "junit.xml");
        if (fs::exists(out_ / "results.json")) results_ = nlohmann::json::parse(read_all(out_ / "results.json"));
    }

    // The <testsuite ...> element of a case, up to its </testsuite>.
    static std::string suite_of(const std::string& name) {
        const auto start = junit_.find("<testsuite name=\"" + name + "\"");
        if (start == std::string::npos) return "";
        return junit_.substr(start, junit_.find("</testsuite>", start) - start);
    }

    static const nlohmann::json* result_of(const std::string& name) {
        for (const nlohmann::json& one : results_["cases"]) {
            if (one["name"] == name) return &one;
        }
        return nullptr;
    }

    static inline fs::path dir_, out_;
    static inline int exit_code_ = -1;
    static inline std::string log_, junit_;
    static inline nlohmann::json results_;
};

TEST_F(CiOutputs, TheRunFailsAndWritesItsOutputs) {
    EXPECT_EQ(exit_code_, 1) << log_;
    ASSERT_FALSE(junit_.empty()) << log_;
    ASSERT_TRUE(results_.is_object()) << log_;
    ASSERT_EQ(results_["cases"].size(), 4u) << results_.dump(2);
}

TEST_F(CiOutputs, JunitIsValidAgainstTheJenkinsSchema) {
    ASSERT_FALSE(junit_.empty()) << log_;
    EXPECT_EQ(xmllint_schema(out_ / "junit.xml", dir_ / "xmllint.log"), 0) << read_all(dir_ / "xmllint.log") << junit_;
}

// The check itself can fail: the rig's old junit.xml put a `file` attribute on
// <testcase>, which that schema refuses (issue 16).
TEST_F(CiOutputs, TheSchemaCheckRefusesWhatTheSchemaForbids) {
    ASSERT_FALSE(junit_.empty()) << log_;
    std::string broken = junit_;
    broken.replace(broken.find("<testcase "), std::string("<testcase ").size(), "<testcase file=\"x.yaml\" ");
    std::ofstream(dir_ / "broken.xml") << broken;
    EXPECT_NE(xmllint_schema(dir_ / "broken.xml", dir_ / "xmllint-broken.log"), 0) << broken;
    EXPECT_NE(read_all(dir_ / "xmllint-broken.log").find("file"), std::string::npos)
        << read_all(dir_ / "xmllint-broken.log");
}

TEST_F(CiOutputs, JunitNamesTheCasesFolderAndCarriesEachCasesFacts) {
    ASSERT_FALSE(junit_.empty()) << log_;
    for (const std::string name : {"passes", "fails", "expected-failure", "controller-dies"}) {
        SCOPED_TRACE(name);
        const std::string suite = suite_of(name);
        ASSERT_FALSE(suite.empty()) << junit_;
        EXPECT_NE(suite.find("<testcase classname=\"ci-suite\" name=\"" + name + "\""), std::string::npos) << suite;
        EXPECT_TRUE(std::regex_search(suite, std::regex(R"( timestamp="\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d")"))) << suite;
        char host[256] = {};
        ::gethostname(host, sizeof host - 1);
        EXPECT_NE(suite.find(std::string(" hostname=\"") + host + "\""), std::string::npos) << suite;
        EXPECT_NE(suite.find("<property name=\"seed\" value=\"5\"/>"), std::string::npos) << suite;
        EXPECT_NE(suite.find("<property name=\"mode\" value=\"lockstep\"/>"), std::string::npos) << suite;
        EXPECT_NE(suite.find("<property name=\"controller_mode\" value=\"process\"/>"), std::string::npos) << suite;
        const nlohmann::json* result = result_of(name);
        ASSERT_NE(result, nullptr);
        const std::string digest = (*result)["trace_sha256"];
        EXPECT_EQ(digest.size(), 64u);
        EXPECT_NE(suite.find("<property name=\"trace_sha256\" value=\"" + digest + "\"/>"), std::string::npos) << suite;
        EXPECT_NE(suite.find("<property name=\"rig_commit\" value=\"" + results_["rig"]["commit"].get<std::string>() +
                             "\"/>"),
                  std::string::npos)
            << suite;
    }
}

TEST_F(CiOutputs, JunitTellsPassFailureExpectedFailureAndErrorApart) {
    ASSERT_FALSE(junit_.empty()) << log_;
    const std::string passes = suite_of("passes");
    EXPECT_EQ(passes.find("<failure"), std::string::npos) << passes;
    EXPECT_EQ(passes.find("<error"), std::string::npos) << passes;
    EXPECT_NE(passes.find("<property name=\"expected_failure\" value=\"false\"/>"), std::string::npos) << passes;

    const std::string fails = suite_of("fails");
    EXPECT_NE(fails.find("failures=\"1\" errors=\"0\""), std::string::npos) << fails;
    EXPECT_NE(fails.find("<failure type=\"limit\" message=\"breakpoint_error_m "), std::string::npos) << fails;

    // No xfail in JUnit: a pass, marked as the expected failure it is.
    const std::string expected = suite_of("expected-failure");
    EXPECT_NE(expected.find("failures=\"0\" errors=\"0\""), std::string::npos) << expected;
    EXPECT_EQ(expected.find("<failure"), std::string::npos) << expected;
    EXPECT_NE(expected.find("<property name=\"expected_failure\" value=\"true\"/>"), std::string::npos) << expected;
    EXPECT_NE(expected.find("<property name=\"verdict\" value=\"XFAIL-OK\"/>"), std::string::npos) << expected;
    EXPECT_NE(expected.find("<system-out>XFAIL-OK: an expected failure"), std::string::npos) << expected;

    const std::string dies = suite_of("controller-dies");
    EXPECT_NE(dies.find("failures=\"0\" errors=\"1\""), std::string::npos) << dies;
    EXPECT_NE(dies.find("<error type=\"node_exited\""), std::string::npos) << dies;

    EXPECT_NE(junit_.find("<testsuites name=\"rig\" tests=\"4\" failures=\"1\" errors=\"1\""), std::string::npos)
        << junit_;
}

TEST_F(CiOutputs, ResultsJsonSaysItsSchemaAndWhichRigWroteIt) {
    ASSERT_TRUE(results_.is_object()) << log_;
    EXPECT_EQ(results_["schema_version"], 2);
    const std::string version = results_["rig"]["version"];
    EXPECT_TRUE(std::regex_match(version, std::regex(R"(\d+\.\d+\.\d+)"))) << version;
    // Built from this git checkout: a commit (with -dirty while it has changes).
    const std::string commit = results_["rig"]["commit"];
    EXPECT_TRUE(std::regex_match(commit, std::regex(R"([0-9a-f]{40}(-dirty)?)"))) << commit;
    // `rig --version` tells the same.
    ASSERT_EQ(rig("--version", dir_ / "version.log"), 0);
    EXPECT_NE(read_all(dir_ / "version.log").find(version), std::string::npos);
    EXPECT_NE(read_all(dir_ / "version.log").find(commit), std::string::npos);
}

// CI archives --out and unpacks it elsewhere: the paths in it must still lead to the traces.
TEST_F(CiOutputs, TracePathsAreRelativeToTheOutputFolderAndSurviveAMove) {
    ASSERT_TRUE(results_.is_object()) << log_;
    const fs::path moved = dir_ / "archived" / "elsewhere";
    fs::create_directories(moved.parent_path());
    fs::copy(out_, moved, fs::copy_options::recursive);
    const nlohmann::json results = nlohmann::json::parse(read_all(moved / "results.json"));
    for (const nlohmann::json& one : results["cases"]) {
        SCOPED_TRACE(one["name"].get<std::string>());
        const fs::path trace = one["trace_path"].get<std::string>();
        EXPECT_TRUE(trace.is_relative()) << trace;
        EXPECT_EQ(trace, fs::path("cases") / one["name"].get<std::string>() / "trace.sqlite");
        EXPECT_TRUE(fs::exists(moved / trace)) << trace;
        const std::string suite = suite_of(one["name"]);
        EXPECT_NE(suite.find("<property name=\"trace_path\" value=\"" + trace.string() + "\"/>"), std::string::npos)
            << suite;
    }
    EXPECT_EQ(read_all(out_ / "report.txt").find(out_.string()), std::string::npos) << "an absolute path in report.txt";
    EXPECT_EQ(read_all(out_ / "report.html").find(out_.string()), std::string::npos) << "an absolute path in report.html";
}

// `rig judge RUN --out NEW` writes NEW/results.json: its trace paths lead from NEW to RUN's traces.
TEST_F(CiOutputs, ARejudgedRunsTracePathsLeadFromItsOwnFolder) {
    ASSERT_TRUE(results_.is_object()) << log_;
    const fs::path again = dir_ / "again";
    rig("judge '" + out_.string() + "' --out '" + again.string() + "'", dir_ / "judge.log");
    ASSERT_TRUE(fs::exists(again / "results.json")) << read_all(dir_ / "judge.log");
    const nlohmann::json results = nlohmann::json::parse(read_all(again / "results.json"));
    ASSERT_EQ(results["cases"].size(), 4u);
    for (const nlohmann::json& one : results["cases"]) {
        const fs::path trace = one["trace_path"].get<std::string>();
        EXPECT_EQ(trace, fs::path("..") / "out" / "cases" / one["name"].get<std::string>() / "trace.sqlite");
        EXPECT_TRUE(fs::exists(again / trace)) << trace;
    }
    EXPECT_EQ(xmllint_schema(again / "junit.xml", dir_ / "xmllint-again.log"), 0) << read_all(dir_ / "xmllint-again.log");
}

}  // namespace

namespace {

// cmake/RigBuildInfo.cmake on `source_dir`: the commit it writes into the generated source.
std::string commit_written_for(const fs::path& source_dir, const fs::path& scratch) {
    const fs::path output = scratch / "build_info.cpp";
    fs::remove(output);
    const int status = run_logged("'" RIG_CMAKE_COMMAND "' -DRIG_SOURCE_DIR='" + source_dir.string() +
                                      "' -DRIG_VERSION=9.8.7 -DRIG_OUTPUT='" + output.string() + "' -DGIT=git -P '" +
                                      RIG_SOURCE_DIR + "/cmake/RigBuildInfo.cmake'",
                                  scratch / "cmake.log");
    EXPECT_EQ(status, 0) << read_all(scratch / "cmake.log");
    std::smatch match;
    const std::string text = read_all(output);
    EXPECT_NE(text.find("rig_version() { return \"9.8.7\"; }"), std::string::npos) << text;
    if (!std::regex_search(text, match, std::regex(R"re(rig_commit\(\) \{ return "([^"]*)"; \})re"))) return "";
    return match[1];
}

// A build from a tarball has no git: its commit is "unknown", also when the
// tarball was unpacked inside some other git checkout (whose commit is not its own).
TEST(BuildInfo, TheCommitIsGitsOrUnknownWithoutAGitCheckoutOfItsOwn) {
    const fs::path scratch = rig::testing::fresh_dir("build-info-" + std::to_string(::getpid()));
    const fs::path tarball = scratch / "sprayer-hil-rig-0.2.0";
    fs::create_directories(tarball);
    EXPECT_EQ(commit_written_for(tarball, scratch), "unknown");
    EXPECT_EQ(commit_written_for(fs::path(RIG_SOURCE_DIR) / "tests" / "data", scratch), "unknown");
    EXPECT_TRUE(std::regex_match(commit_written_for(RIG_SOURCE_DIR, scratch), std::regex("[0-9a-f]{40}(-dirty)?")));
}

}  // namespace
