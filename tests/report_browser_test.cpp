// The HTML report in a real browser (tests/js/check_report.mjs: Debian's
// Chromium, headless, driven by playwright-core): a run's report.html at a
// phone's width (390 px) and a desktop's (1280 px) has no console or page
// errors, never runs past the screen's width (tables and figures scroll inside
// their own boxes), and keeps the figures' text at the size it was drawn (no
// 5 px text from a figure shrunk to the screen). The screenshots' paths are
// printed for CI's log.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <iostream>
#include <string>

#include "run_support.h"
#include "tool_support.h"

namespace fs = std::filesystem;
using rig::testing::fresh_dir;

namespace {

using rig::testing::run_shell;

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// gnuplot's SVG text is drawn at 11 px; 9 px is the smallest a reader is asked to read.
constexpr double kSmallestLegiblePx = 9.0;

}  // namespace

TEST(ReportInABrowser, ReadableAtPhoneAndDesktopWidthWithoutErrors) {
    // check_report.mjs launches /usr/bin/chromium through node; the figures are gnuplot's.
    ASSERT_TRUE(rig::testing::tool_installed("node", "nodejs"));
    ASSERT_TRUE(rig::testing::tool_installed("chromium", "chromium"));
    ASSERT_TRUE(rig::testing::tool_installed("gnuplot", "gnuplot-nox"));
    const fs::path dir = fresh_dir("report-browser");
    const fs::path out = dir / "out";
    // A passing continuation, a failing faulty controller and a seed-001 vision
    // case (a camera frame and the cover maps): every kind of section the report has.
    const auto run = run_shell(quoted(RIG_BINARY_DIR "/bin/rig") + " run " +
                            quoted(RIG_SOURCE_DIR "/cases/table5-6-continuation/continuation-6kmh.yaml") + " " +
                            quoted(RIG_SOURCE_DIR "/cases/faulty-controllers/never-resumes.yaml") + " " +
                            quoted(RIG_SOURCE_DIR "/cases/seed001-vision-faults/dead-camera.yaml") + " --out " +
                            quoted(out) + " 2>&1");
    ASSERT_TRUE(fs::exists(out / "report.html")) << run.output;

    const fs::path shots = dir / "screenshots";
    const auto check = run_shell("cd " + quoted(RIG_JS_TOOLS_DIR) + " && node check_report.mjs " +
                              quoted(out / "report.html") + " " + quoted(shots) + " 2>&1");
    ASSERT_EQ(check.exit_code, 0) << "the browser check failed (scripts/setup installs chromium and runs npm ci in "
                                     RIG_JS_TOOLS_DIR "):\n"
                                  << check.output;
    const nlohmann::json result = nlohmann::json::parse(check.output);
    for (const char* view : {"phone", "desktop"}) {
        SCOPED_TRACE(view);
        const nlohmann::json& page = result.at(view);
        EXPECT_TRUE(page["errors"].empty()) << page["errors"].dump(2);
        EXPECT_LE(page["overflowPx"].get<double>(), 1.0) << "the page runs past the screen's width";
        EXPECT_GE(page["figures"].get<int>(), 4) << "the figures were not drawn";
        EXPECT_GE(page["tables"].get<int>(), 4);
        ASSERT_TRUE(page["smallestFigureTextPx"].is_number()) << page.dump(2);
        EXPECT_GE(page["smallestFigureTextPx"].get<double>(), kSmallestLegiblePx);
        EXPECT_GE(page["smallestPageTextPx"].get<double>(), 12.0);
        const fs::path screenshot = page["screenshot"].get<std::string>();
        EXPECT_GT(fs::exists(screenshot) ? fs::file_size(screenshot) : 0, 10'000u) << screenshot;
        std::cout << "screenshot (" << view << ", " << page["width"] << " px): " << screenshot.string() << std::endl;
    }
}
