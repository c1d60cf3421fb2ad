// Autosteer in the plant (emulators/guidance/, docs/guidance.md) against
// hand-computed cases: the tilted antenna's geometry, pure pursuit's angle, the
// actuator's lag and limits, the linearised pure-pursuit response to an offset
// start, the seeded ground's determinism and size, and both plants with
// guidance off (the route exactly) and on.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "emulators/field2d/sprayer_kinematics.h"
#include "emulators/guidance/ground_roughness.h"
#include "emulators/guidance/guided_path.h"
#include "emulators/plant.h"
#include "harness/judge/guidance_metrics.h"

namespace {

using namespace rig::emulators::guidance;
using rig::field2d::Vec2;

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

// A straight route due north from the origin.
PathPose north_line(double distance_m) { return PathPose{Vec2{0.0, distance_m}, 0.0}; }

// No ground, no lag, no rate limit to speak of: the loop's bare geometry.
GuidanceParams smooth_ground() {
    GuidanceParams p;
    p.roll_sd_deg = 0.0;
    p.pitch_sd_deg = 0.0;
    p.yaw_disturbance_sd_deg_m = 0.0;
    return p;
}

TEST(Guidance, TheAntennaOnATiltedBodyIsWhereTheRotationsPutIt) {
    // 1.7 m up, 10 deg roll (right side down): 1.7 sin 10 = 0.29520 m right, 1.7 cos 10 = 1.67417 m up.
    const BodyPoint rolled = tilted(BodyPoint{0.0, 0.0, 1.7}, 10.0, 0.0);
    EXPECT_NEAR(rolled.right_m, 0.295202, 1e-6);
    EXPECT_NEAR(rolled.forward_m, 0.0, 1e-12);
    EXPECT_NEAR(rolled.up_m, 1.674173, 1e-6);
    // Then 5 deg nose up: the top goes back 1.67417 sin 5 = 0.14591 m, stays 1.67417 cos 5 = 1.66780 m up.
    const BodyPoint both = tilted(BodyPoint{0.0, 0.0, 1.7}, 10.0, 5.0);
    EXPECT_NEAR(both.right_m, 0.295202, 1e-6);
    EXPECT_NEAR(both.forward_m, -0.145914, 1e-6);
    EXPECT_NEAR(both.up_m, 1.667802, 1e-6);
    // A point 1.6 m ahead rises 1.6 sin 5 = 0.13945 m nose up; a point 1 m right drops 1 m at 90 deg roll.
    EXPECT_NEAR(tilted(BodyPoint{0.0, 1.6, 0.0}, 0.0, 5.0).up_m, 0.139449, 1e-6);
    EXPECT_NEAR(tilted(BodyPoint{1.0, 0.0, 0.0}, 90.0, 0.0).up_m, -1.0, 1e-12);
    // Level: unchanged.
    const BodyPoint level = tilted(BodyPoint{0.3, 1.6, 1.7}, 0.0, 0.0);
    EXPECT_EQ(level.right_m, 0.3);
    EXPECT_EQ(level.forward_m, 1.6);
    EXPECT_EQ(level.up_m, 1.7);
}

TEST(Guidance, PurePursuitSteersOntoTheArcThroughTheTarget) {
    // Straight ahead: no steering.
    EXPECT_EQ(pure_pursuit_steer_rad(Vec2{0, 0}, 0.0, Vec2{0, 2}, 1.8), 0.0);
    // 45 deg right at sqrt 2 m: curvature 2 sin 45 / sqrt 2 = 1 /m, delta = atan(1.8 x 1).
    EXPECT_NEAR(pure_pursuit_steer_rad(Vec2{0, 0}, 0.0, Vec2{1, 1}, 1.8), std::atan(1.8), 1e-12);
    // Mirrored: left, negative.
    EXPECT_NEAR(pure_pursuit_steer_rad(Vec2{0, 0}, 0.0, Vec2{-1, 1}, 1.8), -std::atan(1.8), 1e-12);
    // Heading east, a target 2 m east and 1 m south: alpha = atan2(1, 2) to the right, l_d = sqrt 5.
    EXPECT_NEAR(pure_pursuit_steer_rad(Vec2{0, 0}, 90.0, Vec2{2, -1}, 2.0),
                std::atan(2.0 * 2.0 * std::sin(std::atan2(1.0, 2.0)) / std::sqrt(5.0)), 1e-12);
    // The target under the axle: nothing to steer for.
    EXPECT_EQ(pure_pursuit_steer_rad(Vec2{1, 1}, 0.0, Vec2{1, 1}, 1.8), 0.0);
}

TEST(Guidance, TheActuatorLagsAndKeepsToItsRateAndAngle) {
    GuidanceParams p;
    p.steer_time_constant_s = 0.0;
    p.steer_rate_max_deg_s = 10.0;
    // No lag: the rate limit alone, 10 deg/s x 0.01 s = 0.1 deg a step.
    EXPECT_NEAR(steer_actuator_step(0.0, 30.0 * kRadPerDeg, 0.01, p), 0.1 * kRadPerDeg, 1e-15);
    EXPECT_NEAR(steer_actuator_step(0.0, -30.0 * kRadPerDeg, 0.01, p), -0.1 * kRadPerDeg, 1e-15);
    // A gap smaller than a step closes at once.
    EXPECT_NEAR(steer_actuator_step(0.0, 0.05 * kRadPerDeg, 0.01, p), 0.05 * kRadPerDeg, 1e-15);
    // Lag: 0.2 s closes 1 - exp(-0.01 / 0.2) of a 1 deg gap per step when the rate allows.
    p.steer_time_constant_s = 0.2;
    p.steer_rate_max_deg_s = 360.0;
    EXPECT_NEAR(steer_actuator_step(0.0, 1.0 * kRadPerDeg, 0.01, p), (1.0 - std::exp(-0.05)) * kRadPerDeg, 1e-15);
    // The angle limit holds the command and the wheel: 35 deg.
    double angle = 0.0;
    for (int i = 0; i < 1000; ++i) angle = steer_actuator_step(angle, 80.0 * kRadPerDeg, 0.01, p);
    EXPECT_NEAR(angle, 35.0 * kRadPerDeg, 1e-12);
}

TEST(Guidance, AnOffsetStartConvergesAsLinearisedPurePursuitPredicts) {
    // Linearised, pure pursuit with a fixed look-ahead Ld and no lag is
    //   e'' + (2 v / Ld) e' + (2 v^2 / Ld^2) e = 0,
    // damping ratio 1 / sqrt 2, e(t) = e0 exp(-v t / Ld) (cos(v t / Ld) + sin(v t / Ld)).
    // At v = 1 m/s, Ld = 2 m, e0 = 0.1 m: e(2 s) = 50.83 mm, e(4 s) = 6.68 mm,
    // the overshoot's peak at t = 2 pi = 6.28 s, -0.1 exp(-pi) = -4.32 mm.
    // A smooth ground, a fixed look-ahead, no lag and no rate limit to speak of.
    const GuidanceParams p{.lookahead_min_m = 2.0, .lookahead_time_s = 0.0, .steer_time_constant_s = 0.0,
                           .steer_rate_max_deg_s = 360.0, .roll_sd_deg = 0.0, .pitch_sd_deg = 0.0,
                           .yaw_disturbance_sd_deg_m = 0.0, .start_cross_track_m = 0.1};
    const GuidedPath path(p, north_line, [](double) { return 1.0; }, 0.0, 20.0, 0.0, BodyPoint{}, 1);
    const auto expected = [](double t) { return 0.1 * std::exp(-t / 2.0) * (std::cos(t / 2.0) + std::sin(t / 2.0)); };
    EXPECT_NEAR(path.state_at(0.0).cross_track_m, 0.1, 1e-12);
    // Within 0.2 mm: the linearisation drops terms of order e0^3 / Ld^2, the 10 ms steps add a little.
    EXPECT_NEAR(path.state_at(2.0).cross_track_m, expected(2.0), 2e-4);
    EXPECT_NEAR(path.state_at(4.0).cross_track_m, expected(4.0), 2e-4);
    EXPECT_NEAR(path.state_at(2.0 * std::numbers::pi).cross_track_m, expected(2.0 * std::numbers::pi), 2e-4);
    EXPECT_LT(std::abs(path.state_at(20.0).cross_track_m), 1e-4);
    // Driven north the whole time: the odometer is v t.
    EXPECT_NEAR(path.state_at(20.0).distance_m, 20.0, 1e-9);
}

TEST(Guidance, ALargeOffsetSteersNoFasterThanTheActuatorMoves) {
    GuidanceParams p = smooth_ground();
    p.start_cross_track_m = 2.0;
    p.steer_rate_max_deg_s = 20.0;
    const GuidedPath path(p, north_line, [](double) { return 1.5; }, 0.0, 30.0, 0.0, BodyPoint{}, 1);
    double previous = path.state_at(0.0).steer_deg;
    double largest_step = 0.0;
    double largest_angle = 0.0;
    for (int k = 1; k <= 3000; ++k) {
        const double steer = path.state_at(0.01 * k).steer_deg;
        largest_step = std::max(largest_step, std::abs(steer - previous));
        largest_angle = std::max(largest_angle, std::abs(steer));
        previous = steer;
    }
    EXPECT_LE(largest_step, 20.0 * 0.01 + 1e-9);
    // It did have to steer hard (the limit mattered), and it arrived.
    EXPECT_GT(largest_step, 20.0 * 0.01 * 0.99);
    EXPECT_LE(largest_angle, p.steer_angle_max_deg + 1e-9);
    EXPECT_LT(std::abs(path.state_at(30.0).cross_track_m), 0.01);
}

TEST(Guidance, TheGroundIsTheSameForTheSameSeedAndItsSizeIsAsAsked) {
    CorrelatedProfile a(1.0, 2.0, 7, "guidance.roll");
    CorrelatedProfile b(1.0, 2.0, 7, "guidance.roll");
    CorrelatedProfile other_seed(1.0, 2.0, 8, "guidance.roll");
    CorrelatedProfile other_stream(1.0, 2.0, 7, "guidance.pitch");
    // Asked in different orders, the same values, bit for bit.
    const double far = b.at(123.456);
    EXPECT_EQ(a.at(0.0), b.at(0.0));
    EXPECT_EQ(a.at(123.456), far);
    EXPECT_NE(a.at(50.0), other_seed.at(50.0));
    EXPECT_NE(a.at(50.0), other_stream.at(50.0));
    // Stationary SD 1 and correlation (1 + 1) exp(-1) = 0.736 one length (2 m) apart: over 20 km within a few per cent.
    double sum = 0.0;
    double sum_sq = 0.0;
    double lagged = 0.0;
    const int n = 400000;
    for (int i = 0; i < n; ++i) {
        const double x = a.at(0.05 * i);
        sum += x;
        sum_sq += x * x;
        if (i >= 40) lagged += x * a.at(0.05 * (i - 40));
    }
    const double variance = sum_sq / n - (sum / n) * (sum / n);
    EXPECT_NEAR(std::sqrt(variance), 1.0, 0.05);
    EXPECT_NEAR(lagged / (n - 40) / variance, 2.0 * std::exp(-1.0), 0.05);
    // Smooth: 5 cm apart, the values differ by a small fraction of the SD
    // (a first-order chain's would differ by sqrt(2 (1 - exp(-0.025))) = 0.22 SD).
    double step_sq = 0.0;
    for (int i = 1; i < n; ++i) step_sq += std::pow(a.at(0.05 * i) - a.at(0.05 * (i - 1)), 2);
    EXPECT_LT(std::sqrt(step_sq / (n - 1)), 0.05);
    EXPECT_THROW(CorrelatedProfile(-1.0, 2.0, 1, "x"), std::invalid_argument);
    EXPECT_THROW(CorrelatedProfile(1.0, 0.0, 1, "x"), std::invalid_argument);
}

TEST(Guidance, AGuidedRunIsAPureFunctionOfTheSeed) {
    const GuidanceParams p;
    const auto speed = [](double) { return 1.5; };
    const GuidedPath one(p, north_line, speed, 0.0, 20.0, 0.0, BodyPoint{0.0, 1.6, 1.7}, 5);
    const GuidedPath again(p, north_line, speed, 0.0, 20.0, 0.0, BodyPoint{0.0, 1.6, 1.7}, 5);
    const GuidedPath other(p, north_line, speed, 0.0, 20.0, 0.0, BodyPoint{0.0, 1.6, 1.7}, 6);
    bool differs = false;
    for (const double t : {0.0, 3.3, 7.77, 12.0, 19.99}) {
        const GuidedState a = one.state_at(t);
        const GuidedState b = again.state_at(t);
        EXPECT_EQ(a.position, b.position);
        EXPECT_EQ(a.heading_deg, b.heading_deg);
        EXPECT_EQ(a.antenna, b.antenna);
        EXPECT_EQ(a.roll_deg, b.roll_deg);
        differs = differs || other.state_at(t).position != a.position;
    }
    EXPECT_TRUE(differs);
    // The default ground moves the vehicle off the line by centimetres, not metres or nothing.
    double largest = 0.0;
    for (int k = 0; k <= 2000; ++k) largest = std::max(largest, std::abs(one.state_at(0.01 * k).cross_track_m));
    EXPECT_GT(largest, 0.002);
    EXPECT_LT(largest, 0.2);
}

TEST(Guidance, BadParametersAreRefusedByName) {
    GuidanceParams p;
    p.wheelbase_m = 0.0;
    try {
        validate(p);
        ADD_FAILURE() << "accepted";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("guidance.wheelbase_m"), std::string::npos) << error.what();
    }
    p = GuidanceParams{};
    p.terrain_compensation = 1.5;
    EXPECT_THROW(validate(p), std::invalid_argument);
    p = GuidanceParams{};
    p.step_s = std::nan("");
    EXPECT_THROW(GuidedPath(p, north_line, [](double) { return 1.0; }, 0.0, 1.0, 0.0, BodyPoint{}, 1),
                 std::invalid_argument);
    EXPECT_THROW(GuidedPath(GuidanceParams{}, north_line, [](double) { return 1.0; }, 0.0, 1e9, 0.0, BodyPoint{}, 1),
                 std::invalid_argument);
}

