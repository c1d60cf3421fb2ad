// The harness's flow and deposition metrics (DESIGN.md "What the harness
// measures"; seed 000 Table 2, 5, 6 and Eq. 10-12) on hand-built truth with
// known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "harness/metrics.h"

namespace {

using rig::TimeNs;
using rig::harness::AreaSpan;
using rig::harness::DepositionJudging;
using rig::harness::DoseProfile;
using rig::harness::FlowEpisode;
using rig::harness::MainFlowSample;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kS = 1'000'000'000;

// Truth samples every 10 ms over [from, to), the flow given by `flow(t)`.
std::vector<MainFlowSample> sampled(TimeNs from, TimeNs to, const std::function<double(TimeNs)>& flow) {
    std::vector<MainFlowSample> samples;
    for (TimeNs t = from; t < to; t += 10 * kMs) samples.push_back({t, flow(t)});
    return samples;
}

double at(const std::map<std::string, double>& metrics, const std::string& name) {
    const auto it = metrics.find(name);
    if (it == metrics.end()) {
        ADD_FAILURE() << "metric " << name << " missing";
        return std::nan("");
    }
    return it->second;
}

const FlowEpisode kEpisode{1 * kS, 5 * kS};  // sections commanded open at 1 s, closed at 5 s

// ---------------------------------------------------------------- flow_metrics

TEST(FlowMetrics, StepOntoTargetGivesExactlyItsAdjustTime) {
    // Near Table 2's mean (1.359 s): the flow jumps from 0 onto 20 L/min at 2.36 s (open at 1 s).
    const auto samples = sampled(0, 6 * kS, [](TimeNs t) { return t >= 2360 * kMs ? 20.0 : 0.0; });
    const auto metrics = rig::harness::flow_metrics(samples, kEpisode, 20.0);
    EXPECT_EQ(at(metrics, "flow_settled"), 1.0);
    EXPECT_NEAR(at(metrics, "flow_adjust_time_s"), 1.36, 1e-12);
    EXPECT_EQ(at(metrics, "flow_error_pct"), 0.0);
    EXPECT_EQ(at(metrics, "flow_mean_l_min"), 20.0);
}

TEST(FlowMetrics, EnteringTheBandCountsNotReachingTheTarget) {
    // 19.5 L/min is inside +-3 % (19.4-20.6): settled from there on; error 2.5 %.
    const auto samples = sampled(0, 6 * kS, [](TimeNs t) { return t >= 2 * kS ? 19.5 : 10.0; });
    const auto metrics = rig::harness::flow_metrics(samples, kEpisode, 20.0);
    EXPECT_NEAR(at(metrics, "flow_adjust_time_s"), 1.0, 1e-12);
    EXPECT_NEAR(at(metrics, "flow_error_pct"), 2.5, 1e-9);
    EXPECT_NEAR(at(metrics, "flow_mean_l_min"), 19.5, 1e-9);
}

TEST(FlowMetrics, LeavingTheBandRestartsTheAdjustTime) {
    // On target at 2.0 s, out (21 L/min, +5 %) from 3.00 to 3.10 s, back for good at 3.10 s.
    const auto samples = sampled(0, 6 * kS, [](TimeNs t) {
        if (t < 2 * kS) return 0.0;
        if (t >= 3 * kS && t < 3100 * kMs) return 21.0;
        return 20.0;
    });
    const auto metrics = rig::harness::flow_metrics(samples, kEpisode, 20.0);
    EXPECT_EQ(at(metrics, "flow_settled"), 1.0);
    EXPECT_NEAR(at(metrics, "flow_adjust_time_s"), 2.1, 1e-12);
    EXPECT_EQ(at(metrics, "flow_error_pct"), 0.0);  // measured after settling only
}

TEST(FlowMetrics, NeverSettlingGivesTheEpisodeLength) {
    // 25 L/min throughout (+25 %): never in the band. Adjust time = 4 s (the episode),
    // error taken from open + 1.7 s: 25 %.
    const auto samples = sampled(0, 6 * kS, [](TimeNs) { return 25.0; });
    const auto metrics = rig::harness::flow_metrics(samples, kEpisode, 20.0);
    EXPECT_EQ(at(metrics, "flow_settled"), 0.0);
    EXPECT_NEAR(at(metrics, "flow_adjust_time_s"), 4.0, 1e-12);
    EXPECT_NEAR(at(metrics, "flow_error_pct"), 25.0, 1e-9);
    // Leaving the band in the episode's last sample also counts as not settled.
    const auto late = sampled(0, 6 * kS, [](TimeNs t) { return t >= 4990 * kMs ? 30.0 : 20.0; });
    EXPECT_EQ(at(rig::harness::flow_metrics(late, kEpisode, 20.0), "flow_settled"), 0.0);
}

TEST(FlowMetrics, FlowErrorIsTheMeanRelativeDeviationAfterSettling) {
    // Settled at 2 s; then alternately 20.4 (+2 %) and 19.8 (-1 %): mean 1.5 %, mean
    // flow 20.1. The samples from 2.00 to 4.99 s are 300, half of each.
    // Outside the episode (before the open command, after the close) wild values must not count.
    const auto samples = sampled(0, 7 * kS, [](TimeNs t) {
        if (t < 1 * kS || t > 5 * kS) return 100.0;
        if (t < 2 * kS) return 0.0;
        if (t == 5 * kS) return 20.0;  // the episode's end instant is inside it
        return (t / (10 * kMs)) % 2 == 0 ? 20.4 : 19.8;
    });
    const auto metrics = rig::harness::flow_metrics(samples, kEpisode, 20.0);
    EXPECT_NEAR(at(metrics, "flow_adjust_time_s"), 1.0, 1e-12);
    // 150 x 2 % + 150 x 1 % + 1 x 0 % over 301 samples.
    EXPECT_NEAR(at(metrics, "flow_error_pct"), (150 * 2.0 + 150 * 1.0) / 301.0, 1e-9);
    EXPECT_NEAR(at(metrics, "flow_mean_l_min"), (150 * 20.4 + 150 * 19.8 + 20.0) / 301.0, 1e-9);
}

TEST(FlowMetrics, FlowErrorIsRelativeToTheTarget) {
    // Table 5 at 3 km/h: 19.58 L/min against 20 is 2.1 % of the target (2.145 % of
    // the measured flow). The paper prints -2.08 %, presumably from unrounded means.
    const auto samples = sampled(0, 6 * kS, [](TimeNs t) { return t >= 2 * kS ? 19.58 : 0.0; });
    const auto metrics = rig::harness::flow_metrics(samples, kEpisode, 20.0);
    EXPECT_NEAR(at(metrics, "flow_error_pct"), 2.1, 1e-9);
}

TEST(FlowMetrics, NoSamplesInTheEpisodeGiveNoMetrics) {
    const auto samples = sampled(6 * kS, 7 * kS, [](TimeNs) { return 20.0; });
    EXPECT_TRUE(rig::harness::flow_metrics(samples, kEpisode, 20.0).empty());
}

// ---------------------------------------------------------------- deposition_metrics

// 400 rows of 0.05 m from -10 to +10 m (row i centred at -9.975 + 0.05 i); the
// breakpoint at 0, between rows 199 and 200. Each pass sprays the nominal dose on
// the rows its predicate picks.
constexpr double kNominal = 1.64;  // uL/cm^2: 20 L/min, 6 km/h, 12.2 m (164 L/ha)

DoseProfile profile(const std::function<double(int)>& first, const std::function<double(int)>& continuation) {
    DoseProfile p;
    p.first_row_centre_m = -9.975;
    p.row_m = 0.05;
    for (int i = 0; i < 400; ++i) {
        p.first_pass.push_back(first(i));
        p.continuation.push_back(continuation(i));
    }
    return p;
}

DepositionJudging judging() {
    DepositionJudging j;
    j.nominal_dose_ul_cm2 = kNominal;
    return j;  // sprayed above half the nominal dose; CV rows 0.3 m, windows 6 m
}

const AreaSpan* find_area(const std::vector<AreaSpan>& areas, const std::string& name) {
    for (const AreaSpan& area : areas) {
        if (area.name == name) return &area;
    }
    return nullptr;
}

TEST(DepositionMetrics, OverlapOfOnePointFiveMetresIsMeasuredAsSuch) {
    // Table 6 at 3 km/h: 1.5 m repeated. First pass up to the breakpoint, the
    // continuation from 1.5 m before it (row 170).
    const auto p = profile([](int i) { return i < 200 ? kNominal : 0.0; },
                           [](int i) { return i >= 170 ? kNominal : 0.0; });
    const auto result = rig::harness::deposition_metrics(p, judging(), 0.0);
    EXPECT_NEAR(at(result.metrics, "overlap_m"), 1.5, 1e-12);
    EXPECT_EQ(at(result.metrics, "missed_m"), 0.0);
    EXPECT_NEAR(at(result.metrics, "repeated_from_m"), -1.5, 1e-9);
    EXPECT_NEAR(at(result.metrics, "repeated_to_m"), 0.0, 1e-9);
    const AreaSpan* repeated = find_area(result.areas, "repeated");
    ASSERT_NE(repeated, nullptr);
    EXPECT_NEAR(repeated->from_along_m, -1.5, 1e-9);
    EXPECT_NEAR(repeated->to_along_m, 0.0, 1e-9);
    EXPECT_EQ(find_area(result.areas, "missed"), nullptr);
    // Uniform doses: every area's CV is 0.
    EXPECT_NEAR(at(result.metrics, "cv_operational_pct"), 0.0, 1e-9);
    EXPECT_NEAR(at(result.metrics, "cv_repeated_pct"), 0.0, 1e-9);
    EXPECT_NEAR(at(result.metrics, "cv_continuation_pct"), 0.0, 1e-9);
}

TEST(DepositionMetrics, GapOfSixtyCentimetresIsMissed) {
    // The continuation lands 0.6 m after the breakpoint (row 212).
    const auto p = profile([](int i) { return i < 200 ? kNominal : 0.0; },
                           [](int i) { return i >= 212 ? kNominal : 0.0; });
    const auto result = rig::harness::deposition_metrics(p, judging(), 0.0);
    EXPECT_NEAR(at(result.metrics, "missed_m"), 0.6, 1e-12);
    EXPECT_EQ(at(result.metrics, "overlap_m"), 0.0);
    const AreaSpan* missed = find_area(result.areas, "missed");
    ASSERT_NE(missed, nullptr);
    EXPECT_NEAR(missed->from_along_m, 0.0, 1e-9);
    EXPECT_NEAR(missed->to_along_m, 0.6, 1e-9);
    EXPECT_EQ(find_area(result.areas, "repeated"), nullptr);
    EXPECT_EQ(result.metrics.count("cv_repeated_pct"), 0u);
}

TEST(DepositionMetrics, PassesMeetingExactlyGiveNeitherOverlapNorGap) {
    const auto p = profile([](int i) { return i < 200 ? kNominal : 0.0; },
                           [](int i) { return i >= 200 ? kNominal : 0.0; });
    const auto result = rig::harness::deposition_metrics(p, judging(), 0.0);
    EXPECT_EQ(at(result.metrics, "overlap_m"), 0.0);
    EXPECT_EQ(at(result.metrics, "missed_m"), 0.0);
    EXPECT_EQ(find_area(result.areas, "missed"), nullptr);
    EXPECT_EQ(find_area(result.areas, "repeated"), nullptr);
    // Without a repeated area the breakpoint separates the operational and continuation areas.
    const AreaSpan* operational = find_area(result.areas, "operational");
    const AreaSpan* continuation = find_area(result.areas, "continuation");
    ASSERT_NE(operational, nullptr);
    ASSERT_NE(continuation, nullptr);
    EXPECT_EQ(operational->to_along_m, 0.0);
    EXPECT_EQ(operational->from_along_m, -6.0);
    EXPECT_EQ(continuation->from_along_m, 0.0);
    EXPECT_EQ(continuation->to_along_m, 6.0);
}

TEST(DepositionMetrics, UnsprayedEndsOfTheTrackAreNotMissed) {
    // Spray only between -5 and +5 m: the unsprayed rows outside are before the first
    // and after the last sprayed row, not gaps.
    const auto p = profile([](int i) { return i >= 100 && i < 200 ? kNominal : 0.0; },
                           [](int i) { return i >= 200 && i < 300 ? kNominal : 0.0; });
    const auto result = rig::harness::deposition_metrics(p, judging(), 0.0);
    EXPECT_EQ(at(result.metrics, "missed_m"), 0.0);
}

TEST(DepositionMetrics, RowBelowHalfTheNominalDoseCountsAsUnsprayed) {
    // One thin row (0.4 x nominal) in the first pass at -2 m, one at exactly half (sprayed).
    const auto p = profile(
        [](int i) {
            if (i == 160) return 0.4 * kNominal;
            if (i == 150) return 0.5 * kNominal;
            return i < 200 ? kNominal : 0.0;
        },
        [](int i) { return i >= 200 ? kNominal : 0.0; });
    const auto result = rig::harness::deposition_metrics(p, judging(), 0.0);
    EXPECT_NEAR(at(result.metrics, "missed_m"), 0.05, 1e-12);
    const AreaSpan* missed = find_area(result.areas, "missed");
    ASSERT_NE(missed, nullptr);
    EXPECT_NEAR(missed->from_along_m, -2.0, 1e-9);
    EXPECT_NEAR(missed->to_along_m, -1.95, 1e-9);
}

TEST(DepositionMetrics, ContinuationCvByHand) {
    // After the breakpoint the continuation alternates, per 0.3 m CV row (6 grid
    // rows), between 1.0 and 3.0 uL/cm^2: row sums 6 and 18, mean 12, S 6: CV 50 %.
    const auto p = profile([](int i) { return i < 200 ? kNominal : 0.0; },
                           [](int i) {
                               if (i < 200) return 0.0;
                               return ((i - 200) / 6) % 2 == 0 ? 1.0 : 3.0;
                           });
    const auto result = rig::harness::deposition_metrics(p, judging(), 0.0);
    EXPECT_NEAR(at(result.metrics, "cv_continuation_pct"), 50.0, 1e-9);
    EXPECT_NEAR(at(result.metrics, "cv_operational_pct"), 0.0, 1e-9);
}

TEST(DepositionMetrics, CvAreasStopWhereTheSprayingStops) {
    // The first pass starts 3 m before the breakpoint and the continuation stops
    // 2 m after it, both inside the 6 m windows: the areas end at the sprayed
    // rows, so the bare ground beyond does not count as uneven deposition.
    const auto p = profile([](int i) { return i >= 140 && i < 200 ? kNominal : 0.0; },
                           [](int i) { return i >= 200 && i < 240 ? kNominal : 0.0; });
    const auto result = rig::harness::deposition_metrics(p, judging(), 0.0);
    const AreaSpan* operational = find_area(result.areas, "operational");
    const AreaSpan* continuation = find_area(result.areas, "continuation");
    ASSERT_NE(operational, nullptr);
    ASSERT_NE(continuation, nullptr);
    EXPECT_NEAR(operational->from_along_m, -3.0, 1e-9);
    EXPECT_NEAR(continuation->to_along_m, 2.0, 1e-9);
    EXPECT_NEAR(at(result.metrics, "cv_operational_pct"), 0.0, 1e-9);
    EXPECT_NEAR(at(result.metrics, "cv_continuation_pct"), 0.0, 1e-9);
}

// ---------------------------------------------------------------- Eq. 10-12

TEST(CoefficientOfVariation, Eq10To12ByHand) {
    // mean 5, population deviation sqrt(32 / 8) = 2: CV 40 %.
    EXPECT_NEAR(rig::harness::coefficient_of_variation_pct({2, 4, 4, 4, 5, 5, 7, 9}), 40.0, 1e-12);
    // {1, 2, 3}: mean 2, S = sqrt(2 / 3): CV 40.82 %.
    EXPECT_NEAR(rig::harness::coefficient_of_variation_pct({1, 2, 3}), 100.0 * std::sqrt(2.0 / 3.0) / 2.0, 1e-12);
    EXPECT_EQ(rig::harness::coefficient_of_variation_pct({7.5}), 0.0);
    EXPECT_EQ(rig::harness::coefficient_of_variation_pct({3, 3, 3}), 0.0);
    EXPECT_TRUE(std::isnan(rig::harness::coefficient_of_variation_pct({})));
    EXPECT_TRUE(std::isnan(rig::harness::coefficient_of_variation_pct({0.0, 0.0})));
    // Scale-free: the same shape at any dose.
    EXPECT_NEAR(rig::harness::coefficient_of_variation_pct({20, 40, 40, 40, 50, 50, 70, 90}), 40.0, 1e-12);
}

TEST(CoefficientOfVariation, TableSixOperationalAreaAt3KmH) {
    // Table 6: mean 7538.37, S 398.93 -> CV 5.29 %. Two rows mean -+ S have exactly that mean and S.
    EXPECT_NEAR(rig::harness::coefficient_of_variation_pct({7538.37 - 398.93, 7538.37 + 398.93}), 5.29, 0.005);
}

}  // namespace
