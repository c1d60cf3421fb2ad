// `rig sweep` (harness/report/sweep.h, issue 15 Monte Carlo): percentiles as numpy's
// default computes them, bands and pass rates from runs whose numbers are
// known, and the command itself: its runs are the case's own runs (a seed's
// digest is `rig run --seed`'s), traces kept only as asked, real-time cases
// and bad arguments refused by name.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "harness/spec/case_spec.h"
#include "harness/systems/systems.h"
#include "harness/report/sweep.h"
#include "run_support.h"

namespace fs = std::filesystem;
using namespace rig::harness;
using rig::testing::fresh_dir;
using rig::testing::read_all;
using rig::testing::run_shell;

namespace {

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

const std::string kRig = quoted(RIG_BINARY_DIR "/bin/rig");
const std::string kShortCase = quoted(RIG_SOURCE_DIR "/tests/data/short-fusion.yaml");

CaseResult run_with(std::map<std::string, double> metrics, std::map<std::string, double> limits, bool passed) {
    CaseResult result;
    result.name = "c";
    result.metrics = std::move(metrics);
    result.limits = std::move(limits);
    result.passed = passed;
    if (!passed) result.failures.push_back("a metric over its limit");
    return result;
}

const MetricBand* band_named(const CaseSweep& sweep, const std::string& metric) {
    for (const MetricBand& band : sweep.bands) {
        if (band.metric == metric) return &band;
    }
    return nullptr;
}

}  // namespace

TEST(Sweep, PercentilesInterpolateBetweenOrderStatisticsAsNumpyDoes) {
    // numpy.percentile([1, 2, 3, 4], [0, 5, 50, 95, 100]) = 1, 1.15, 2.5, 3.85, 4
    const std::vector<double> four = {1, 2, 3, 4};
    EXPECT_DOUBLE_EQ(percentile_of_sorted(four, 0), 1.0);
    EXPECT_NEAR(percentile_of_sorted(four, 5), 1.15, 1e-12);
    EXPECT_DOUBLE_EQ(percentile_of_sorted(four, 50), 2.5);
    EXPECT_NEAR(percentile_of_sorted(four, 95), 3.85, 1e-12);
    EXPECT_DOUBLE_EQ(percentile_of_sorted(four, 100), 4.0);
    // 1..100: p5 = 5.95, p95 = 95.05 (numpy)
    std::vector<double> hundred;
    for (int i = 1; i <= 100; ++i) hundred.push_back(i);
    EXPECT_NEAR(percentile_of_sorted(hundred, 5), 5.95, 1e-12);
    EXPECT_NEAR(percentile_of_sorted(hundred, 95), 95.05, 1e-12);
    EXPECT_DOUBLE_EQ(percentile_of_sorted({7.0}, 95), 7.0);
    EXPECT_TRUE(std::isnan(percentile_of_sorted({}, 50)));
}