rig::field2d::SprayerKinematics seed001_sprayer(std::optional<GuidanceParams> guidance) {
    using namespace rig::field2d;
    Route2d route(RouteStart{Vec2{9.0, -18.0}, 0.0, 1.0},
                  {StraightSegment{13.0, 1.0, 0.5, false}, StraightSegment{1.0, 1.0, 0.5, true}});
    return SprayerKinematics(LocalFrame(35.1, 113.3, 90.0), route, SprayerMounting{}, BoomHeightProfile({{0.0, 0.5}}),
                             guidance, 1);
}

TEST(Guidance, Seed001WithoutGuidanceDrivesTheRouteAndWithASmoothGroundStaysOnIt) {
    const rig::field2d::SprayerKinematics exact = seed001_sprayer(std::nullopt);
    EXPECT_EQ(exact.guided(), nullptr);
    const rig::field2d::SprayerKinematics smooth = seed001_sprayer(smooth_ground());
    ASSERT_NE(smooth.guided(), nullptr);
    for (const double t : {0.0, 4.0, 9.5, 14.0}) {
        const rig::field2d::SprayerTruth a = exact.truth_at(t);
        EXPECT_EQ(a.pose.position, exact.route().state_at(t).position);
        // Guided over a smooth ground from on the line: nothing to correct (a
        // straight north line, so east stays exactly 9.0 and the heading 0).
        const rig::field2d::SprayerTruth b = smooth.truth_at(t);
        EXPECT_EQ(b.pose.position.east_m, 9.0);
        EXPECT_EQ(b.pose.heading_deg, 0.0);
        EXPECT_NEAR(b.pose.position.north_m, a.pose.position.north_m, 1e-9);
        EXPECT_NEAR(b.antenna.north_m, a.antenna.north_m, 1e-9);
        EXPECT_NEAR(b.antenna_geodetic.height_m, a.antenna_geodetic.height_m, 1e-9);
        for (std::size_t n = 0; n < a.nozzles.size(); ++n) EXPECT_NEAR(b.nozzles[n].east_m, a.nozzles[n].east_m, 1e-12);
    }
}

