// The land wheel's slip/terrain error model and the seeded random streams under it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "emulators/land_wheel.h"
#include "emulators/seeded_random.h"

namespace {

using namespace rig::emulators;

TEST(SeededRandom, SameSeedAndStreamGiveTheSameSequence) {
    SeededRandom first(7, "gnss_g970");
    SeededRandom second(7, "gnss_g970");
    for (int i = 0; i < 1000; ++i) {
        ASSERT_EQ(first.next_u64(), second.next_u64());
        ASSERT_EQ(first.gaussian(), second.gaussian());  // bit-identical, not just close
        ASSERT_EQ(first.uniform01(), second.uniform01());
    }
}

TEST(SeededRandom, StreamsAndSeedsAreIndependent) {
    SeededRandom gnss(7, "gnss_g970");
    SeededRandom wheel(7, "land_wheel.slip");
    SeededRandom other_seed(8, "gnss_g970");
    int equal_to_wheel = 0;
    int equal_to_other_seed = 0;
    for (int i = 0; i < 1000; ++i) {
        const std::uint64_t value = gnss.next_u64();
        equal_to_wheel += value == wheel.next_u64();
        equal_to_other_seed += value == other_seed.next_u64();
    }
    EXPECT_EQ(equal_to_wheel, 0);
    EXPECT_EQ(equal_to_other_seed, 0);
}

TEST(SeededRandom, Fnv1aMatchesTheReferenceVectors) {
    // From the FNV reference (isthe.com/chongo/tech/comp/fnv): FNV-1a 64 of "" and "a".
    EXPECT_EQ(fnv1a_64(""), 0xcbf29ce484222325ULL);
    EXPECT_EQ(fnv1a_64("a"), 0xaf63dc4c8601ec8cULL);
    EXPECT_EQ(fnv1a_64("foobar"), 0x85944171f73967e8ULL);
}

TEST(SeededRandom, UniformAndGaussianMomentsAreSane) {
    // 1e5 samples: the standard error of a mean of N(0,1) is 0.0032, of a sd ~0.0022;
    // the bounds are about 5 standard errors, loose enough never to flake.
    SeededRandom random(20231215, "moments");
    constexpr int kSamples = 100000;
    double sum = 0.0;
    double sum_squares = 0.0;
    double uniform_sum = 0.0;
    double uniform_min = 1.0;
    double uniform_max = 0.0;
    int beyond_three_sigma = 0;
    for (int i = 0; i < kSamples; ++i) {
        const double value = random.gaussian();
        ASSERT_TRUE(std::isfinite(value));
        sum += value;
        sum_squares += value * value;
        beyond_three_sigma += std::abs(value) > 3.0;
        const double uniform = random.uniform01();
        ASSERT_GE(uniform, 0.0);
        ASSERT_LT(uniform, 1.0);
        uniform_sum += uniform;
        uniform_min = std::min(uniform_min, uniform);
        uniform_max = std::max(uniform_max, uniform);
    }
    const double mean = sum / kSamples;
    const double sd = std::sqrt(sum_squares / kSamples - mean * mean);
    EXPECT_NEAR(mean, 0.0, 0.016);
    EXPECT_NEAR(sd, 1.0, 0.011);
    // P(|z| > 3) = 0.27 %: 270 expected, sd ~16.
    EXPECT_GT(beyond_three_sigma, 190);
    EXPECT_LT(beyond_three_sigma, 350);
    // Uniform mean 0.5, sd of the mean 0.29 / sqrt(1e5) = 0.0009.
    EXPECT_NEAR(uniform_sum / kSamples, 0.5, 0.005);
    EXPECT_LT(uniform_min, 1e-3);
    EXPECT_GT(uniform_max, 1.0 - 1e-3);
}

TEST(LandWheel, IsAPureFunctionOfSeedAndDistance) {
    const LandWheelParams params{1.5, 0.5, 0.005, 1000.0};
    const LandWheel first(params, 3);
    const LandWheel second(params, 3);
    const LandWheel other_seed(params, 4);
    // Query order and repetition do not matter: compare a forward and a backward sweep.
    constexpr int kPoints = 300;
    constexpr double kStep_m = 0.37;
    std::vector<double> forward;
    for (int i = 0; i < kPoints; ++i) forward.push_back(first.wheel_travel_m(kStep_m * i));
    for (int i = kPoints - 1; i >= 0; --i) {
        ASSERT_EQ(second.wheel_travel_m(kStep_m * i), forward[static_cast<std::size_t>(i)]) << i;
        ASSERT_EQ(first.wheel_travel_m(kStep_m * i), forward[static_cast<std::size_t>(i)]) << i;
    }
    EXPECT_EQ(first.slip_fraction(), second.slip_fraction());
    EXPECT_NE(first.slip_fraction(), other_seed.slip_fraction());
    EXPECT_NE(first.wheel_travel_m(50.0), other_seed.wheel_travel_m(50.0));
    EXPECT_EQ(first.wheel_travel_m(0.0), 0.0);
}

TEST(LandWheel, IdealWheelWithoutSlipOrTerrain) {
    const LandWheel ideal(LandWheelParams{0.0, 0.0, 0.0, 100.0}, 1);
    for (const double d : {0.0, 0.4, 1.0, 17.25, 100.0}) EXPECT_NEAR(ideal.wheel_travel_m(d), d, 1e-12);
    // Pure slip: 2 % slip rolls 98 m per 100 m.
    const LandWheel slipping(LandWheelParams{2.0, 0.0, 0.0, 100.0}, 1);
    EXPECT_NEAR(slipping.wheel_travel_m(100.0), 98.0, 1e-9);
    EXPECT_NEAR(slipping.error_m(50.0), -1.0, 1e-9);
}

TEST(LandWheel, NeverRollsBackwardsWhileTheVehicleDrivesForwards) {
    // Default terrain, plus an extreme case where the clamp must act: a terrain
    // sigma comparable to the cell length would otherwise make the wheel run back.
    for (const LandWheelParams params :
         {LandWheelParams{}, LandWheelParams{3.0, 2.0, 0.005, 500.0}, LandWheelParams{0.0, 0.0, 1.5, 500.0}}) {
        for (std::uint64_t seed = 1; seed <= 5; ++seed) {
            const LandWheel wheel(params, seed);
            double previous_m = wheel.wheel_travel_m(0.0);
            for (double d = 0.01; d <= 500.0; d += 0.01) {
                const double travel_m = wheel.wheel_travel_m(d);
                ASSERT_GE(travel_m, previous_m) << "seed " << seed << " at " << d << " m";
                previous_m = travel_m;
            }
        }
    }
}

TEST(LandWheel, ErrorGrowsWithDistance) {
    // Over 400 seeds (runs), the mean |odometer error| after 50 m must exceed the
    // one after 5 m, for the terrain walk alone (spread ~ sigma sqrt(d): 1.1 cm vs
    // 3.5 cm) and with a random slip (spread ~ d: 5 cm vs 50 cm at 1 % sd).
    for (const LandWheelParams params :
         {LandWheelParams{0.0, 0.0, 0.005, 100.0}, LandWheelParams{0.0, 1.0, 0.005, 100.0}}) {
        double sum_at_5_m = 0.0;
        double sum_at_50_m = 0.0;
        constexpr int kRuns = 400;
        for (int seed = 1; seed <= kRuns; ++seed) {
            const LandWheel wheel(params, static_cast<std::uint64_t>(seed));
            sum_at_5_m += std::abs(wheel.error_m(5.0));
            sum_at_50_m += std::abs(wheel.error_m(50.0));
        }
        const double mean_at_5_m = sum_at_5_m / kRuns;
        const double mean_at_50_m = sum_at_50_m / kRuns;
        std::printf("slip sd %.1f %%, terrain %.3f m/sqrt(m): mean |error| %.4f m at 5 m, %.4f m at 50 m\n",
                    params.slip_sd_pct, params.terrain_sd_m_per_sqrt_m, mean_at_5_m, mean_at_50_m);
        EXPECT_GT(mean_at_50_m, 2.0 * mean_at_5_m);
    }
}

TEST(LandWheel, TerrainSpreadFollowsTheRandomWalk) {
    // Terrain only: error(d) ~ N(0, sigma^2 d) at grid nodes. Over 2000 runs the
    // sample sd at 25 m should be 0.005 x 5 = 0.025 m (standard error ~1.6 %).
    constexpr int kRuns = 2000;
    double sum_squares = 0.0;
    for (int seed = 1; seed <= kRuns; ++seed) {
        const LandWheel wheel(LandWheelParams{0.0, 0.0, 0.005, 30.0}, static_cast<std::uint64_t>(seed));
        sum_squares += wheel.error_m(25.0) * wheel.error_m(25.0);
    }
    EXPECT_NEAR(std::sqrt(sum_squares / kRuns), 0.025, 0.025 * 0.08);
}

TEST(LandWheel, SlipIsDrawnAroundTheMean) {
    constexpr int kRuns = 2000;
    double sum = 0.0;
    double sum_squares = 0.0;
    for (int seed = 1; seed <= kRuns; ++seed) {
        const LandWheel wheel(LandWheelParams{1.5, 0.5, 0.0, 10.0}, static_cast<std::uint64_t>(seed));
        sum += wheel.slip_fraction();
        sum_squares += wheel.slip_fraction() * wheel.slip_fraction();
    }
    const double mean = sum / kRuns;
    EXPECT_NEAR(mean, 0.015, 0.0005);
    EXPECT_NEAR(std::sqrt(sum_squares / kRuns - mean * mean), 0.005, 0.0005);
}

TEST(LandWheel, RejectsBadParametersAndDistances) {
    EXPECT_THROW(LandWheel(LandWheelParams{0.0, -1.0, 0.005, 100.0}, 1), std::invalid_argument);
    EXPECT_THROW(LandWheel(LandWheelParams{0.0, 0.0, -0.1, 100.0}, 1), std::invalid_argument);
    EXPECT_THROW(LandWheel(LandWheelParams{0.0, 0.0, 0.005, 0.0}, 1), std::invalid_argument);
    const LandWheel wheel(LandWheelParams{0.0, 0.0, 0.005, 100.5}, 1);
    EXPECT_NO_THROW(wheel.wheel_travel_m(100.5));
    EXPECT_THROW(wheel.wheel_travel_m(100.6), std::out_of_range);
    EXPECT_THROW(wheel.wheel_travel_m(-0.1), std::out_of_range);
    EXPECT_THROW(wheel.wheel_travel_m(std::nan("")), std::out_of_range);
}

}  // namespace