TEST(Sweep, BandsCountRunsOverTheLimitAndUnmeasuredOnesAndKeepThePapersNumber) {
    CaseSpec first;
    first.name = "first";
    first.paper.source = "Table 2";
    first.paper.values = {{"flow_adjust_time_s", 1.286}, {"never_measured_s", 2.0}};
    CaseSpec second;
    second.name = "second";
    const std::vector<CaseSpec> specs = {first, second};
    const std::map<std::string, double> limits = {{"flow_adjust_time_s", 1.7}};
    std::vector<CaseInstance> runs;
    std::vector<CaseResult> results;
    // first: values 1.0 .. 1.9 for seeds 1..10 (1.8 and 1.9 over 1.7), seed 11 never settled.
    for (int seed = 1; seed <= 10; ++seed) {
        const double value = (9.0 + seed) / 10.0;  // 1.7 exactly as the literal
        runs.push_back(CaseInstance{0, static_cast<std::uint64_t>(seed), "first-seed" + std::to_string(seed)});
        results.push_back(run_with({{"flow_adjust_time_s", value}, {"overlap_m", 1.0}}, limits, value <= 1.7));
    }
    runs.push_back(CaseInstance{0, 11, "first-seed11"});
    CaseResult unsettled = run_with({{"overlap_m", 1.0}}, limits, false);
    unsettled.not_measured["flow_adjust_time_s"] = "never settled";
    results.push_back(unsettled);
    // second: interleaved with the first's runs, as --jobs finishes them.
    runs.insert(runs.begin() + 3, CaseInstance{1, 4, "second-seed4"});
    results.insert(results.begin() + 3, run_with({{"overlap_m", 2.0}}, {}, true));

    const std::vector<CaseSweep> sweeps = summarize_sweep(specs, runs, results);
    ASSERT_EQ(sweeps.size(), 2u);
    const CaseSweep& a = sweeps[0];
    EXPECT_EQ(a.runs, 11u);
    EXPECT_EQ(a.passed, 8u);
    EXPECT_EQ(a.failed_seeds, (std::vector<std::uint64_t>{9, 10, 11}));
    EXPECT_EQ(a.paper_source, "Table 2");
    EXPECT_EQ(a.paper_unmatched, std::vector<std::string>{"never_measured_s"});
    const MetricBand* time = band_named(a, "flow_adjust_time_s");
    ASSERT_NE(time, nullptr);
    EXPECT_EQ(time->measured, 10u);
    EXPECT_EQ(time->not_measured, 1u);
    EXPECT_EQ(time->over_limit, 3u);  // 1.8, 1.9 and the run that never settled
    EXPECT_NEAR(time->min, 1.0, 1e-12);
    EXPECT_NEAR(time->max, 1.9, 1e-12);
    EXPECT_NEAR(time->p50, 1.45, 1e-12);
    EXPECT_NEAR(time->p95, 1.855, 1e-12);
    EXPECT_NEAR(time->mean, 1.45, 1e-12);
    ASSERT_TRUE(time->limit.has_value());
    EXPECT_DOUBLE_EQ(*time->limit, 1.7);
    ASSERT_TRUE(time->paper.has_value());
    EXPECT_DOUBLE_EQ(*time->paper, 1.286);
    const MetricBand* overlap = band_named(a, "overlap_m");
    ASSERT_NE(overlap, nullptr);
    EXPECT_FALSE(overlap->limit.has_value());
    EXPECT_EQ(overlap->over_limit, 0u);
    const CaseSweep& b = sweeps[1];
    EXPECT_EQ(b.runs, 1u);
    EXPECT_EQ(b.passed, 1u);
    EXPECT_TRUE(b.failed_seeds.empty());

    SweepInfo info;
    info.seeds = {1, 2, 3};
    const std::string table = sweep_table(sweeps, info);
    EXPECT_NE(table.find("8/11"), std::string::npos) << table;
    EXPECT_NE(table.find("did not pass with seeds 9 10 11"), std::string::npos) << table;
    EXPECT_NE(table.find("1.286"), std::string::npos) << table;
    const std::string html = sweep_html(sweeps, info);
    EXPECT_NE(html.find("stroke=\"#c00\""), std::string::npos);  // the limit
    EXPECT_NE(html.find("<polygon"), std::string::npos);         // the paper's number
    EXPECT_NE(html.find("8 of 11 passed"), std::string::npos);
    const nlohmann::json json = sweep_json(sweeps, runs, results, info);
    EXPECT_EQ(json.at("cases").at(0).at("bands").at("flow_adjust_time_s").at("over_limit"), 3);
    EXPECT_EQ(json.at("cases").at(0).at("seeds").size(), 11u);
    EXPECT_EQ(json.at("cases").at(1).at("seeds").at(0).at("run"), "second-seed4");
}

TEST(Sweep, ItsRunsAreTheCasesOwnRunsAndItKeepsTheTracesAsked) {
    const fs::path dir = fresh_dir("sweep-command");
    const auto sweep = run_shell(kRig + " sweep " + kShortCase + " --seeds 3 --first-seed 4 --jobs 2 --in-process --out " +
                                 quoted(dir / "sweep") + " 2>&1");
    ASSERT_EQ(sweep.exit_code, 0) << sweep.output;
    EXPECT_NE(sweep.output.find("3 runs: 3 passed"), std::string::npos) << sweep.output;
    const nlohmann::json json = nlohmann::json::parse(read_all(dir / "sweep" / "sweep.json"));
    EXPECT_EQ(json.at("seeds"), (std::vector<int>{4, 5, 6}));
    const nlohmann::json& runs = json.at("cases").at(0).at("seeds");
    ASSERT_EQ(runs.size(), 3u);
    // Passed runs keep no trace by default; their numbers stay.
    for (const nlohmann::json& run : runs) {
        EXPECT_FALSE(fs::exists(dir / "sweep" / "cases" / run.at("run").get<std::string>() / "trace.sqlite"));
        EXPECT_TRUE(run.at("passed").get<bool>());
    }
    EXPECT_TRUE(fs::exists(dir / "sweep" / "sweep.html"));
    // Seed 5 of the sweep is `rig run --seed 5`, digest for digest.
    const auto single = run_shell(kRig + " run " + kShortCase + " --seed 5 --out " + quoted(dir / "single") + " 2>&1");
    ASSERT_EQ(single.exit_code, 0) << single.output;
    const nlohmann::json results = nlohmann::json::parse(read_all(dir / "single" / "results.json"));
    EXPECT_EQ(runs.at(1).at("seed"), 5);
    EXPECT_EQ(runs.at(1).at("trace_sha256"), results.at("cases").at(0).at("trace_sha256"));

    const auto kept = run_shell(kRig + " sweep " + kShortCase + " --seeds 1 --keep-traces all -q --out " +
                                quoted(dir / "kept") + " 2>&1");
    ASSERT_EQ(kept.exit_code, 0) << kept.output;
    EXPECT_TRUE(fs::exists(dir / "kept" / "cases" / "short-fusion-seed1" / "trace.sqlite")) << kept.output;
}