TEST(Guidance, Seed001NozzlesFollowTheGuidedBodysYaw) {
    GuidanceParams p = smooth_ground();
    p.start_heading_error_deg = 3.0;
    const rig::field2d::SprayerKinematics sprayer = seed001_sprayer(p);
    const rig::field2d::SprayerTruth at_start = sprayer.truth_at(0.0);
    EXPECT_NEAR(at_start.pose.heading_deg, 3.0, 1e-12);
    // The boom, Y1 + 1.6 m ahead of the axle, turns with the body: its nozzles
    // lie on the line through the boom centre at right angles to the heading.
    const Vec2 across = at_start.nozzles.back() - at_start.nozzles.front();
    EXPECT_NEAR(std::atan2(-across.north_m, across.east_m) / kRadPerDeg, 3.0, 1e-9);
}

rig::emulators::PlantParams seed000_plant(std::optional<GuidanceParams> guidance) {
    rig::emulators::PlantParams params;
    params.route = {rig::emulators::DrivePhase{20.0, 1.25, 0.5}, rig::emulators::RepositionPhase{10.0},
                    rig::emulators::DrivePhase{30.0, 1.25, 0.5}};
    params.guidance = guidance;
    return params;
}

TEST(Guidance, Seed000ComesBackToTheLineOffsetAfterEachHeadlandTurn) {
    const rig::emulators::Plant exact(seed000_plant(std::nullopt));
    GuidanceParams p = smooth_ground();
    p.start_cross_track_m = 0.05;
    p.start_heading_error_deg = 1.0;
    const rig::emulators::Plant guided(seed000_plant(p));
    const double turn_s = exact.vehicle().pass_start_s(1);
    for (const double t : {0.0, turn_s}) {
        const auto a = exact.truth_at(rig::seconds_to_ns(t));
        const auto b = guided.truth_at(rig::seconds_to_ns(t));
        EXPECT_EQ(a.cross_m(), 0.0);
        EXPECT_EQ(a.heading_deg(), 90.0);
        // The antenna (1 m ahead of the axle, 2.5 m up, level): 0.05 + sin(1 deg) m right.
        EXPECT_NEAR(b.cross_m(), 0.05 + std::sin(kRadPerDeg), 1e-9);
        EXPECT_NEAR(b.heading_deg(), 91.0, 1e-9);
        // Along: 1 m cos(1 deg) ahead of the axle instead of 1 m.
        EXPECT_NEAR(b.along_m(), a.along_m() + std::cos(kRadPerDeg) - 1.0, 1e-9);
    }
    // Steered back onto the line by the end of each pass.
    EXPECT_LT(std::abs(guided.truth_at(rig::seconds_to_ns(turn_s - 0.5)).cross_m()), 0.005);
    EXPECT_LT(std::abs(guided.truth_at(rig::seconds_to_ns(exact.vehicle().end_time_s())).cross_m()), 0.005);
}

