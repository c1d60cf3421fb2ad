// The table of which way each metric gets worse (harness/judge/metric_direction.h):
// every metric the golden runs of both systems give is declared, every limited
// one is worse upwards (a limit is an upper bound), and the patterns pick the
// family a numbered metric belongs to.
#include <fstream>
#include <iterator>
#include <limits>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "harness/judge/metric_direction.h"

namespace {

using rig::harness::declared_metric;
using rig::harness::is_worse;
using rig::harness::WorseDirection;

TEST(MetricDirection, EveryMetricOfTheGoldenRunsIsDeclared) {
    std::ifstream file(std::string(RIG_SOURCE_DIR) + "/tests/golden/results.json");
    ASSERT_TRUE(file) << "tests/golden/results.json";
    const nlohmann::json results = nlohmann::json::parse(file);
    std::size_t checked = 0;
    for (const auto& run : results.at("cases")) {
        for (const auto& [name, value] : run.at("metrics").items()) {
            EXPECT_TRUE(declared_metric(name).has_value()) << name << " (" << run.at("name") << ")";
            ++checked;
        }
        for (const auto& [name, limit] : run.at("limits").items()) {
            const auto declaration = declared_metric(name);
            ASSERT_TRUE(declaration.has_value()) << name;
            EXPECT_EQ(declaration->worse, WorseDirection::up) << name << " is limited, so higher is worse";
            EXPECT_GT(declaration->min_effect, 0.0) << name;
        }
    }
    EXPECT_GT(checked, 100u);
}

// docs/metrics.md "Worse is" prints every declaration: the page and the table stay in step.
TEST(MetricDirection, EveryDeclarationIsInTheMetricsPage) {
    std::ifstream file(std::string(RIG_SOURCE_DIR) + "/docs/metrics.md");
    ASSERT_TRUE(file) << "docs/metrics.md";
    const std::string page((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    for (const auto& declaration : rig::harness::metric_declarations()) {
        const std::string row = "| `" + std::string(declaration.pattern) + "` | " +
                                std::string(rig::harness::worse_direction_name(declaration.worse)) + " |";
        EXPECT_NE(page.find(row), std::string::npos) << "docs/metrics.md lacks the row " << row;
    }
}

TEST(MetricDirection, NumberedFamiliesFindTheirOwnRule) {
    EXPECT_EQ(declared_metric("drive_out_excess_nozzle3_mean_m")->worse, WorseDirection::up);
    EXPECT_EQ(declared_metric("breakpoint_error_signed_m")->worse, WorseDirection::away_from_zero);
    EXPECT_EQ(declared_metric("drive_in_excess_nozzle12_max_m")->worse, WorseDirection::up);
    EXPECT_EQ(declared_metric("boundary_overrun_min_m")->worse, WorseDirection::down);
    EXPECT_EQ(declared_metric("boundary_overrun_stations_dry")->worse, WorseDirection::up);
    EXPECT_EQ(declared_metric("boundary_overrun_stations")->worse, WorseDirection::none);
    EXPECT_EQ(declared_metric("vision_camera1_level_mismatch_pct")->worse, WorseDirection::up);
    EXPECT_EQ(declared_metric("flow_nozzle2_duty40_l_min")->worse, WorseDirection::none);
    EXPECT_EQ(declared_metric("gnss_corrupt_checksums_count")->worse, WorseDirection::none);
    EXPECT_EQ(declared_metric("overlap_m")->min_effect, 0.05);
    EXPECT_FALSE(declared_metric("overlap_m_typo").has_value());
    EXPECT_FALSE(declared_metric("").has_value());
}

TEST(MetricDirection, WorseFollowsTheDirection) {
    EXPECT_TRUE(is_worse(WorseDirection::up, 1.21, 1.58));
    EXPECT_FALSE(is_worse(WorseDirection::up, 1.58, 1.21));
    EXPECT_TRUE(is_worse(WorseDirection::down, 0.99, 0.95));
    EXPECT_TRUE(is_worse(WorseDirection::away_from_zero, 0.1, -0.3));
    EXPECT_FALSE(is_worse(WorseDirection::away_from_zero, -0.3, 0.1));
    EXPECT_FALSE(is_worse(WorseDirection::none, 0.0, 1e9));
    EXPECT_FALSE(is_worse(WorseDirection::up, 1.0, 1.0));
}

}  // namespace