TEST(Sweep, RefusesRealTimeCasesAndBadArgumentsByName) {
    const fs::path dir = fresh_dir("sweep-refusals");
    const auto realtime = run_shell(kRig + " sweep " + quoted(RIG_SOURCE_DIR "/cases/bench-wired") + " --seeds 2 --out " +
                                    quoted(dir / "rt") + " 2>&1");
    EXPECT_EQ(realtime.exit_code, 2) << realtime.output;
    EXPECT_NE(realtime.output.find("real-time case"), std::string::npos) << realtime.output;
    EXPECT_FALSE(fs::exists(dir / "rt" / "sweep.json"));
    const auto no_seeds = run_shell(kRig + " sweep " + kShortCase + " --seeds 0 --out " + quoted(dir / "zero") + " 2>&1");
    EXPECT_EQ(no_seeds.exit_code, 2) << no_seeds.output;
    EXPECT_NE(no_seeds.output.find("--seeds"), std::string::npos) << no_seeds.output;
    const auto overflow = run_shell(kRig + " sweep " + kShortCase +
                                    " --seeds 2 --first-seed 18446744073709551615 --out " + quoted(dir / "big") + " 2>&1");
    EXPECT_EQ(overflow.exit_code, 2) << overflow.output;
    EXPECT_NE(overflow.output.find("largest seed"), std::string::npos) << overflow.output;
    const auto keep = run_shell(kRig + " sweep " + kShortCase + " --seeds 2 --keep-traces some --out " +
                                quoted(dir / "keep") + " 2>&1");
    EXPECT_EQ(keep.exit_code, 2) << keep.output;
    EXPECT_NE(keep.output.find("--keep-traces"), std::string::npos) << keep.output;
}

TEST(Sweep, ThePapersNumbersNeedASourceAndMetricNamesWithUnits) {
    const std::string base = read_all(RIG_SOURCE_DIR "/tests/data/short-fusion.yaml");
    ASSERT_FALSE(base.empty());
    const CaseSpec plain = parse_case(base, "short-fusion.yaml");
    EXPECT_TRUE(plain.paper.values.empty());
    const CaseSpec with = parse_case(base + "\npaper: { source: \"Table 6, 6 km/h\", overlap_m: 3.3, missed_m: 0 }\n",
                                     "short-fusion.yaml");
    EXPECT_EQ(with.paper.source, "Table 6, 6 km/h");
    EXPECT_EQ(with.paper.values, (std::map<std::string, double>{{"missed_m", 0.0}, {"overlap_m", 3.3}}));
    auto error_of = [&](const std::string& paper) {
        try {
            parse_case(base + "\n" + paper + "\n", "short-fusion.yaml");
        } catch (const std::exception& error) {
            return std::string(error.what());
        }
        return std::string("accepted");
    };
    EXPECT_NE(error_of("paper: { overlap_m: 3.3 }").find("need a source"), std::string::npos);
    EXPECT_NE(error_of("paper: { source: \"Table 6\", overlap: 3.3 }").find("unit suffix"), std::string::npos);
    EXPECT_NE(error_of("paper: { source: \"Table 6\", overlap_m: fast }").find("overlap_m"), std::string::npos);
    EXPECT_NE(error_of("paper: { source: \"\", overlap_m: 3.3 }").find("source"), std::string::npos);
}