TEST(Guidance, TheJudgeTakesTheErrorOverTheMovingSamples) {
    using rig::harness::GuidanceErrorSample;
    // Standing (0.05 m/s) is left out, however far off. The three are 50 ms
    // apart: the first stands for 25 ms, the second for 50 ms, so the RMS of 3
    // and -4 cm is sqrt((25 * 9 + 50 * 16) / 75) = 3.697 cm, the peak 4 cm.
    const rig::harness::MetricSet judged = rig::harness::guidance_metrics(
        {GuidanceErrorSample{0, 0.03, 1.0, 1.0}, GuidanceErrorSample{50'000'000, -0.04, -2.0, 1.5},
         GuidanceErrorSample{100'000'000, 1.0, 30.0, 0.05}},
        "axle");
    // Weights 25 and 50 ms: sqrt((25 * 9 + 50 * 16) / 75) cm, sqrt((25 * 1 + 50 * 4) / 75) deg.
    EXPECT_NEAR(judged.values.at("guidance_axle_cross_track_rms_m"), 0.01 * std::sqrt(1025.0 / 75.0), 1e-15);
    EXPECT_DOUBLE_EQ(judged.values.at("guidance_axle_cross_track_peak_m"), 0.04);
    EXPECT_NEAR(judged.values.at("guidance_heading_error_rms_deg"), std::sqrt(3.0), 1e-15);
    EXPECT_EQ(judged.values.at("guidance_moving_samples"), 2.0);
    // Never moving: not measured, saying why, rather than a zero error.
    const rig::harness::MetricSet standing =
        rig::harness::guidance_metrics({GuidanceErrorSample{0, 0.5, 3.0, 0.0}}, "antenna");
    EXPECT_EQ(standing.values.count("guidance_antenna_cross_track_rms_m"), 0u);
    EXPECT_NE(standing.not_measured.at("guidance_antenna_cross_track_rms_m").find("never moved"), std::string::npos);
}

