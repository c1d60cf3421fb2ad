// The SDK as an outside team uses it (docs/sdk.md): `cmake --install` of this
// build into an empty prefix; each example project copied from the install
// (share/rig/examples), configured against that prefix alone with
// find_package(rig), built, and run in its cases by the installed `rig`, judged
// like any controller; the installed `rig` running the rig's own seed-001
// cases unchanged (their reference controller from the install); and
// (SdkCleanClone, its own ctest entry) the documented install steps, as
// docs/sdk.md writes them, from a clean clone.
#include <gtest/gtest.h>

#include "run_support.h"

#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;
using rig::testing::read_all;

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// Runs a shell command (written to LOG.sh, so it may quote as it likes),
// bounded by `timeout_s`, with its output in `log`; the exit status (-1 if it
// did not exit).
int run(const std::string& command, const fs::path& log, int timeout_s = 900) {
    const fs::path script = log.string() + ".sh";
    std::ofstream(script) << "set -e\n" << command << "\n";
    const std::string bounded =
        "timeout -k 10 " + std::to_string(timeout_s) + " sh " + quoted(script) + " > " + quoted(log) + " 2>&1";
    const int status = std::system(bounded.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// `text` with every `from` replaced by `to`.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
        text.replace(at, from.size(), to);
    }
    return text;
}

nlohmann::json results_of(const fs::path& out) {
    const std::string text = read_all(out / "results.json");
    if (text.empty()) return nlohmann::json::object();
    return nlohmann::json::parse(text);
}

const nlohmann::json& case_named(const nlohmann::json& results, const std::string& name) {
    static const nlohmann::json none = nlohmann::json::object();
    if (results.contains("cases")) {
        for (const nlohmann::json& one : results.at("cases")) {
            if (one.value("name", "") == name) return one;
        }
    }
    ADD_FAILURE() << "no case " << name << " in the results";
    return none;
}

// One value of a trace's meta table, read with the sqlite3 shell.
std::string trace_meta(const fs::path& trace, const std::string& key) {
    std::string value = rig::testing::read_all_command("sqlite3 " + quoted(trace) + " \"select value from meta where key = '" +
                                                       key + "'\"");
    while (!value.empty() && value.back() == '\n') value.pop_back();
    return value;
}

// The largest duty any nozzle was commanded in a trace (actuator/nozzle_pwm/duty).
double largest_commanded_duty_pct(const fs::path& trace) {
    const std::string rows = rig::testing::read_all_command(
        "sqlite3 " + quoted(trace) + " \"select json from samples where topic = 'actuator/nozzle_pwm/duty'\"");
    double largest = -1.0;
    std::istringstream lines(rows);
    for (std::string line; std::getline(lines, line);) {
        const nlohmann::json sample = nlohmann::json::parse(line);
        for (const nlohmann::json& duty : sample.at("duty_pct")) largest = std::max(largest, duty.get<double>());
    }
    return largest;
}

// One install of this build for every test of the suite: the package as a team gets it.
class Sdk : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir_ = rig::testing::fresh_dir("sdk-install");
        prefix_ = dir_ / "prefix";
        install_status_ = run("cmake --install " + quoted(RIG_BINARY_DIR) + " --prefix " + quoted(prefix_), dir_ / "install.log");
    }
    void SetUp() override { ASSERT_EQ(install_status_, 0) << read_all(dir_ / "install.log"); }

    // The example `name` copied out of the install and built against it alone
    // (no path into this source tree or its build), as docs/sdk.md step 2 says.
    static fs::path build_installed_example(const std::string& name) {
        const fs::path project = dir_ / name;
        fs::remove_all(project);
        fs::copy(prefix_ / "share" / "rig" / "examples" / name, project, fs::copy_options::recursive);
        const auto started = std::chrono::steady_clock::now();
        const int status = run("cd " + quoted(project) + " && cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=" +
                                   quoted(prefix_) + " && cmake --build build",
                               dir_ / (name + "-build.log"));
        EXPECT_EQ(status, 0) << read_all(dir_ / (name + "-build.log"));
        const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
        std::cout << name << " configured and built against the install in " << build_s << " s\n";
        return project;
    }

    // The installed `rig` with `args`; its output in `log`.
    static int installed_rig(const std::string& args, const fs::path& log) {
        return run(quoted(prefix_ / "bin" / "rig") + " " + args, log, 600);
    }

    static fs::path dir_;
    static fs::path prefix_;
    static int install_status_;
};
fs::path Sdk::dir_;
fs::path Sdk::prefix_;
int Sdk::install_status_ = -1;

