// The rank statistics rig compare and rig history call shifts with
// (harness/regression/rank_statistics.h): the U test's exact distribution
// against enumeration of every arrangement, its normal approximation, the
// false-positive rate alpha promises on samples of no change, Holm's
// correction and the Hodges-Lehmann shift.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "harness/regression/rank_statistics.h"

namespace {

using rig::harness::hodges_lehmann;
using rig::harness::holm_adjusted;
using rig::harness::mann_whitney;
using rig::harness::normal_upper_quantile;
using rig::harness::normal_upper_tail;

TEST(MannWhitney, CompleteSeparationOfThreeAndThreeIsOneArrangementInTwenty) {
    const auto test = mann_whitney({1, 2, 3}, {4, 5, 6});
    EXPECT_TRUE(test.exact);
    EXPECT_DOUBLE_EQ(test.u, 9.0);
    EXPECT_NEAR(test.p_greater, 1.0 / 20.0, 1e-12);
    EXPECT_NEAR(test.p_less, 1.0, 1e-12);
    EXPECT_NEAR(test.p_two_sided, 0.1, 1e-12);
}

// Every way to place 4 base and 5 head values among 9 ranks, counted by U:
// the exact p-value must be the share of arrangements at least as extreme.
TEST(MannWhitney, ExactPValuesAreTheShareOfArrangementsAtLeastAsExtreme) {
    const int m = 4, n = 5;
    std::vector<int> counts(m * n + 1, 0);
    int arrangements = 0;
    for (int mask = 0; mask < (1 << (m + n)); ++mask) {
        if (__builtin_popcount(static_cast<unsigned>(mask)) != n) continue;  // bits set: head ranks
        int u = 0, base_below = 0;
        for (int rank = 0; rank < m + n; ++rank) {
            if (mask & (1 << rank)) {
                u += base_below;
            } else {
                ++base_below;
            }
        }
        ++counts[u];
        ++arrangements;
    }
    // base {1, 3, 6, 8} head {2, 4, 5, 7, 9}: head above base in 1+2+2+3+4 = 12 pairs
    const auto test = mann_whitney({1, 3, 6, 8}, {2, 4, 5, 7, 9});
    ASSERT_TRUE(test.exact);
    EXPECT_DOUBLE_EQ(test.u, 12.0);
    int at_or_above = 0, at_or_below = 0;
    for (int u = 0; u <= m * n; ++u) {
        if (u >= 12) at_or_above += counts[u];
        if (u <= 12) at_or_below += counts[u];
    }
    EXPECT_NEAR(test.p_greater, static_cast<double>(at_or_above) / arrangements, 1e-12);
    EXPECT_NEAR(test.p_less, static_cast<double>(at_or_below) / arrangements, 1e-12);
}

TEST(MannWhitney, TiesUseTheNormalApproximationAndAllTiedIsNoChange) {
    const auto tied = mann_whitney({0, 0, 0, 0}, {0, 0, 0, 0});
    EXPECT_FALSE(tied.exact);
    EXPECT_DOUBLE_EQ(tied.p_two_sided, 1.0);
    // A run that gave no value ranks as the worst: three of five lost is a move up.
    const double lost = std::numeric_limits<double>::infinity();
    const auto worse = mann_whitney({1, 2, 3, 4, 5, 6, 7, 8}, {lost, lost, lost, lost, lost, lost, lost, 8});
    EXPECT_FALSE(worse.exact);
    EXPECT_LT(worse.p_greater, 0.01);
    EXPECT_GT(worse.p_less, 0.5);
    EXPECT_THROW(mann_whitney({std::nan("")}, {1.0}), std::invalid_argument);
    EXPECT_DOUBLE_EQ(mann_whitney({}, {1.0}).p_two_sided, 1.0);
}

TEST(MannWhitney, NormalApproximationFollowsTheExactTailAtThirtyAndThirty) {
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::vector<double> base(30), head(30);
    for (double& value : base) value = uniform(random);
    for (double& value : head) value = uniform(random) + 0.2;
    const auto exact = mann_whitney(base, head);
    ASSERT_TRUE(exact.exact);
    // 60 values, one tie added forces the approximation with almost the same ranks.
    head.back() = base.front();
    const auto approximate = mann_whitney(base, head);
    ASSERT_FALSE(approximate.exact);
    EXPECT_NEAR(std::log10(approximate.p_greater), std::log10(exact.p_greater), 0.15);
}

// No change: two samples of one distribution. The share of comparisons
// called at alpha must be what alpha promises (at most, for a test whose
// exact distribution is discrete), at 10 and at 30 seeds a side.
TEST(MannWhitney, FalsePositiveRateOnNoChangeIsAtMostAlpha) {
    std::mt19937_64 random(2026);
    std::lognormal_distribution<double> skewed(0.0, 0.5);  // like an adjust time: skewed, positive
    for (std::size_t seeds : {10u, 30u}) {
        const int comparisons = 4000;
        int called = 0;
        for (int k = 0; k < comparisons; ++k) {
            std::vector<double> base(seeds), head(seeds);
            for (double& value : base) value = skewed(random);
            for (double& value : head) value = skewed(random);
            if (mann_whitney(base, head).p_two_sided < 0.01) ++called;
        }
        const double rate = static_cast<double>(called) / comparisons;
        // 0.01 plus three binomial standard deviations of 4000 draws.
        EXPECT_LE(rate, 0.01 + 3.0 * std::sqrt(0.01 * 0.99 / comparisons)) << seeds << " seeds";
        EXPECT_GT(called, 0) << "a test that never fires proves nothing about its rate";
    }
}

TEST(MannWhitney, AShiftOfOneSpreadIsFoundAtThirtySeeds) {
    std::mt19937_64 random(11);
    std::normal_distribution<double> noise(0.0, 1.0);
    int found = 0;
    for (int k = 0; k < 200; ++k) {
        std::vector<double> base(30), head(30);
        for (double& value : base) value = noise(random);
        for (double& value : head) value = noise(random) + 1.0;
        if (mann_whitney(base, head).p_greater < 0.01) ++found;
    }
    EXPECT_GT(found, 150);  // power about 0.9 for one SD at 30 a side
}

TEST(HodgesLehmann, ShiftIsTheMedianPairwiseDifferenceWithAnIntervalAroundIt) {
    const auto shift = hodges_lehmann({0, 0, 0}, {1, 2, 3}, 0.9);
    ASSERT_TRUE(shift.estimate);
    EXPECT_DOUBLE_EQ(*shift.estimate, 2.0);
    std::vector<double> base, head;
    for (int k = 0; k < 30; ++k) {
        base.push_back(k * 0.1);
        head.push_back(k * 0.1 + 0.5);
    }
    const auto wide = hodges_lehmann(base, head, 0.99);
    ASSERT_TRUE(wide.estimate && wide.low && wide.high);
    EXPECT_NEAR(*wide.estimate, 0.5, 1e-9);
    EXPECT_LT(*wide.low, 0.5);
    EXPECT_GT(*wide.high, 0.5);
    // Too few pairs for a 99 % interval: unbounded, never a made-up end.
    const auto small = hodges_lehmann({1.0}, {2.0}, 0.99);
    EXPECT_TRUE(small.estimate);
    EXPECT_FALSE(small.low);
    const double lost = std::numeric_limits<double>::infinity();
    EXPECT_FALSE(hodges_lehmann({lost}, {lost}, 0.99).estimate);
}

TEST(Holm, AdjustsStepDownAndKeepsTheOrder) {
    const auto adjusted = holm_adjusted({0.01, 0.04, 0.03, 0.005});
    ASSERT_EQ(adjusted.size(), 4u);
    EXPECT_NEAR(adjusted[0], 0.03, 1e-12);
    EXPECT_NEAR(adjusted[1], 0.06, 1e-12);
    EXPECT_NEAR(adjusted[2], 0.06, 1e-12);
    EXPECT_NEAR(adjusted[3], 0.02, 1e-12);
    EXPECT_TRUE(holm_adjusted({}).empty());
    EXPECT_DOUBLE_EQ(holm_adjusted({0.9, 0.8})[0], 1.0);
}

TEST(Normal, QuantileInvertsTheTail) {
    EXPECT_NEAR(normal_upper_quantile(0.025), 1.959964, 1e-6);
    EXPECT_NEAR(normal_upper_tail(normal_upper_quantile(0.005)), 0.005, 1e-12);
    EXPECT_THROW(normal_upper_quantile(0.0), std::invalid_argument);
}

}  // namespace