// Seed 000's truth/vehicle is a 20 Hz grid plus a sample at every instant the
// controller published: a burst of those while the vehicle was off the line must
// not weigh more than the time it lasted, nor any other controller's timing.
TEST(Guidance, SamplesAtTheControllersInstantsWeighOnlyTheTimeTheyStandFor) {
    using rig::harness::GuidanceErrorSample;
    constexpr rig::TimeNs kGrid = 50'000'000;  // 20 Hz
    std::vector<GuidanceErrorSample> grid;
    for (int i = 0; i <= 40; ++i) {  // 2 s: 2 cm off for the first second, then on the line
        grid.push_back(GuidanceErrorSample{i * kGrid, i < 20 ? 0.02 : 0.0, 0.0, 1.0});
    }
    const rig::harness::MetricSet on_grid = rig::harness::guidance_metrics(grid, "antenna");
    // 2 cm over the first 0.975 s of 2 s (the sample at 0.95 s stands to 0.975 s):
    // sqrt(0.975 / 2) * 2 cm.
    EXPECT_NEAR(on_grid.values.at("guidance_antenna_cross_track_rms_m"), 0.02 * std::sqrt(0.975 / 2.0), 1e-12);
    // Ten samples more, 1 ms apart, 10 ms into the off-line second (a controller
    // publishing in a burst): one sample one vote would be 41 against 10 more.
    std::vector<GuidanceErrorSample> with_burst = grid;
    for (int k = 1; k <= 10; ++k) {
        with_burst.insert(with_burst.begin() + k, GuidanceErrorSample{k * 1'000'000, 0.02, 0.0, 1.0});
    }
    const rig::harness::MetricSet judged = rig::harness::guidance_metrics(with_burst, "antenna");
    EXPECT_NEAR(judged.values.at("guidance_antenna_cross_track_rms_m"),
                on_grid.values.at("guidance_antenna_cross_track_rms_m"), 1e-12);
    EXPECT_EQ(judged.values.at("guidance_moving_samples"), 51.0);
    // (Counted one a sample, the burst would have made it sqrt(30 / 51) * 2 cm =
    // 1.53 cm instead of sqrt(0.975 / 2) * 2 cm = 1.40 cm.)
}

}  // namespace