TEST_F(Sdk, TheInstallHoldsTheSdkEveryReferenceControllerTheDocsAndTheExamples) {
    for (const char* file : {"lib/cmake/rig/rigConfig.cmake", "lib/cmake/rig/rigConfigVersion.cmake",
                             "lib/cmake/rig/rigTargets.cmake", "lib/librig_node.a", "lib/librig_idl.a",
                             "lib/librig_nmea.a", "include/rig/runtime/dds_context.h", "include/rig/runtime/lockstep.h",
                             "include/rig/runtime/follower.h", "include/rig/nmea/nmea_parser.h",
                             "include/rig/papers/seed001.h", "include/rig/idl/topics.h",
                             "include/rig/idl/controllerPubSubTypes.h", "include/rig/idl/actuatorPubSubTypes.h",
                             "share/rig/idl/topics.json", "share/rig/idl/clock.idl",
                             // The harness and the reference controller each system runs when a case names none.
                             "bin/rig", "bin/rig-controller", "bin/rig-boundary-controller",
                             "lib/rig/rig-controller-plugin.so",
                             // What a team reads: the contract, the SDK, what is judged and recorded, each seed's pages.
                             "share/rig/docs/controller-contract.md", "share/rig/docs/sdk.md", "share/rig/docs/metrics.md",
                             "share/rig/docs/trace-format.md", "share/rig/docs/seed001-boundary.md",
                             "share/rig/docs/seed001-vision.md", "share/rig/docs/reproduction-seed001.md",
                             "share/rig/examples/rtk-breakpoint-controller/CMakeLists.txt",
                             "share/rig/examples/boundary-shutoff-controller/CMakeLists.txt",
                             "share/rig/examples/boundary-shutoff-controller/cases/drive-out.yaml"}) {
        EXPECT_TRUE(fs::exists(prefix_ / file)) << file;
    }
    // Every document a page links to is installed beside it.
    for (const auto& entry : fs::directory_iterator(RIG_SOURCE_DIR "/docs")) {
        if (entry.path().extension() == ".md") {
            EXPECT_TRUE(fs::exists(prefix_ / "share/rig/docs" / entry.path().filename())) << entry.path().filename();
        }
    }
}

TEST_F(Sdk, TheSeed000ExampleBuildsAgainstTheInstallAndIsJudgedInItsCase) {
    const fs::path project = build_installed_example("rtk-breakpoint-controller");
    ASSERT_TRUE(fs::exists(project / "build" / "rtk-breakpoint-controller"));

    // Its case, run by the installed rig; the case names the program relative to itself.
    const fs::path out = dir_ / "rtk-out";
    const int status = installed_rig("run " + quoted(project / "case.yaml") + " --out " + quoted(out), dir_ / "rtk-run.log");
    const nlohmann::json results = results_of(out);
    ASSERT_TRUE(results.contains("cases")) << read_all(dir_ / "rtk-run.log");
    const nlohmann::json& result = results["cases"][0];
    EXPECT_EQ(status, 0) << read_all(dir_ / "rtk-run.log")
                         << read_all(out / "cases" / "rtk-breakpoint-controller" / "controller.log");
    EXPECT_TRUE(result["passed"].get<bool>()) << result.dump(2);
    EXPECT_NE(result["file"].get<std::string>().find("case.yaml"), std::string::npos);
    // Judged from truth: it declared the breakpoint, within Table 4's limit at 6 km/h.
    EXPECT_EQ(result["metrics"]["breakpoint_reached_count"].get<double>(), 1.0) << result.dump(2);
    EXPECT_LT(result["metrics"]["breakpoint_error_m"].get<double>(), 0.55) << result.dump(2);
    EXPECT_LT(result["metrics"]["breakpoint_store_error_m"].get<double>(), 0.10) << result.dump(2);
}

