// `rig compare` on real runs, each side changed through the reference
// controller's configuration as a team's commit would change it:
//  * one seed, the same controller: same behaviour, exit 0; a controller
//    that acts 0.1 s late (seed 001, drive-out): drive_out_excess_mean_m
//    regressed, exit 1, and the report says the controller's configuration is
//    what changed;
//  * 30 seeds (label no_sanitize: 60 runs): Kp 0.05 instead of 0.20 on the
//    6 km/h continuation makes the flow error and its oscillation worse while
//    every run still passes its limits, and rig compare flags both.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "run_support.h"

namespace {

namespace fs = std::filesystem;
using rig::testing::read_all;
using rig::testing::run_shell;

const fs::path kCases = fs::path(RIG_SOURCE_DIR) / "cases";
const std::string kRig = std::string("'") + RIG_BINARY_DIR + "/bin/rig'";

// The case file with `extra` added to its controller section (appended as one when it has none).
fs::path variant(const fs::path& dir, const fs::path& file, const std::string& name, const std::string& after,
                 const std::string& extra) {
    std::string text = read_all(file);
    if (!extra.empty()) {
        const std::size_t at = text.find(after);
        EXPECT_NE(at, std::string::npos) << file << " no longer has '" << after << "'";
        if (at != std::string::npos) text.insert(text.find('\n', at) + 1, extra + "\n");
    }
    const fs::path written = dir / (name + ".yaml");
    std::ofstream(written) << text;
    return written;
}

nlohmann::json metric_of(const nlohmann::json& compare, const std::string& metric) {
    for (const auto& item : compare.at("cases").at(0).at("metrics")) {
        if (item.at("metric") == metric) return item;
    }
    return nullptr;
}

TEST(CompareRuns, OneSeedSameControllerIsSameBehaviourAndALateOneRegresses) {
    const fs::path dir = rig::testing::fresh_dir("compare-runs-one-seed");
    const fs::path drive_out = kCases / "seed001-table8-boundary" / "drive-out.yaml";
    const fs::path base = variant(dir, drive_out, "base", "", "");
    const fs::path late = variant(dir, drive_out, "late", "", "");
    std::ofstream(late, std::ios::app) << "controller:\n  faults: { command_delay_s: 0.1 }\n";
    for (const auto& [file, out] : {std::pair{base, dir / "base"}, std::pair{base, dir / "again"}, std::pair{late, dir / "late"}}) {
        const auto run = run_shell("timeout -k 10 300 " + kRig + " run '" + file.string() + "' --seed 1 --in-process --out '" +
                                   out.string() + "' --bmf '" + out.string() + ".bmf.json' 2>&1");
        // The late controller may break the case's limit too (exit 1); the comparison is what is tested.
        ASSERT_TRUE(run.exit_code == 0 || (file == late && run.exit_code == 1)) << run.output;
    }
    const nlohmann::json bmf = nlohmann::json::parse(read_all(dir / "base.bmf.json"));
    EXPECT_TRUE(bmf.at("seed001-table8-drive-out").at("drive_out_excess_mean_m").contains("value")) << bmf.dump(1);

    const auto same = run_shell(kRig + " compare '" + (dir / "base").string() + "' '" + (dir / "again").string() + "' 2>&1");
    EXPECT_EQ(same.exit_code, 0) << same.output;
    EXPECT_NE(same.output.find("1 unchanged"), std::string::npos) << same.output;

    const fs::path out = dir / "compare";
    const auto worse = run_shell(kRig + " compare '" + (dir / "base").string() + "' '" + (dir / "late").string() +
                                 "' --out '" + out.string() + "' 2>&1");
    EXPECT_EQ(worse.exit_code, 1) << worse.output;
    const nlohmann::json compare = nlohmann::json::parse(read_all(out / "compare.json"));
    const nlohmann::json& one = compare.at("cases").at(0);
    EXPECT_EQ(one.at("method"), "exact");
    EXPECT_EQ(one.at("changed"), nlohmann::json::array({"controller configuration"}));
    const nlohmann::json excess = metric_of(compare, "drive_out_excess_mean_m");
    ASSERT_FALSE(excess.is_null());
    EXPECT_EQ(excess.at("verdict"), "regressed") << excess.dump(1);
    // 0.1 s later at 1.5 m/s, the valves latching on their 9 Hz PWM period
    // (0.111 s): one period, 0.17 m, further past the edge.
    EXPECT_GT(excess.at("difference").get<double>(), 0.1);
    EXPECT_LT(excess.at("difference").get<double>(), 0.3);
    EXPECT_NE(read_all(out / "compare.md").find("drive_out_excess_mean_m"), std::string::npos);
    EXPECT_NE(read_all(out / "junit.xml").find("<failure"), std::string::npos);

    const auto missing = run_shell(kRig + " compare '" + (dir / "base").string() + "' '" + (dir / "nowhere").string() + "' 2>&1");
    EXPECT_EQ(missing.exit_code, 2) << missing.output;
    EXPECT_NE(missing.output.find("nowhere"), std::string::npos) << missing.output;
}

TEST(CompareRuns, ThirtySeedsFlagAWorseGainWhileEveryRunPasses) {
    const fs::path dir = rig::testing::fresh_dir("compare-runs-thirty-seeds");
    const fs::path continuation = kCases / "table5-6-continuation" / "continuation-6kmh.yaml";
    const fs::path base = variant(dir, continuation, "base", "", "");
    const fs::path soft = variant(dir, continuation, "soft", "hysteresis_compensation: true", "  pid: { kp: 0.05 }");
    for (const auto& [file, out] : {std::pair{base, dir / "base"}, std::pair{soft, dir / "soft"}}) {
        const auto sweep = run_shell("timeout -k 10 900 " + kRig + " sweep '" + file.string() +
                                     "' --seeds 30 --in-process --jobs 2 --keep-traces none -q --out '" + out.string() + "' 2>&1");
        ASSERT_EQ(sweep.exit_code, 0) << "every run passes its limits: " << sweep.output;
    }
    const fs::path out = dir / "compare";
    const auto compared = run_shell(kRig + " compare '" + (dir / "base").string() + "' '" + (dir / "soft").string() +
                                    "' --out '" + out.string() + "' 2>&1");
    EXPECT_EQ(compared.exit_code, 1) << compared.output;
    const nlohmann::json compare = nlohmann::json::parse(read_all(out / "compare.json"));
    EXPECT_EQ(compare.at("cases").at(0).at("method"), "u_test");
    for (const char* metric : {"flow_error_pct", "flow_oscillation_pct"}) {
        const nlohmann::json found = metric_of(compare, metric);
        ASSERT_FALSE(found.is_null()) << metric;
        EXPECT_EQ(found.at("verdict"), "regressed") << found.dump(1);
        EXPECT_GT(found.at("difference").get<double>(), 0.0) << metric;
        EXPECT_LT(found.at("p_adjusted").get<double>(), 0.01) << metric;
    }
    EXPECT_LT(metric_of(compare, "flow_error_pct").at("head_of_limit").get<double>(), 1.0);
}

}  // namespace
