// rig compare's decisions on hand-made samples (harness/regression/compare.h):
// one run a side is exact (same trace: same behaviour; a move beyond the
// minimum effect the worse way: regressed), many seeds go through the U test
// with Holm's correction, and what cannot be compared says why. The
// false-positive rate on no change is checked on recorded runs in
// compare_runs_test; here on samples drawn for the purpose.
#include <cmath>
#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "harness/regression/bencher_format.h"
#include "harness/regression/compare.h"
#include "harness/regression/compare_report.h"
#include "harness/regression/run_samples.h"

namespace {

using namespace rig::harness;

RunSample run(std::uint64_t seed, std::map<std::string, double> metrics, std::string trace = "") {
    RunSample sample;
    sample.seed = seed;
    sample.run = "case-seed" + std::to_string(seed);
    sample.metrics = std::move(metrics);
    sample.trace_sha256 = trace.empty() ? "trace-" + std::to_string(seed) : trace;
    sample.case_sha256 = "case-digest";
    sample.controller_sha256 = "controller-digest";
    sample.controller_config_sha256 = "config-digest";
    return sample;
}

RunSamples output_of(std::vector<CaseSamples> cases) {
    RunSamples samples;
    samples.kind = "sweep";
    samples.rig_version = "0.2.0";
    samples.rig_commit = "abc";
    samples.cases = std::move(cases);
    return samples;
}

CaseSamples one_case(std::vector<RunSample> runs, std::string name = "continuation-6kmh") {
    CaseSamples samples;
    samples.name = std::move(name);
    samples.file = "cases/x.yaml";
    samples.limits = {{"flow_adjust_time_s", 1.7}, {"overlap_m", 3.3}};
    samples.runs = std::move(runs);
    return samples;
}

const MetricComparison& metric_of(const Comparison& comparison, const std::string& metric) {
    for (const MetricComparison& found : comparison.cases.at(0).metrics) {
        if (found.metric == metric) return found;
    }
    throw std::runtime_error("no metric " + metric);
}

TEST(CompareExact, SameTraceIsSameBehaviour) {
    const auto base = output_of({one_case({run(1, {{"overlap_m", 1.9}}, "same")})});
    const Comparison comparison = compare_runs(base, base, {});
    EXPECT_EQ(comparison.cases.at(0).verdict, CompareVerdict::unchanged);
    EXPECT_EQ(comparison.cases.at(0).method, "exact");
    EXPECT_NE(comparison.cases.at(0).reason.find("same behaviour"), std::string::npos) << comparison.cases[0].reason;
    EXPECT_EQ(comparison.regressions(), 0u);
    EXPECT_FALSE(comparison.rig_differs);
}

TEST(CompareExact, AMoveTheWorseWayPastTheMinimumEffectRegressesWhileStillInsideTheLimit) {
    const auto base = output_of({one_case({run(1, {{"flow_adjust_time_s", 1.21}, {"overlap_m", 1.9},
                                                   {"flow_mean_l_min", 20.0}, {"overlap_typo_m", 1.0}}, "base")})});
    auto head_case = one_case({run(1, {{"flow_adjust_time_s", 1.58}, {"overlap_m", 1.93},
                                       {"flow_mean_l_min", 19.0}, {"overlap_typo_m", 2.0}}, "head")});
    head_case.runs[0].controller_config_sha256 = "another";
    const Comparison comparison = compare_runs(base, output_of({head_case}), {});
    const MetricComparison& adjust = metric_of(comparison, "flow_adjust_time_s");
    EXPECT_EQ(adjust.verdict, CompareVerdict::regressed) << adjust.reason;
    EXPECT_NEAR(*adjust.difference, 0.37, 1e-12);
    EXPECT_NEAR(*adjust.head_of_limit, 1.58 / 1.7, 1e-12);
    // 3 cm of overlap is less than its declared 5 cm.
    EXPECT_EQ(metric_of(comparison, "overlap_m").verdict, CompareVerdict::unchanged);
    EXPECT_NE(metric_of(comparison, "overlap_m").reason.find("minimum effect"), std::string::npos);
    // Neither better nor worse, and a name no declaration knows: reported, never a regression.
    EXPECT_EQ(metric_of(comparison, "flow_mean_l_min").verdict, CompareVerdict::unchanged);
    EXPECT_FALSE(metric_of(comparison, "overlap_typo_m").declared);
    EXPECT_EQ(metric_of(comparison, "overlap_typo_m").verdict, CompareVerdict::unchanged);
    EXPECT_EQ(comparison.cases[0].changed, std::vector<std::string>{"controller configuration"});
    EXPECT_EQ(comparison.regressions(), 1u);
    // The command line's minimum effect wins over the declared one.
    CompareSettings strict;
    strict.min_effects["overlap_m"] = 0.01;
    EXPECT_EQ(metric_of(compare_runs(base, output_of({head_case}), strict), "overlap_m").verdict,
              CompareVerdict::regressed);
}

TEST(CompareExact, LosingAMetricRegressesAndGainingOneImproves) {
    auto base_case = one_case({run(1, {{"flow_adjust_time_s", 1.3}}, "base")});
    auto head_case = one_case({run(1, {}, "head")});
    head_case.runs[0].not_measured["flow_adjust_time_s"] = "never settled";
    const Comparison worse = compare_runs(output_of({base_case}), output_of({head_case}), {});
    EXPECT_EQ(metric_of(worse, "flow_adjust_time_s").verdict, CompareVerdict::regressed);
    EXPECT_NE(metric_of(worse, "flow_adjust_time_s").reason.find("never settled"), std::string::npos);
    const Comparison better = compare_runs(output_of({head_case}), output_of({base_case}), {});
    EXPECT_EQ(metric_of(better, "flow_adjust_time_s").verdict, CompareVerdict::improved);
}

TEST(CompareExact, WhatCannotBeComparedSaysWhy) {
    const auto base = output_of({one_case({run(1, {{"overlap_m", 1.9}})}), one_case({run(1, {})}, "only-base")});
    auto other_seed = one_case({run(2, {{"overlap_m", 1.9}})});
    Comparison comparison = compare_runs(base, output_of({other_seed}), {});
    ASSERT_EQ(comparison.cases.size(), 2u);
    EXPECT_EQ(comparison.cases[0].verdict, CompareVerdict::not_comparable);
    EXPECT_NE(comparison.cases[0].reason.find("different seeds"), std::string::npos) << comparison.cases[0].reason;
    EXPECT_EQ(comparison.cases[1].reason, "only in the base");
    auto changed_case = one_case({run(1, {{"overlap_m", 1.9}})});
    changed_case.runs[0].case_sha256 = "edited";
    comparison = compare_runs(base, output_of({changed_case}), {});
    EXPECT_EQ(comparison.cases[0].verdict, CompareVerdict::not_comparable);
    EXPECT_NE(comparison.cases[0].reason.find("the case changed"), std::string::npos);
    auto other_rig = output_of({one_case({run(1, {{"overlap_m", 1.9}})})});
    other_rig.rig_commit = "def";
    EXPECT_TRUE(compare_runs(base, other_rig, {}).rig_differs);
    EXPECT_NE(compare_markdown(compare_runs(base, other_rig, {})).find("may be the rig's"), std::string::npos);
}

CaseSamples drawn(std::mt19937_64& random, double shift, std::uint64_t first_seed, std::size_t seeds,
                  std::size_t lose_adjust = 0) {
    std::normal_distribution<double> noise(0.0, 0.05);
    std::vector<RunSample> runs;
    for (std::size_t k = 0; k < seeds; ++k) {
        RunSample sample = run(first_seed + k, {{"flow_error_pct", 0.5 + shift + noise(random)},
                                                {"overlap_m", 1.9 + noise(random)},
                                                {"flow_adjust_time_s", 1.3 + noise(random)}});
        if (k < lose_adjust) {
            sample.metrics.erase("flow_adjust_time_s");
            sample.not_measured["flow_adjust_time_s"] = "never settled";
        }
        runs.push_back(std::move(sample));
    }
    return one_case(std::move(runs));
}

TEST(CompareSamples, AShiftOfTheWorseWayIsFoundAtThirtySeedsAndOnlyThere) {
    std::mt19937_64 random(5);
    const auto base = output_of({drawn(random, 0.0, 1, 30)});
    const auto head = output_of({drawn(random, 0.08, 1, 30)});
    const Comparison comparison = compare_runs(base, head, {});
    EXPECT_EQ(comparison.cases[0].method, "u_test");
    const MetricComparison& error = metric_of(comparison, "flow_error_pct");
    EXPECT_EQ(error.verdict, CompareVerdict::regressed) << error.reason;
    ASSERT_TRUE(error.difference && error.shift_low && error.shift_high);
    EXPECT_NEAR(*error.difference, 0.08, 0.03);
    EXPECT_LT(*error.shift_low, *error.difference);
    EXPECT_GT(*error.shift_high, *error.difference);
    EXPECT_LT(*error.p_adjusted, 0.01);
    EXPECT_EQ(metric_of(comparison, "overlap_m").verdict, CompareVerdict::unchanged);
    EXPECT_EQ(comparison.tests, 3u);  // Holm's family: the three metrics with a direction
    // The same shift, but a minimum effect above it: significant and not news.
    CompareSettings coarse;
    coarse.min_effects["flow_error_pct"] = 0.5;
    const Comparison coarse_comparison = compare_runs(base, head, coarse);
    const MetricComparison& small = metric_of(coarse_comparison, "flow_error_pct");
    EXPECT_EQ(small.verdict, CompareVerdict::unchanged);
    EXPECT_NE(small.reason.find("less than its minimum effect"), std::string::npos) << small.reason;
    // An improvement is the mirror image.
    EXPECT_EQ(metric_of(compare_runs(head, base, {}), "flow_error_pct").verdict, CompareVerdict::improved);
}

TEST(CompareSamples, RunsThatLoseTheMetricAreARegression) {
    std::mt19937_64 random(9);
    const auto base = output_of({drawn(random, 0.0, 1, 30)});
    const auto head = output_of({drawn(random, 0.0, 1, 30, /*lose_adjust=*/12)});
    const Comparison comparison = compare_runs(base, head, {});
    const MetricComparison& adjust = metric_of(comparison, "flow_adjust_time_s");
    EXPECT_EQ(adjust.verdict, CompareVerdict::regressed) << adjust.reason;
    EXPECT_NE(adjust.reason.find("not measured in 0 -> 12 runs"), std::string::npos) << adjust.reason;
}

TEST(CompareSamples, DifferentSeedSetsNeedAnyseeds) {
    std::mt19937_64 random(3);
    const auto base = output_of({drawn(random, 0.0, 1, 20)});
    const auto head = output_of({drawn(random, 0.0, 21, 20)});
    EXPECT_EQ(compare_runs(base, head, {}).cases[0].verdict, CompareVerdict::not_comparable);
    CompareSettings any;
    any.any_seeds = true;
    EXPECT_EQ(compare_runs(base, head, any).cases[0].verdict, CompareVerdict::unchanged);
}

// No change, many comparisons of a three-case suite: a comparison flags
// anything with probability at most alpha (Holm over the whole family).
TEST(CompareSamples, NoChangeFlagsAComparisonAtMostAlphaOfTheTime) {
    std::mt19937_64 random(2026);
    const int comparisons = 600;
    int flagged = 0;
    CompareSettings settings;
    settings.any_seeds = true;
    settings.min_effects = {{"flow_error_pct", 0.0}, {"overlap_m", 0.0}, {"flow_adjust_time_s", 0.0}};
    for (int k = 0; k < comparisons; ++k) {
        std::vector<CaseSamples> base_cases, head_cases;
        for (const char* name : {"a", "b", "c"}) {
            base_cases.push_back(drawn(random, 0.0, 1, 10));
            base_cases.back().name = name;
            head_cases.push_back(drawn(random, 0.0, 11, 10));
            head_cases.back().name = name;
        }
        Comparison comparison = compare_runs(output_of(base_cases), output_of(head_cases), settings);
        if (comparison.regressions() + comparison.metric_counts[CompareVerdict::improved] > 0) ++flagged;
    }
    EXPECT_LE(flagged, static_cast<int>(comparisons * 0.01 + 3.0 * std::sqrt(comparisons * 0.01 * 0.99)));
}

// Recorded runs of no change: the reference controller on the 6 km/h
// continuation over seeds 1-60 (tests/regression/, a `rig sweep` output).
// Split at random into two disjoint halves, each split is a draw of the U
// test's own null distribution; Holm over the 18 directional metrics keeps
// the share of splits flagged anywhere at most alpha. Without the correction
// it would be near 1 - 0.99^18 = 17 %.
TEST(CompareRecorded, SplitsOfOneControllersRunsAreFlaggedAtMostAlphaOfTheTime) {
    const RunSamples recorded =
        load_run_samples(std::string(RIG_SOURCE_DIR) + "/tests/regression/continuation-6kmh-60-seeds.json");
    ASSERT_EQ(recorded.cases.size(), 1u);
    ASSERT_EQ(recorded.cases[0].runs.size(), 60u);
    CompareSettings settings;
    settings.any_seeds = true;
    std::mt19937_64 random(60);
    for (std::size_t seeds : {10u, 30u}) {
        const int splits = 400;
        int flagged = 0;
        std::size_t family = 0;
        for (int k = 0; k < splits; ++k) {
            std::vector<RunSample> runs = recorded.cases[0].runs;
            std::shuffle(runs.begin(), runs.end(), random);
            RunSamples base = recorded, head = recorded;
            base.cases[0].runs.assign(runs.begin(), runs.begin() + static_cast<long>(seeds));
            head.cases[0].runs.assign(runs.begin() + static_cast<long>(seeds), runs.begin() + static_cast<long>(2 * seeds));
            for (RunSamples* side : {&base, &head}) {
                std::sort(side->cases[0].runs.begin(), side->cases[0].runs.end(),
                          [](const RunSample& a, const RunSample& b) { return a.seed < b.seed; });
            }
            Comparison comparison = compare_runs(base, head, settings);
            family = comparison.tests;
            if (comparison.regressions() + comparison.metric_counts[CompareVerdict::improved] > 0) ++flagged;
        }
        EXPECT_GE(family, 15u);
        EXPECT_LE(flagged, static_cast<int>(splits * 0.01 + 3.0 * std::sqrt(splits * 0.01 * 0.99)))
            << seeds << " seeds a side: " << flagged << " of " << splits << " splits flagged";
    }
}

TEST(CompareOutputs, JsonMarkdownHtmlAndJunitCarryTheRegression) {
    std::mt19937_64 random(5);
    const auto base = output_of({drawn(random, 0.0, 1, 30)});
    const auto head = output_of({drawn(random, 0.08, 1, 30)});
    const Comparison comparison = compare_runs(base, head, {});
    const nlohmann::json json = compare_json(comparison);
    EXPECT_EQ(json.at("schema_version"), kCompareSchemaVersion);
    EXPECT_EQ(json.at("summary").at("metrics").at("regressed"), 1);
    EXPECT_EQ(json.at("cases").at(0).at("verdict"), "regressed");
    const std::string markdown = compare_markdown(comparison);
    EXPECT_NE(markdown.find("#### Regressed"), std::string::npos);
    EXPECT_NE(markdown.find("`flow_error_pct`"), std::string::npos);
    EXPECT_NE(compare_html(comparison).find("<svg"), std::string::npos);
    const std::string junit = compare_junit(comparison);
    EXPECT_NE(junit.find("failures=\"1\""), std::string::npos);
    EXPECT_NE(junit.find("<failure"), std::string::npos);
    const nlohmann::json bmf = bencher_metric_format(head);
    EXPECT_TRUE(bmf.at("continuation-6kmh").at("flow_error_pct").contains("lower_value"));
    EXPECT_LT(bmf["continuation-6kmh"]["flow_error_pct"]["lower_value"].get<double>(),
              bmf["continuation-6kmh"]["flow_error_pct"]["value"].get<double>());
}

}  // namespace