// examples/boundary-shutoff-controller: a seed-001 controller written from the
// contract and the installed headers alone, judged from the plant's truth in
// its three cases at three seeds each (docs/seed001-boundary.md "Writing a
// seed-001 controller").
TEST_F(Sdk, TheSeed001ExampleBuildsAgainstTheInstallAndPassesItsCases) {
    const fs::path project = build_installed_example("boundary-shutoff-controller");
    const fs::path program = (project / "build" / "boundary-shutoff-controller").lexically_normal();
    ASSERT_TRUE(fs::exists(program));

    const fs::path out = dir_ / "boundary-out";
    const int status =
        installed_rig("run " + quoted(project / "cases") + " --jobs 2 --out " + quoted(out), dir_ / "boundary-run.log");
    const nlohmann::json results = results_of(out);
    ASSERT_TRUE(results.contains("cases")) << read_all(dir_ / "boundary-run.log");
    EXPECT_EQ(status, 0) << read_all(dir_ / "boundary-run.log");
    ASSERT_EQ(results["cases"].size(), 9u) << results.dump(2);  // three cases, seeds 1-3
    for (const nlohmann::json& one : results["cases"]) {
        EXPECT_TRUE(one["passed"].get<bool>()) << one.dump(2)
                                               << read_all(out / "cases" / one["name"].get<std::string>() / "controller.log");
        EXPECT_EQ(trace_meta(out / one["trace_path"].get<std::string>(), "controller_command").rfind(program.string(), 0), 0u)
            << "the case ran the example, named relative to the case file";
    }
    for (const char* seed : {"-seed1", "-seed2", "-seed3"}) {
        // Driving out at 1.5 m/s: every station under the boom was wet inside
        // the area and dry past a shut-off a loop delay late (0.05 - 0.5 m),
        // sprayed at Eq. 14's level 2 for cover 0.5 (100 %).
        const nlohmann::json& out_case = case_named(results, std::string("example-boundary-drive-out") + seed);
        EXPECT_EQ(out_case["metrics"]["drive_out_excess_stations"].get<double>(), 8.0) << out_case.dump(2);
        const double out_excess = out_case["metrics"]["drive_out_excess_mean_m"].get<double>();
        EXPECT_GT(out_excess, 0.05) << seed;
        EXPECT_LT(out_excess, 0.50) << seed;
        EXPECT_EQ(largest_commanded_duty_pct(out / out_case["trace_path"].get<std::string>()), 100.0) << seed;

        // Driving in at 0.5 m/s with the boom at 0.31 m: the laser's height
        // puts the boom 0.70 m ahead of the antenna (Eq. 18), so the spray
        // starts at the edge, not 0.30 m before it; level 1 (40 %) at 0.5 m/s.
        const nlohmann::json& in_case = case_named(results, std::string("example-boundary-low-boom-drive-in") + seed);
        EXPECT_EQ(in_case["metrics"]["drive_in_excess_stations"].get<double>(), 6.0) << in_case.dump(2);
        const double in_excess = in_case["metrics"]["drive_in_excess_mean_m"].get<double>();
        EXPECT_LT(in_excess, 0.10) << seed;
        EXPECT_GT(in_excess, -0.30) << seed << ": the spray started well inside the area";
        EXPECT_EQ(largest_commanded_duty_pct(out / in_case["trace_path"].get<std::string>()), 40.0) << seed;

        // Along the edge with the boom centre outside: nozzles 0-2 are inside,
        // and Sec. 4.2's second rule keeps them shut: nothing delivered.
        const nlohmann::json& centre_case = case_named(results, std::string("example-boundary-centre-outside") + seed);
        EXPECT_EQ(centre_case["metrics"]["centre_out_spray_ml"].get<double>(), 0.0) << centre_case.dump(2);
        EXPECT_GT(centre_case["metrics"]["centre_out_samples"].get<double>(), 100.0) << seed;
    }

    // Bad input is refused before anything starts, naming the file, the line and the key.
    const fs::path bad = dir_ / "bad-inputs";
    fs::create_directories(bad);
    std::ofstream(bad / "empty.yaml") << "{}\n";
    std::ofstream(bad / "settings.yaml") << "# a setting this controller does not have\nnozzle_count: 4\n";
    const std::string job = read_all(out / "cases" / "example-boundary-drive-out-seed1" / "job.yaml");
    ASSERT_NE(job.find("nozzle_spacing_m:"), std::string::npos) << job;
    std::ofstream(bad / "job.yaml") << replaced(job, "nozzle_spacing_m:", "nozzle_pitch_m:");
    const auto refused = [&](const std::string& config, const std::string& job_file) {
        return rig::testing::run_shell(quoted(program) + " --domain 0 --node-name controller --config " + quoted(bad / config) +
                                       " --state-dir " + quoted(bad) + " --job " + quoted(bad / job_file) + " 2>&1");
    };
    const rig::testing::ShellResult missing_key = refused("empty.yaml", "job.yaml");
    EXPECT_EQ(missing_key.exit_code, 2) << missing_key.output;
    EXPECT_NE(missing_key.output.find((bad / "job.yaml").string() + ":"), std::string::npos) << missing_key.output;
    EXPECT_NE(missing_key.output.find("sprayer.nozzle_spacing_m: missing"), std::string::npos) << missing_key.output;
    const rig::testing::ShellResult setting = refused("settings.yaml", "job.yaml");
    EXPECT_EQ(setting.exit_code, 2) << setting.output;
    EXPECT_NE(setting.output.find((bad / "settings.yaml").string() + ":2: nozzle_count: this controller has no settings"),
              std::string::npos)
        << setting.output;
}

