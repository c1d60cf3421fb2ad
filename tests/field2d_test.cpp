// Seed 001's 2-D plant truth (emulators/field2d/): local frame, target-area
// polygons, the route with heading, Eq. 18's lift, nozzle positions, Table 3
// and the deposition grid. Known answers are worked out by hand beside each check.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "emulators/field2d/boom_lift.h"
#include "emulators/field2d/deposition_grid2d.h"
#include "emulators/field2d/local_frame.h"
#include "emulators/field2d/nozzle_flow_table.h"
#include "emulators/field2d/polygon.h"
#include "emulators/field2d/route2d.h"
#include "emulators/field2d/sprayer_kinematics.h"

namespace {

using namespace rig::field2d;

// Wuzhi county, Henan (seed 001 Sec. 5.1), about 35.1 N 113.3 E.
constexpr double kWuzhiLat = 35.1;
constexpr double kWuzhiLon = 113.3;

// Expects `fn` to throw E with a message containing every fragment.
template <class E, class Fn>
void expect_throw_with(Fn fn, const std::vector<std::string>& fragments) {
    try {
        fn();
        ADD_FAILURE() << "no exception";
    } catch (const E& error) {
        for (const std::string& f : fragments) EXPECT_NE(std::string(error.what()).find(f), std::string::npos) << error.what();
    }
}

TEST(LocalFrame, RoundTripsAndRejectsBadOrigins) {
    const LocalFrame frame(kWuzhiLat, kWuzhiLon, 90.0);
    const GeodeticPoint p = frame.to_geodetic({100.0, 50.0});
    const Vec2 back = frame.to_local(p);
    EXPECT_NEAR(back.east_m, 100.0, 1e-6);
    EXPECT_NEAR(back.north_m, 50.0, 1e-6);
    // 50 m north is 50 / 110 950 m per degree of latitude at 35 N, about 4.5e-4 deg.
    EXPECT_NEAR(p.lat_deg - kWuzhiLat, 50.0 / 110950.0, 2e-6);
    expect_throw_with<std::invalid_argument>([] { LocalFrame(95.0, 0.0); }, {"latitude"});
    expect_throw_with<std::invalid_argument>([] { LocalFrame(0.0, NAN); }, {"longitude"});
}

TEST(Polygon, PointInSquareEdgesAndCorners) {
    // 10 m square, given clockwise: stored counter-clockwise, area 100 m^2.
    const Polygon square({{0, 0}, {0, 10}, {10, 10}, {10, 0}}, "square");
    EXPECT_DOUBLE_EQ(square.area_m2(), 100.0);
    const auto& v = square.vertices();
    double twice_area = 0.0;
    for (std::size_t i = 0; i < v.size(); ++i) twice_area += cross(v[i], v[(i + 1) % v.size()]);
    EXPECT_GT(twice_area, 0.0);  // counter-clockwise
    EXPECT_TRUE(square.contains({5, 5}));
    EXPECT_FALSE(square.contains({11, 5}));
    EXPECT_FALSE(square.contains({5, -0.001}));
    EXPECT_TRUE(square.contains({10, 5}));   // on an edge: inside (closed set)
    EXPECT_TRUE(square.contains({0, 0}));    // a corner
    // Signed distance: -5 at the centre, +2 two metres east of the east edge,
    // 5 (a 3-4-5 triangle) from the corner (0, 0) to (-3, -4).
    EXPECT_DOUBLE_EQ(square.signed_distance_m({5, 5}), -5.0);
    EXPECT_DOUBLE_EQ(square.signed_distance_m({12, 5}), 2.0);
    EXPECT_DOUBLE_EQ(square.signed_distance_m({-3, -4}), 5.0);
}

TEST(Polygon, ConcaveAreaHasAHoleInItsNotch) {
    // An L: the 10 x 10 square without its north-east 5 x 5 quarter.
    const Polygon l_shape({{0, 0}, {10, 0}, {10, 5}, {5, 5}, {5, 10}, {0, 10}}, "L");
    EXPECT_DOUBLE_EQ(l_shape.area_m2(), 75.0);
    EXPECT_TRUE(l_shape.contains({2, 8}));
    EXPECT_TRUE(l_shape.contains({8, 2}));
    EXPECT_FALSE(l_shape.contains({8, 8}));
    // A ray from (1, 5) east passes through the vertex (5, 5): counted once.
    EXPECT_TRUE(l_shape.contains({1, 5}));
}

TEST(Polygon, DegenerateAreasAreRejectedByName) {
    expect_throw_with<std::invalid_argument>([] { Polygon({{0, 0}, {1, 0}}, "field A"); }, {"field A", "3 corners"});
    expect_throw_with<std::invalid_argument>([] { Polygon({{0, 0}, {1, 0}, {2, 0}, {3, 0}}, "line"); },
                                             {"line", "edges"});
    expect_throw_with<std::invalid_argument>([] { Polygon({{0, 0}, {5, 0}, {5, 0}, {0, 5}}, "twice"); },
                                             {"twice", "corners 1 and 2", "same point"});
    // Bow-tie: the four corners of a square in the wrong order.
    expect_throw_with<std::invalid_argument>([] { Polygon({{0, 0}, {10, 10}, {10, 0}, {0, 10}}, "bowtie"); },
                                             {"bowtie", "cross"});
    expect_throw_with<std::invalid_argument>([] { Polygon({{0, 0}, {NAN, 0}, {0, 1}}, "nan"); },
                                             {"nan", "corner 1", "not finite"});
    // A sliver: 10 m x 0.5 mm = 0.005 m^2 < 0.01 m^2 (the edges do not cross).
    expect_throw_with<std::invalid_argument>([] { Polygon({{0, 0}, {10, 0}, {10, 0.0005}, {0, 0.0005}}, "sliver"); },
                                             {"sliver"});
}

TEST(Polygon, FromFourRecordedCorners) {
    const LocalFrame frame(kWuzhiLat, kWuzhiLon, 90.0);
    // A 20 m x 10 m area recorded as lat/lon corners.
    std::vector<GeodeticPoint> corners;
    for (const Vec2 c : {Vec2{0, 0}, Vec2{20, 0}, Vec2{20, 10}, Vec2{0, 10}}) corners.push_back(frame.to_geodetic(c));
    const Polygon area = Polygon::from_geodetic(frame, corners, "plot");
    EXPECT_NEAR(area.area_m2(), 200.0, 1e-5);
    EXPECT_TRUE(area.contains({19.9, 9.9}));
    EXPECT_FALSE(area.contains({20.1, 5.0}));
    corners[2].lat_deg = 91.0;
    expect_throw_with<std::invalid_argument>([&] { Polygon::from_geodetic(frame, corners, "plot"); },
                                             {"plot", "corner 2", "latitude"});
}

TEST(Route2d, StraightTrapezoidFromRest) {
    // 10 m east at 1 m/s, a = 0.5: ramp 2 s over 1 m, cruise 8 m in 8 s, brake
    // 2 s over 1 m: 12 s in all.
    const Route2d route({{0, 0}, 90.0}, {StraightSegment{10.0, 1.0, 0.5, true}});
    EXPECT_DOUBLE_EQ(route.end_time_s(), 12.0);
    EXPECT_DOUBLE_EQ(route.total_distance_m(), 10.0);
    const VehiclePose2d ramp = route.state_at(1.0);  // a t^2 / 2 = 0.25 m
    EXPECT_NEAR(ramp.position.east_m, 0.25, 1e-12);
    EXPECT_EQ(ramp.position.north_m, 0.0);  // exactly: heading 90 has no north component
    EXPECT_DOUBLE_EQ(ramp.heading_deg, 90.0);
    EXPECT_DOUBLE_EQ(ramp.speed_m_s, 0.5);
    EXPECT_NEAR(route.state_at(6.0).position.east_m, 5.0, 1e-12);  // 1 + 4 s x 1 m/s
    const VehiclePose2d end = route.state_at(12.0);
    EXPECT_NEAR(end.position.east_m, 10.0, 1e-12);
    EXPECT_EQ(end.speed_m_s, 0.0);
    EXPECT_EQ(route.state_at(100.0).position, end.position);
    EXPECT_EQ(route.state_at(-1.0).position, (Vec2{0, 0}));
    // Inverse: 1 m at 2 s, 5 m at 6 s, 9.75 m at 11 s (1 m braking: 0.75 = t - t^2 / 4 at t = 1).
    EXPECT_NEAR(route.time_at_distance(1.0), 2.0, 1e-12);
    EXPECT_NEAR(route.time_at_distance(5.0), 6.0, 1e-12);
    EXPECT_NEAR(route.time_at_distance(9.75), 11.0, 1e-9);
    EXPECT_TRUE(std::isnan(route.time_at_distance(10.5)));
}

TEST(Route2d, QuarterTurnsRightAndLeft) {
    // Already at 1 m/s heading north; a quarter circle of radius 5 m to the
    // right (clockwise) ends 5 m east and 5 m north heading east; halfway
    // (45 deg) at (5 - 5 cos 45, 5 sin 45) = (1.464466, 3.535534). Yaw rate
    // v / R = 0.2 rad/s = 11.459156 deg/s.
    const Route2d right({{0, 0}, 0.0, 1.0},
                        {TurnSegment{5.0, 90.0, 1.0}, StraightSegment{5.0, 1.0, 0.5, true}});
    const double quarter_s = 5.0 * M_PI / 2.0;
    const VehiclePose2d half = right.state_at(quarter_s / 2.0);
    EXPECT_NEAR(half.position.east_m, 5.0 - 5.0 * std::cos(M_PI / 4.0), 1e-9);
    EXPECT_NEAR(half.position.north_m, 5.0 * std::sin(M_PI / 4.0), 1e-9);
    EXPECT_NEAR(half.heading_deg, 45.0, 1e-9);
    EXPECT_NEAR(half.yaw_rate_deg_s, 11.459156, 1e-6);
    const VehiclePose2d out = right.state_at(quarter_s);
    EXPECT_NEAR(out.position.east_m, 5.0, 1e-9);
    EXPECT_NEAR(out.position.north_m, 5.0, 1e-9);
    EXPECT_NEAR(out.heading_deg, 90.0, 1e-9);
    // Then 5 m east (with the brake): ends at (10, 5).
    EXPECT_NEAR(right.state_at(1e3).position.east_m, 10.0, 1e-9);
    EXPECT_NEAR(right.state_at(1e3).position.north_m, 5.0, 1e-9);

    const Route2d left({{0, 0}, 0.0, 1.0}, {TurnSegment{5.0, -90.0, 1.0}, StraightSegment{5.0, 1.0, 0.5, true}});
    const VehiclePose2d left_out = left.state_at(quarter_s);
    EXPECT_NEAR(left_out.position.east_m, -5.0, 1e-9);
    EXPECT_NEAR(left_out.position.north_m, 5.0, 1e-9);
    EXPECT_NEAR(left_out.heading_deg, 270.0, 1e-9);
    EXPECT_LT(left.state_at(1.0).yaw_rate_deg_s, 0.0);
}

// Drive out across an edge, U-turn, drive back along it, stop.
Route2d headland_route() {
    return Route2d({{0, -10}, 0.0},
                   {StraightSegment{12.0, 1.5, 0.5}, TurnSegment{3.0, 180.0, 1.0, 0.5},
                    StraightSegment{8.0, 1.5, 0.5, true}, StandSegment{2.0}});
}

TEST(Route2d, ContinuousAndTheSameInAnyQueryOrder) {
    const Route2d route = headland_route();
    std::vector<double> times;
    for (double t = -1.0; t < route.end_time_s() + 1.0; t += 0.01) times.push_back(t);
    std::vector<VehiclePose2d> in_order;
    for (double t : times) in_order.push_back(route.state_at(t));
    // Backwards gives bit-identical states.
    for (std::size_t i = times.size(); i-- > 0;) {
        const VehiclePose2d p = route.state_at(times[i]);
        ASSERT_EQ(p.position, in_order[i].position);
        ASSERT_EQ(p.heading_deg, in_order[i].heading_deg);
        ASSERT_EQ(p.speed_m_s, in_order[i].speed_m_s);
    }
    // Moves no more than the top speed allows between samples, never faster than 1.5 m/s,
    // never accelerates beyond 0.5 m/s^2.
    for (std::size_t i = 1; i < in_order.size(); ++i) {
        const double step = norm(in_order[i].position - in_order[i - 1].position);
        ASSERT_LE(step, 1.5 * 0.01 + 1e-9) << "at t = " << times[i];
        ASSERT_LE(in_order[i].speed_m_s, 1.5 + 1e-12);
        ASSERT_LE(std::abs(in_order[i].speed_m_s - in_order[i - 1].speed_m_s), 0.5 * 0.01 + 1e-9);
    }
    // After the U-turn it heads south, 6 m east of the way out.
    const VehiclePose2d end = route.state_at(route.end_time_s());
    EXPECT_NEAR(end.heading_deg, 180.0, 1e-9);
    EXPECT_NEAR(end.position.east_m, 6.0, 1e-9);
    EXPECT_NEAR(end.position.north_m, -6.0, 1e-9);  // 12 m north, then 8 m south
}

TEST(Route2d, BadRoutesAreRejectedNamingTheSegment) {
    const RouteStart start{{0, 0}, 0.0};
    expect_throw_with<std::invalid_argument>(
        [&] { Route2d(start, {StraightSegment{5.0, 1.0}, StandSegment{1.0}}); }, {"segment 1", "at rest"});
    // From 1.5 m/s at 0.5 m/s^2 the vehicle needs 2.25 m to stop.
    expect_throw_with<std::invalid_argument>(
        [&] { Route2d(start, {StraightSegment{5.0, 1.5, 0.5}, StraightSegment{2.0, 1.5, 0.5, true}}); },
        {"segment 1", "cannot stop", "2.25"});
    expect_throw_with<std::invalid_argument>([&] { Route2d(start, {TurnSegment{5.0, 0.0, 1.0, 0.5, true}}); },
                                             {"segment 0", "angle"});
    expect_throw_with<std::invalid_argument>([&] { Route2d(start, {StraightSegment{-1.0, 1.0, 0.5, true}}); },
                                             {"segment 0", "length_m"});
    expect_throw_with<std::invalid_argument>([&] { Route2d(start, {StraightSegment{5.0, 1.0}}); }, {"end at rest"});
    expect_throw_with<std::invalid_argument>([&] { Route2d(start, {StraightSegment{5.0, 0.0, 0.5, true}}); },
                                             {"speed_m_s"});
}

TEST(BoomLift, Eq18AtKnownHeights) {
    const ParallelogramLift lift;  // I 0.5, Hp 0.8, M 0.3, L 0.9 (assumed)
    // H = 0.5: sqrt(0.25 - 0.09) - (0.3 - 0.9) = 0.4 + 0.6 = 1.0 m.
    EXPECT_NEAR(eq18_boom_offset_m(lift, 0.5), 1.0, 1e-12);
    // H = 0.4: sqrt(0.25 - 0.16) + 0.6 = 0.9 m; H = 0.6: sqrt(0.21) + 0.6 = 1.058258 m.
    EXPECT_NEAR(eq18_boom_offset_m(lift, 0.4), 0.9, 1e-12);
    EXPECT_NEAR(eq18_boom_offset_m(lift, 0.6), 1.058258, 1e-6);
    // Rods horizontal (H = Hp): the longest reach, 0.5 + 0.6 = 1.1 m.
    EXPECT_NEAR(eq18_boom_offset_m(lift, 0.8), 1.1, 1e-12);
    expect_throw_with<std::invalid_argument>([&] { eq18_boom_offset_m(lift, 0.2); }, {"Eq. 18", "0.2"});
}

TEST(BoomLift, HeightProfileInterpolates) {
    const BoomHeightProfile profile({{0.0, 0.5}, {10.0, 0.6}});
    EXPECT_DOUBLE_EQ(profile.height_at(-1.0), 0.5);
    EXPECT_NEAR(profile.height_at(5.0), 0.55, 1e-12);
    EXPECT_DOUBLE_EQ(profile.height_at(20.0), 0.6);
    expect_throw_with<std::invalid_argument>([] { BoomHeightProfile({{1.0, 0.5}, {1.0, 0.6}}); }, {"knot 1"});
    expect_throw_with<std::invalid_argument>([] { BoomHeightProfile(std::vector<HeightKnot>{}); }, {"at least one"});
}

TEST(SprayerKinematics, AntennaBoomAndNozzlesFacingEast) {
    const LocalFrame frame(kWuzhiLat, kWuzhiLon, 90.0);
    const Route2d route({{0, 0}, 90.0}, {StandSegment{1.0}});
    const SprayerKinematics k(frame, route, SprayerMounting{}, BoomHeightProfile{});
    const SprayerTruth t = k.truth_at(0.5);
    // Antenna 1.6 m ahead of the rear axle; boom centre Y1 = 1.0 m further (Eq. 18 at 0.5 m).
    EXPECT_NEAR(t.antenna.east_m, 1.6, 1e-12);
    EXPECT_NEAR(t.boom_centre.east_m, 2.6, 1e-12);
    EXPECT_DOUBLE_EQ(t.boom_offset_m, 1.0);
    ASSERT_EQ(t.nozzles.size(), 6u);
    // Facing east, left is north: nozzle 0 at 1.25 m north, nozzle 5 at 1.25 m south, 0.5 m apart.
    EXPECT_NEAR(t.nozzles[0].north_m, 1.25, 1e-12);
    EXPECT_NEAR(t.nozzles[5].north_m, -1.25, 1e-12);
    EXPECT_NEAR(t.nozzles[2].north_m - t.nozzles[3].north_m, 0.5, 1e-12);
    for (const Vec2& n : t.nozzles) EXPECT_NEAR(n.east_m, 2.6, 1e-12);
    // The antenna's WGS84 height: 1.7 m above the origin's tangent plane (+ 0.2 mm of Earth curvature at 1.6 m).
    EXPECT_NEAR(t.antenna_geodetic.height_m, 91.7, 1e-3);
}

TEST(SprayerKinematics, AntennaSlipsSidewaysInATurn) {
    const LocalFrame frame(kWuzhiLat, kWuzhiLon);
    // Right turn R = 5 m at 1 m/s: yaw 0.2 rad/s; the antenna 1.6 m ahead of the
    // axle moves 0.32 m/s to the right besides 1 m/s forward: speed 1.049952 m/s,
    // course over ground heading + atan(0.32) = heading + 17.744 deg.
    const Route2d route({{0, 0}, 0.0, 1.0}, {TurnSegment{5.0, 90.0, 1.0}, StraightSegment{5.0, 1.0, 0.5, true}});
    const SprayerKinematics k(frame, route, SprayerMounting{}, BoomHeightProfile{});
    const SprayerTruth t = k.truth_at(1.0);
    EXPECT_NEAR(norm(t.antenna_velocity_m_s), std::hypot(1.0, 0.32), 1e-9);
    EXPECT_NEAR(bearing_deg(t.antenna_velocity_m_s) - t.pose.heading_deg, std::atan(0.32) * 180.0 / M_PI, 1e-9);
}

TEST(SprayerKinematics, HeightsTheLiftCannotReachAreRejected) {
    const LocalFrame frame(kWuzhiLat, kWuzhiLon);
    const Route2d route({{0, 0}, 0.0}, {StandSegment{1.0}});
    expect_throw_with<std::invalid_argument>(
        [&] { SprayerKinematics(frame, route, SprayerMounting{}, BoomHeightProfile({{0.0, 0.5}, {1.0, 0.25}})); },
        {"0.25", "reach"});
    SprayerMounting bad;
    bad.nozzle_spacing_m = 0.0;
    expect_throw_with<std::invalid_argument>([&] { SprayerKinematics(frame, route, bad, BoomHeightProfile{}); },
                                             {"nozzle_spacing_m"});
}

TEST(NozzleFlowTable, Table3Interpolation) {
    const NozzleFlowTable t = NozzleFlowTable::paper_table3();
    ASSERT_EQ(t.nozzle_count(), 6);
    EXPECT_DOUBLE_EQ(t.flow_ml_min(0, 100.0), 610.0);
    EXPECT_DOUBLE_EQ(t.flow_ml_min(0, 30.0), 350.0);
    EXPECT_DOUBLE_EQ(t.flow_ml_min(0, 35.0), 370.0);   // (350 + 390) / 2
    EXPECT_DOUBLE_EQ(t.flow_ml_min(3, 95.0), 635.0);   // (640 + 630) / 2: Table 3 dips from 90 to 100 %
    EXPECT_DOUBLE_EQ(t.flow_ml_min(5, 55.0), 515.0);   // (490 + 540) / 2
    EXPECT_NEAR(t.flow_ml_min(2, 72.5), 550.0 + 0.25 * 30.0, 1e-12);
    // The table's mean row (Sec. 3.2.1): 614.17 at 100 %, 406.67 at 30 %.
    double sum100 = 0.0;
    double sum30 = 0.0;
    for (int n = 0; n < 6; ++n) {
        sum100 += t.flow_ml_min(n, 100.0);
        sum30 += t.flow_ml_min(n, 30.0);
    }
    EXPECT_NEAR(sum100 / 6.0, 614.17, 0.005);
    EXPECT_NEAR(sum30 / 6.0, 406.67, 0.005);
    expect_throw_with<std::out_of_range>([&] { t.flow_ml_min(1, 20.0); }, {"nozzle 1", "20", "[30"});
    expect_throw_with<std::out_of_range>([&] { t.flow_ml_min(6, 50.0); }, {"nozzle 6"});
}

TEST(NozzleFlowTable, BadTablesAreRejected) {
    expect_throw_with<std::invalid_argument>([] { NozzleFlowTable({}); }, {"no nozzles"});
    expect_throw_with<std::invalid_argument>([] { NozzleFlowTable({{{50, 400}}}); }, {"nozzle 0", "2 points"});
    expect_throw_with<std::invalid_argument>([] { NozzleFlowTable({{{50, 400}, {50, 410}}}); }, {"given twice"});
    expect_throw_with<std::invalid_argument>([] { NozzleFlowTable({{{0, 0}, {100, 600}}}); }, {"point 0", "duty"});
    expect_throw_with<std::invalid_argument>([] { NozzleFlowTable({{{50, 400}, {100, 600}}, {{50, -1}, {100, 600}}}); },
                                             {"nozzle 1", "point 0", "flow"});
}

TEST(DepositionGrid2d, FanFootprintWidthAtHalfAMetre) {
    // 2 H tan(55 deg) at H = 0.5 m: tan 55 deg = 1.428148, so 1.428148 m.
    EXPECT_NEAR(fan_width_m(0.5, 110.0), 1.428148, 1e-6);
    DepositionGrid2dParams params;
    params.east_min_m = -2.0;
    params.east_max_m = 2.0;
    params.north_min_m = -1.0;
    params.north_max_m = 1.0;
    params.cell_m = 0.02;
    DepositionGrid2d grid(params);
    // Heading north: the fan lies across, east-west.
    grid.deposit_band(2, {0.0, 0.0}, 0.0, fan_width_m(0.5, 110.0), 0.10, 1e-3);
    double west = 1e9;
    double east = -1e9;
    double south = 1e9;
    double north = -1e9;
    double litres = 0.0;
    for (std::size_t iy = 0; iy < grid.ny(); ++iy) {
        for (std::size_t ix = 0; ix < grid.nx(); ++ix) {
            const double dose = grid.dose_ul_cm2(2, ix, iy);
            if (dose <= 0.0) continue;
            const Vec2 c = grid.cell_centre(ix, iy);
            west = std::min(west, c.east_m - 0.01);
            east = std::max(east, c.east_m + 0.01);
            south = std::min(south, c.north_m - 0.01);
            north = std::max(north, c.north_m + 0.01);
            litres += dose * 4.0 /* cm^2 per cell */ * 1e-6;
        }
    }
    // Wet extent across within a cell of 1.428 m; along within a cell of 0.10 m.
    EXPECT_NEAR(east - west, 1.428148, 0.021);
    EXPECT_NEAR(north - south, 0.10, 0.021);
    EXPECT_NEAR(west, -0.714, 0.021);
    // Every drop is booked: the litres on the grid are what was sprayed.
    EXPECT_NEAR(litres, 1e-3, 1e-12);
    EXPECT_DOUBLE_EQ(grid.volume_off_grid_l(), 0.0);
    EXPECT_EQ(grid.dose_ul_cm2(1, 100, 50), 0.0);  // another nozzle's layer stays dry
    // Heading east: the same band now lies north-south, so half of it (beyond +-1 m north) is off this grid.
    grid.deposit_band(0, {0.0, 0.0}, 90.0, 2.0 * 1.428148, 0.10, 1e-3);
    EXPECT_NEAR(grid.volume_off_grid_l(), 1e-3 * (2.856296 - 2.0) / 2.856296, 2e-5);
}

TEST(DepositionGrid2d, BadGridsAreRejected) {
    DepositionGrid2dParams p;
    p.cell_m = 0.0;
    expect_throw_with<std::invalid_argument>([&] { DepositionGrid2d{p}; }, {"cell_m"});
    p = DepositionGrid2dParams{};
    p.east_max_m = p.east_min_m;
    expect_throw_with<std::invalid_argument>([&] { DepositionGrid2d{p}; }, {"east_min_m"});
    p = DepositionGrid2dParams{};
    p.cell_m = 0.001;  // 20 000 x 20 000 cells x 6 nozzles
    expect_throw_with<std::invalid_argument>([&] { DepositionGrid2d{p}; }, {"max_cells_total"});
    DepositionGrid2d grid{DepositionGrid2dParams{}};
    expect_throw_with<std::invalid_argument>([&] { grid.deposit_band(6, {0, 0}, 0, 1, 0.1, 1e-3); }, {"nozzle 6"});
}

}  // namespace
