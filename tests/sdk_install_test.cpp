// The SDK as an outside team uses it (docs/sdk.md): `cmake --install` of this
// build into an empty prefix, the example controller project
// (examples/rtk-breakpoint-controller) configured against that prefix alone
// with find_package(rig) and built, and then run in its case by the installed
// `rig` and judged like any controller.
#include <gtest/gtest.h>

#include "run_support.h"

#include <sys/wait.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;
using rig::testing::read_all;

// Runs a shell command with its output in `log`; the exit status (-1 if it did not exit).
int run(const std::string& command, const fs::path& log) {
    const int status = std::system((command + " > '" + log.string() + "' 2>&1").c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Sdk, TheExampleControllerBuildsAgainstAnInstalledRigAndIsJudgedInACase) {
    const fs::path dir = rig::testing::fresh_dir("sdk-install");
    const fs::path prefix = dir / "prefix";

    // 1. Install: the SDK and the rig's executables land in the prefix.
    ASSERT_EQ(run("cmake --install '" RIG_BINARY_DIR "' --prefix '" + prefix.string() + "'", dir / "install.log"), 0)
        << read_all(dir / "install.log");
    for (const char* file : {"lib/cmake/rig/rigConfig.cmake", "lib/cmake/rig/rigConfigVersion.cmake",
                             "lib/cmake/rig/rigTargets.cmake", "lib/librig_node.a", "lib/librig_idl.a",
                             "lib/librig_nmea.a", "include/rig/runtime/dds_context.h", "include/rig/runtime/lockstep.h",
                             "include/rig/runtime/follower.h",
                             "include/rig/nmea/nmea_parser.h", "include/rig/idl/topics.h",
                             "include/rig/idl/controllerPubSubTypes.h", "share/rig/idl/topics.json",
                             "share/rig/idl/clock.idl", "share/rig/docs/controller-contract.md", "bin/rig",
                             "bin/rig-controller"}) {
        EXPECT_TRUE(fs::exists(prefix / file)) << file;
    }

    // 2. The example project, against the prefix alone (no path into this source
    // tree's build), in a copy outside the source tree.
    const fs::path project = dir / "example";
    fs::copy(RIG_SOURCE_DIR "/examples/rtk-breakpoint-controller", project, fs::copy_options::recursive);
    const auto started = std::chrono::steady_clock::now();
    ASSERT_EQ(run("cmake -S '" + project.string() + "' -B '" + (project / "build").string() +
                      "' -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH='" + prefix.string() + "'",
                  dir / "configure.log"),
              0)
        << read_all(dir / "configure.log");
    ASSERT_EQ(run("cmake --build '" + (project / "build").string() + "'", dir / "build.log"), 0)
        << read_all(dir / "build.log");
    const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    RecordProperty("example_configure_and_build_seconds", std::to_string(build_s));
    std::cout << "the example configured and built against the install in " << build_s << " s\n";

    // 3. Its case, run by the installed rig; the case names the program relative to itself.
    const int status = run("'" + (prefix / "bin" / "rig").string() + "' run '" + (project / "case.yaml").string() +
                               "' --out '" + (dir / "out").string() + "'",
                           dir / "run.log");
    ASSERT_TRUE(fs::exists(dir / "out" / "results.json")) << read_all(dir / "run.log");
    const nlohmann::json results = nlohmann::json::parse(read_all(dir / "out" / "results.json"));
    const nlohmann::json& result = results["cases"][0];
    EXPECT_EQ(status, 0) << read_all(dir / "run.log") << read_all(dir / "out" / "cases" / "rtk-breakpoint-controller" / "controller.log");
    EXPECT_TRUE(result["passed"].get<bool>()) << result.dump(2);
    EXPECT_NE(result["file"].get<std::string>().find("case.yaml"), std::string::npos);
    // Judged from truth: it declared the breakpoint, within Table 4's limit at 6 km/h.
    EXPECT_EQ(result["metrics"]["breakpoint_reached_count"].get<double>(), 1.0) << result.dump(2);
    EXPECT_LT(result["metrics"]["breakpoint_error_m"].get<double>(), 0.55) << result.dump(2);
    EXPECT_LT(result["metrics"]["breakpoint_store_error_m"].get<double>(), 0.10) << result.dump(2);
}

}  // namespace