// Item 5 of issue 29: the installed package runs the rig's own seed-001 cases,
// unchanged. A few, one of each kind: Table 8's drive out, Table 3's duty
// sweep, a faulty controller that must fail on its metric, and a case with
// the two boom cameras; each with the reference controller from the install.
TEST_F(Sdk, TheInstalledRigRunsTheRigsOwnSeed001Cases) {
    const fs::path cases = fs::path(RIG_SOURCE_DIR) / "cases";
    std::string files;
    for (const char* file : {"seed001-table8-boundary/drive-out.yaml", "seed001-table3-flow/duty-sweep.yaml",
                             "seed001-faulty-controllers/ignore-centre-rule.yaml",
                             "seed001-table4-6-vision/normal-1_5-m-s.yaml"}) {
        files += quoted(cases / file) + " ";
    }
    const fs::path out = dir_ / "seed001-cases-out";
    const int status = installed_rig("run " + files + "--seed 1 --jobs 2 --out " + quoted(out), dir_ / "seed001-cases.log");
    const nlohmann::json results = results_of(out);
    ASSERT_TRUE(results.contains("cases")) << read_all(dir_ / "seed001-cases.log");
    EXPECT_EQ(status, 0) << read_all(dir_ / "seed001-cases.log");
    ASSERT_EQ(results["cases"].size(), 4u) << results.dump(2);
    for (const nlohmann::json& one : results["cases"]) {
        EXPECT_TRUE(one["passed"].get<bool>()) << one.dump(2);
        EXPECT_TRUE(one["error_kind"].is_null()) << one.dump(2);
        EXPECT_EQ(trace_meta(out / one["trace_path"].get<std::string>(), "controller_command")
                      .rfind((fs::canonical(prefix_ / "bin") / "rig-boundary-controller").string(), 0),
                  0u)
            << one["name"];
    }
    // The faulty controller was caught, on its own metric.
    const nlohmann::json& faulty = case_named(results, "seed001-faulty-ignore-centre-rule");
    EXPECT_TRUE(faulty["expected_failure"].get<bool>()) << faulty.dump(2);
}

// docs/sdk.md's install steps as it writes them, from a clean clone (the
// files git has, none of a build): the SDK-only build installed into a
// prefix, the full build's configure step, and step 2's example against the
// SDK-only install. The full build itself is what scripts/test builds.
TEST(SdkCleanClone, TheDocumentedStepsWorkAsWritten) {
    const std::string sdk_md = read_all(RIG_SOURCE_DIR "/docs/sdk.md");
    const std::string full_install = "cmake -S . -B build && cmake --build build -j \"$(nproc)\" && cmake --install build --prefix /opt/rig";
    const std::string sdk_install =
        "cmake -S . -B build-sdk -DRIG_SDK_ONLY=ON && cmake --build build-sdk -j \"$(nproc)\" && cmake --install build-sdk --prefix /opt/rig";
    const std::string copy_example = "cp -r /opt/rig/share/rig/examples/rtk-breakpoint-controller mine && cd mine";
    const std::string build_example = "cmake -S . -B build -DCMAKE_PREFIX_PATH=/opt/rig && cmake --build build";
    for (const std::string* command : {&full_install, &sdk_install, &copy_example, &build_example}) {
        ASSERT_NE(sdk_md.find(*command), std::string::npos) << "docs/sdk.md no longer says: " << *command;
    }

    const fs::path dir = rig::testing::fresh_dir("sdk-clean-clone");
    const fs::path clone = dir / "rig";
    const fs::path prefix = dir / "prefix";
    // A clean clone: every file git tracks (or would, not ignored), as it is in this checkout.
    const rig::testing::ShellResult listed =
        rig::testing::run_shell("git -C " + quoted(RIG_SOURCE_DIR) + " ls-files --cached --others --exclude-standard");
    ASSERT_EQ(listed.exit_code, 0) << "git ls-files in " RIG_SOURCE_DIR ": " << listed.output;
    std::istringstream files(listed.output);
    std::size_t copied = 0;
    for (std::string file; std::getline(files, file);) {
        const fs::path from = fs::path(RIG_SOURCE_DIR) / file;
        if (!fs::is_regular_file(from)) continue;  // deleted in the work tree, not yet in the index
        fs::create_directories((clone / file).parent_path());
        fs::copy_file(from, clone / file);
        ++copied;
    }
    ASSERT_GT(copied, 100u);
    ASSERT_FALSE(fs::exists(clone / "build"));

    // Step 1, the full build's configure (the whole build is scripts/test's).
    const std::string configure_full = full_install.substr(0, full_install.find(" && "));
    EXPECT_EQ(run("cd " + quoted(clone) + " && " + configure_full, dir / "configure-full.log"), 0)
        << read_all(dir / "configure-full.log");

    // Step 1 for a machine that only builds controllers, as written.
    ASSERT_EQ(run("cd " + quoted(clone) + " && " + replaced(sdk_install, "/opt/rig", prefix.string()), dir / "sdk.log", 1200), 0)
        << read_all(dir / "sdk.log");
    EXPECT_TRUE(fs::exists(prefix / "lib/cmake/rig/rigConfig.cmake"));
    EXPECT_TRUE(fs::exists(prefix / "share/rig/docs/controller-contract.md"));
    EXPECT_FALSE(fs::exists(prefix / "bin/rig")) << "the SDK alone has no harness";

    // Step 2 against it.
    ASSERT_EQ(run("cd " + quoted(dir) + " && " + replaced(copy_example, "/opt/rig", prefix.string()) + " && " +
                      replaced(build_example, "/opt/rig", prefix.string()),
                  dir / "example.log"),
              0)
        << read_all(dir / "example.log");
    EXPECT_TRUE(fs::exists(dir / "mine" / "build" / "rtk-breakpoint-controller"));
}

}  // namespace
