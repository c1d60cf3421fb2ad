// The plant's vehicle (closed-form route on the A-B line) and the field frame
// that places it on the WGS84 ellipsoid.
#include <gtest/gtest.h>

#include <GeographicLib/Geodesic.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "emulators/field_frame.h"
#include "emulators/vehicle_plant.h"

namespace {

using namespace rig::emulators;

constexpr double kSixKmH_m_s = 6.0 / 3.6;

// Approach like the paper's field runs: 60 m run-up to the breakpoint at 6 km/h.
VehiclePlant approach_at_6_km_h() {
    return VehiclePlant({DrivePhase{0.0, kSixKmH_m_s, 0.5}}, BoomGeometry{}, -60.0);
}

TEST(VehiclePlant, TrapezoidProfileStopsExactlyOnTheTarget) {
    const VehiclePlant plant = approach_at_6_km_h();
    // v = 1.666667 m/s, a = 0.5 m/s^2: ramps of v/a = 3.333333 s over v^2/(2a) =
    // 2.777778 m each; cruise (60 - 5.555556) / 1.666667 = 32.666667 s;
    // total 3.333333 x 2 + 32.666667 = 39.333333 s.
    EXPECT_NEAR(plant.end_time_s(), 39.333333, 1e-6);
    const VehicleState end = plant.state_at(plant.end_time_s());
    EXPECT_EQ(end.nozzle_line_along_m, 0.0);  // exactly, not approximately
    EXPECT_EQ(end.speed_m_s, 0.0);
    EXPECT_EQ(plant.state_at(1000.0).nozzle_line_along_m, 0.0);
    EXPECT_NEAR(end.odometer_distance_m, 60.0, 1e-12);

    const VehicleState ramped = plant.state_at(10.0 / 3.0);
    EXPECT_NEAR(ramped.nozzle_line_along_m, -60.0 + 2.777778, 1e-6);
    EXPECT_NEAR(ramped.speed_m_s, kSixKmH_m_s, 1e-12);
    const VehicleState cruising = plant.state_at(20.0);
    EXPECT_NEAR(cruising.speed_m_s, kSixKmH_m_s, 1e-12);
    EXPECT_EQ(cruising.accel_m_s2, 0.0);
    EXPECT_EQ(plant.state_at(1.0).accel_m_s2, 0.5);
    EXPECT_EQ(plant.state_at(38.0).accel_m_s2, -0.5);
    // Before t = 0 it stands at the start.
    EXPECT_EQ(plant.state_at(-5.0).nozzle_line_along_m, -60.0);
    EXPECT_EQ(plant.state_at(-5.0).speed_m_s, 0.0);
}

TEST(VehiclePlant, TriangularProfileWhenTooShortToReachCruise) {
    // 2 m at a = 0.5 m/s^2 cannot reach 1.667 m/s (that needs v^2/a = 5.56 m):
    // peak sqrt(a L) = sqrt(0.5 x 2) = 1.0 m/s after 2 s and 1 m; stops at 4 s.
    const VehiclePlant plant({DrivePhase{2.0, kSixKmH_m_s, 0.5}}, BoomGeometry{}, 0.0);
    EXPECT_DOUBLE_EQ(plant.end_time_s(), 4.0);
    const VehicleState peak = plant.state_at(2.0);
    EXPECT_NEAR(peak.speed_m_s, 1.0, 1e-12);
    EXPECT_NEAR(peak.nozzle_line_along_m, 1.0, 1e-12);
    EXPECT_NEAR(plant.state_at(1.0).nozzle_line_along_m, 0.25, 1e-12);  // a t^2 / 2
    EXPECT_NEAR(plant.state_at(3.0).nozzle_line_along_m, 1.75, 1e-12);
    EXPECT_EQ(plant.state_at(4.0).nozzle_line_along_m, 2.0);
    EXPECT_EQ(plant.state_at(4.0).speed_m_s, 0.0);
}

// A route with every kind of phase: stand on the breakpoint (button press),
// jump back 60 m, approach at 6 km/h and overrun, turn, and a short second pass.
std::vector<RoutePhase> full_route() {
    return {StandPhase{1.5},
            RepositionPhase{-60.0},
            StandPhase{0.5},
            DrivePhase{5.0, kSixKmH_m_s, 0.5},
            RepositionPhase{-10.0},
            DrivePhase{-8.5, 3.0 / 3.6, 0.8},
            DrivePhase{5.0, 4.5 / 3.6, 0.3}};
}

TEST(VehiclePlant, PositionAndSpeedAreContinuousAndConsistent) {
    const VehiclePlant plant(full_route(), BoomGeometry{}, 0.0);
    const double dt_s = 1e-3;
    double max_accel_m_s2 = 0.8;
    double previous_odometer_m = 0.0;
    VehicleState previous = plant.state_at(0.0);
    int jumps = 0;
    for (double t_s = dt_s; t_s <= plant.end_time_s() + 1.0; t_s += dt_s) {
        const VehicleState state = plant.state_at(t_s);
        const double moved_m = state.nozzle_line_along_m - previous.nozzle_line_along_m;
        if (std::abs(moved_m) > 0.01) {
            ++jumps;  // a reposition: the headland turn the rig does not model
        } else {
            // Speed is the derivative of position: the trapezoid rule is exact to a dt^2.
            EXPECT_NEAR(moved_m, 0.5 * (state.speed_m_s + previous.speed_m_s) * dt_s, max_accel_m_s2 * dt_s * dt_s)
                << t_s;
            EXPECT_LE(std::abs(state.speed_m_s - previous.speed_m_s), max_accel_m_s2 * dt_s + 1e-12) << t_s;
        }
        EXPECT_GE(state.speed_m_s, 0.0);
        EXPECT_GE(state.odometer_distance_m, previous_odometer_m) << t_s;
        EXPECT_NEAR(state.antenna_along_m - state.nozzle_line_along_m, BoomGeometry{}.l4_m(), 1e-12);
        previous_odometer_m = state.odometer_distance_m;
        previous = state;
    }
    EXPECT_EQ(jumps, 2);
    // Odometer counts driving only: 65 + 1.5 + 13.5 m, not the repositions.
    EXPECT_NEAR(plant.state_at(plant.end_time_s()).odometer_distance_m, 80.0, 1e-9);
}

TEST(VehiclePlant, RepositionTakesEffectAtItsInstant) {
    const VehiclePlant plant(full_route(), BoomGeometry{}, 0.0);
    EXPECT_EQ(plant.state_at(1.4999).nozzle_line_along_m, 0.0);
    EXPECT_EQ(plant.state_at(1.5).nozzle_line_along_m, -60.0);
    EXPECT_EQ(plant.state_at(1.9).nozzle_line_along_m, -60.0);
    EXPECT_EQ(plant.state_at(1.5).odometer_distance_m, 0.0);
}

TEST(VehiclePlant, AntennaIsL4AheadOfTheNozzleLine) {
    // Eq. 6 with the paper's geometry: L4 = 1.628399 m (1.63 m at 0.5 m boom height).
    const BoomGeometry boom{};
    EXPECT_NEAR(boom.l4_m(), 1.628399, 1e-6);
    const VehiclePlant plant({StandPhase{1.0}}, boom, 12.0);
    EXPECT_NEAR(plant.state_at(0.5).antenna_along_m, 12.0 + 1.628399, 1e-6);
}

// Bisection on state_at: the first time in [low, high] with nozzle line >= along.
double bisect_reach(const VehiclePlant& plant, double along_m, double low_s, double high_s) {
    for (int i = 0; i < 200; ++i) {
        const double mid_s = 0.5 * (low_s + high_s);
        if (plant.state_at(mid_s).nozzle_line_along_m >= along_m) {
            high_s = mid_s;
        } else {
            low_s = mid_s;
        }
    }
    return high_s;
}

TEST(VehiclePlant, TimeWhenNozzleLineReachesIsExact) {
    const VehiclePlant plant = approach_at_6_km_h();
    // In the acceleration ramp, the cruise and the braking ramp, and the end point.
    for (const double along_m : {-60.0, -59.9, -58.0, -57.3, -30.0, -2.5, -1.0, -0.001, 0.0}) {
        const double exact_s = plant.time_when_nozzle_line_reaches(along_m);
        ASSERT_TRUE(std::isfinite(exact_s)) << along_m;
        EXPECT_NEAR(plant.state_at(exact_s).nozzle_line_along_m, along_m, 1e-9) << along_m;
        if (along_m > -60.0) {
            const double bisected_s = bisect_reach(plant, along_m, 0.0, plant.end_time_s());
            EXPECT_NEAR(exact_s, bisected_s, 1e-7) << along_m;
        } else {
            EXPECT_EQ(exact_s, 0.0);  // the drive starts there
        }
    }
    // Hand value: after the 2.777778 m ramp (3.333333 s), -30 m is 27.222222 m of
    // cruise at 1.666667 m/s = 16.333333 s later: t = 19.666667 s.
    EXPECT_NEAR(plant.time_when_nozzle_line_reaches(-30.0), 19.666667, 1e-6);
    EXPECT_TRUE(std::isnan(plant.time_when_nozzle_line_reaches(0.5)));    // never gets there
    EXPECT_TRUE(std::isnan(plant.time_when_nozzle_line_reaches(-61.0)));  // never there while driving
}

TEST(VehiclePlant, TimeWhenNozzleLineReachesHonoursAfter) {
    const VehiclePlant plant(full_route(), BoomGeometry{}, 0.0);
    // Standing on 0 at the start is not "reaching" it; the first pass is.
    const double first_pass_s = plant.time_when_nozzle_line_reaches(0.0);
    ASSERT_TRUE(std::isfinite(first_pass_s));
    EXPECT_GT(first_pass_s, 2.0);
    EXPECT_NEAR(plant.state_at(first_pass_s).nozzle_line_along_m, 0.0, 1e-9);
    // After the first pass, the second one (a later drive over the same spot).
    const double second_pass_s = plant.time_when_nozzle_line_reaches(0.0, first_pass_s + 1e-6);
    ASSERT_TRUE(std::isfinite(second_pass_s));
    EXPECT_GT(second_pass_s, first_pass_s + 10.0);
    EXPECT_NEAR(plant.state_at(second_pass_s).nozzle_line_along_m, 0.0, 1e-9);
    EXPECT_NEAR(second_pass_s, bisect_reach(plant, 0.0, first_pass_s + 5.0, plant.end_time_s()), 1e-7);
    // Asking exactly at a crossing returns that crossing.
    EXPECT_EQ(plant.time_when_nozzle_line_reaches(0.0, first_pass_s), first_pass_s);
    EXPECT_TRUE(std::isnan(plant.time_when_nozzle_line_reaches(0.0, second_pass_s + 1e-6)));
    // -9 m lies only in the short -10 -> -8.5 drive (the first approach starts at -60
    // and passes it too); after the first pass only that drive is left.
    const double short_drive_s = plant.time_when_nozzle_line_reaches(-9.0, first_pass_s);
    EXPECT_NEAR(plant.state_at(short_drive_s).nozzle_line_along_m, -9.0, 1e-9);
    EXPECT_LT(short_drive_s, second_pass_s);
}

TEST(VehiclePlant, RejectsImpossibleRoutes) {
    EXPECT_THROW(VehiclePlant({DrivePhase{-1.0, 1.0, 0.5}}, BoomGeometry{}, 0.0), std::invalid_argument);
    EXPECT_THROW(VehiclePlant({DrivePhase{1.0, 0.0, 0.5}}, BoomGeometry{}, 0.0), std::invalid_argument);
    EXPECT_THROW(VehiclePlant({DrivePhase{1.0, 1.0, 0.0}}, BoomGeometry{}, 0.0), std::invalid_argument);
    EXPECT_THROW(VehiclePlant({StandPhase{-1.0}}, BoomGeometry{}, 0.0), std::invalid_argument);
    try {
        VehiclePlant({StandPhase{1.0}, DrivePhase{-1.0, 1.0, 0.5}}, BoomGeometry{}, 0.0);
        FAIL() << "a backwards drive was accepted";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("route phase 1"), std::string::npos) << error.what();
    }
    // A zero-length drive is allowed and takes no time.
    const VehiclePlant still({DrivePhase{3.0, 1.0, 0.5}}, BoomGeometry{}, 3.0);
    EXPECT_EQ(still.end_time_s(), 0.0);
    EXPECT_EQ(still.time_when_nozzle_line_reaches(3.0), 0.0);
}

// --- the boom moving during the run (BoomLift)

// Eq. 6 written out here, apart from the plant's: L4 = L1 + cos(atan(h/L2)) L2 + L3
// with the paper's 0.5 / 0.8 / 0.45 m, cos(atan(x)) = 1 / sqrt(1 + x^2).
double eq6_l4_m(double rise_m) { return 0.5 + 0.8 / std::sqrt(1.0 + (rise_m / 0.8) * (rise_m / 0.8)) + 0.45; }

std::vector<RoutePhase> stand_then_approach() {
    return {StandPhase{2.0}, DrivePhase{0.0, kSixKmH_m_s, 0.5}, StandPhase{5.0}, DrivePhase{10.0, kSixKmH_m_s, 0.5}};
}

TEST(VehiclePlant, L4FollowsTheLinkageRiseAndTheAntennaTheRoute) {
    // Up 0.5 -> 1.0 m at 0.1 m/s from 10 s (arrives at 15 s), back down at 30 s (arrives at 35 s).
    const VehiclePlant moving(stand_then_approach(), BoomGeometry{}, -60.0,
                              {BoomLift{10.0, 1.0, 0.1}, BoomLift{30.0, 0.5, 0.1}});
    const VehiclePlant still(stand_then_approach(), BoomGeometry{}, -60.0);
    for (const double t_s : {0.0, 5.0, 9.99, 10.0, 12.5, 15.0, 20.0, 32.5, 35.0, 38.0, 50.0}) {
        SCOPED_TRACE(t_s);
        const VehicleState a = moving.state_at(t_s);
        const VehicleState b = still.state_at(t_s);
        // The vehicle drives the same whatever the boom does.
        EXPECT_EQ(a.antenna_along_m, b.antenna_along_m);
        EXPECT_EQ(a.speed_m_s, b.speed_m_s);
        EXPECT_EQ(a.odometer_distance_m, b.odometer_distance_m);
        EXPECT_NEAR(a.l4_m, eq6_l4_m(a.linkage_rise_m), 1e-12);
        EXPECT_NEAR(a.antenna_along_m - a.nozzle_line_along_m, a.l4_m, 1e-12);
        EXPECT_EQ(b.linkage_rise_m, 0.5);
        EXPECT_EQ(b.nozzle_line_along_m + b.l4_m, b.antenna_along_m);
    }
    EXPECT_NEAR(moving.state_at(12.5).linkage_rise_m, 0.75, 1e-12);
    EXPECT_EQ(moving.state_at(15.0).linkage_rise_m, 1.0);
    EXPECT_EQ(moving.state_at(20.0).linkage_rise_m, 1.0);
    EXPECT_NEAR(moving.state_at(32.5).linkage_rise_m, 0.75, 1e-12);
    // Raised, the nozzles swing 0.179 m towards the antenna (1.628 -> 1.450 m).
    EXPECT_NEAR(moving.state_at(20.0).nozzle_line_along_m - still.state_at(20.0).nozzle_line_along_m,
                eq6_l4_m(0.5) - eq6_l4_m(1.0), 1e-12);
    EXPECT_NEAR(eq6_l4_m(0.5) - eq6_l4_m(1.0), 0.179, 0.001);
    // Before the first move and once back at the initial h: the route itself, bit for bit.
    for (const double t_s : {0.0, 9.99, 10.0, 35.0, 38.0, 50.0}) {
        EXPECT_EQ(moving.state_at(t_s).nozzle_line_along_m, still.state_at(t_s).nozzle_line_along_m) << t_s;
        EXPECT_EQ(moving.state_at(t_s).l4_m, still.state_at(t_s).l4_m) << t_s;
    }
}

// Equal bit for bit, or both NaN ("never").
bool same_time(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

TEST(VehiclePlant, LiftsAfterTheRouteLeaveEveryAnswerBitForBit) {
    const VehiclePlant still(stand_then_approach(), BoomGeometry{}, -60.0);
    const VehiclePlant late(stand_then_approach(), BoomGeometry{}, -60.0,
                            {BoomLift{still.end_time_s() + 1.0, 0.9, 0.05}});
    for (double t_s = 0.0; t_s <= still.end_time_s(); t_s += 0.37) {
        EXPECT_EQ(late.state_at(t_s).nozzle_line_along_m, still.state_at(t_s).nozzle_line_along_m) << t_s;
    }
    EXPECT_TRUE(std::isfinite(still.time_when_nozzle_line_reaches(4.0, 45.0)));
    for (const double along_m : {-59.0, -30.0, -0.5, 0.0, 4.0, 10.0}) {
        EXPECT_TRUE(same_time(late.time_when_nozzle_line_reaches(along_m), still.time_when_nozzle_line_reaches(along_m)))
            << along_m;
        EXPECT_TRUE(same_time(late.time_when_nozzle_line_reaches(along_m, 45.0),
                              still.time_when_nozzle_line_reaches(along_m, 45.0)))
            << along_m;
    }
}

TEST(VehiclePlant, TimeWhenNozzleLineReachesAgreesWithStateAtWhileTheBoomMoves) {
    // Raised while accelerating and cruising, lowered (h 1.0 -> 0) while cruising
    // (the vehicle's 1.67 m/s beats the boom's at most 0.385 x 0.1 m/s backwards:
    // the nozzle line still only goes forward), raised again in the stand at the
    // breakpoint (41.3-46.3 s), where the nozzle line moves with the vehicle still.
    const VehiclePlant plant(stand_then_approach(), BoomGeometry{}, -60.0,
                             {BoomLift{3.0, 1.0, 0.05}, BoomLift{20.0, 0.0, 0.1}, BoomLift{42.0, 1.0, 0.5}});
    int reached = 0;
    for (double along_m = -59.5; along_m <= 10.0; along_m += 0.173) {
        SCOPED_TRACE(along_m);
        const double t_s = plant.time_when_nozzle_line_reaches(along_m);
        ASSERT_TRUE(std::isfinite(t_s));
        ++reached;
        EXPECT_NEAR(plant.state_at(t_s).nozzle_line_along_m, along_m, 1e-9);
        // Forward only here, so the first time is where a bisection on state_at finds it.
        EXPECT_NEAR(t_s, bisect_reach(plant, along_m, 0.0, plant.end_time_s()), 1e-7);
    }
    EXPECT_GT(reached, 390);
    // Between where the lowered boom left the nozzle line at the stop (L4 1.75 m:
    // 0.12 m short of the route's 0) and where raising it in the stand takes it
    // (L4 1.45 m: 0.18 m past): reached while the vehicle stands.
    const double stand_s = plant.time_when_nozzle_line_reaches(0.1, 30.0);
    EXPECT_GT(stand_s, 42.0);
    EXPECT_LT(stand_s, 44.0);
    EXPECT_EQ(plant.state_at(stand_s).speed_m_s, 0.0);
    EXPECT_NEAR(plant.state_at(stand_s).nozzle_line_along_m, 0.1, 1e-9);
}

TEST(VehiclePlant, LoweringTheBoomMovesTheNozzleLineBackAtMost0385TimesTheRate) {
    // Standing at 0 with h 1.0, lowered to 0 at 50 mm/s from 5 s to 25 s.
    const double rate_m_s = 0.05;
    const VehiclePlant standing({StandPhase{30.0}}, BoomGeometry{0.5, 0.8, 0.45, 1.0}, 0.0,
                                {BoomLift{5.0, 0.0, rate_m_s}});
    EXPECT_NEAR(standing.state_at(30.0).nozzle_line_along_m, eq6_l4_m(1.0) - eq6_l4_m(0.0), 1e-12);  // -0.30 m
    double fastest_back_m_s = 0.0;
    for (double t_s = 5.0; t_s < 25.0; t_s += 0.01) {
        const double step_m = standing.state_at(t_s + 0.01).nozzle_line_along_m - standing.state_at(t_s).nozzle_line_along_m;
        EXPECT_LE(step_m, 0.0) << t_s;
        fastest_back_m_s = std::max(fastest_back_m_s, -step_m / 0.01);
    }
    // max |dL4/dh| = 2 / (3 sqrt 3), at h = L2 / sqrt 2 (0.57 m), which the move passes.
    const double bound_m_s = 2.0 / (3.0 * std::sqrt(3.0)) * rate_m_s;
    EXPECT_LE(fastest_back_m_s, bound_m_s * (1.0 + 1e-6));
    EXPECT_GT(fastest_back_m_s, bound_m_s * 0.999);
    // Going back over a spot counts as reaching it (the nozzles pass over it);
    // a spot ahead is never reached.
    const double back_s = standing.time_when_nozzle_line_reaches(-0.15);
    EXPECT_GT(back_s, 5.0);
    EXPECT_LT(back_s, 25.0);
    EXPECT_NEAR(standing.state_at(back_s).nozzle_line_along_m, -0.15, 1e-9);
    EXPECT_TRUE(std::isnan(standing.time_when_nozzle_line_reaches(0.1)));

    // Creeping forward at 2 cm/s while the boom drops at 0.5 m/s (up to 0.19 m/s
    // back): the nozzle line goes back over -0.1 m, then forward over it again.
    const VehiclePlant creeping({DrivePhase{1.0, 0.02, 0.5}}, BoomGeometry{0.5, 0.8, 0.45, 1.0}, 0.0,
                                {BoomLift{1.0, 0.0, 0.5}});
    const double first_s = creeping.time_when_nozzle_line_reaches(-0.1);
    EXPECT_GT(first_s, 1.0);
    EXPECT_LT(first_s, 3.0);
    EXPECT_NEAR(creeping.state_at(first_s).nozzle_line_along_m, -0.1, 1e-9);
    for (double t_s = 0.0; t_s < first_s - 1e-3; t_s += 1e-3) {
        EXPECT_GT(creeping.state_at(t_s).nozzle_line_along_m, -0.1) << t_s;  // it is the first
    }
    const double again_s = creeping.time_when_nozzle_line_reaches(-0.1, first_s + 0.01);
    EXPECT_GT(again_s, 3.0);
    EXPECT_NEAR(creeping.state_at(again_s).nozzle_line_along_m, -0.1, 1e-9);
}

TEST(VehiclePlant, RejectsImpossibleLifts) {
    const auto build = [](BoomGeometry boom, std::vector<BoomLift> lifts) {
        return VehiclePlant({StandPhase{10.0}}, boom, 0.0, std::move(lifts));
    };
    EXPECT_THROW(build(BoomGeometry{}, {BoomLift{-1.0, 0.2, 0.1}}), std::invalid_argument);
    EXPECT_THROW(build(BoomGeometry{}, {BoomLift{1.0, -0.2, 0.1}}), std::invalid_argument);
    EXPECT_THROW(build(BoomGeometry{}, {BoomLift{1.0, 0.2, 0.0}}), std::invalid_argument);
    EXPECT_THROW(build(BoomGeometry{}, {BoomLift{1.0, 0.2, std::nan("")}}), std::invalid_argument);
    EXPECT_THROW(build(BoomGeometry{}, {BoomLift{1.0, 20.0, 0.1}}), std::invalid_argument);
    EXPECT_THROW(build(BoomGeometry{0.5, 0.8, 0.45, -0.1}, {BoomLift{1.0, 0.2, 0.1}}), std::invalid_argument);
    try {
        // 0.5 -> 0.2 m at 0.1 m/s arrives at 4 s; the next starts at 3.9 s.
        build(BoomGeometry{}, {BoomLift{1.0, 0.2, 0.1}, BoomLift{3.9, 0.6, 0.1}});
        FAIL() << "overlapping lifts were accepted";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("boom lift 1"), std::string::npos) << error.what();
    }
    EXPECT_NO_THROW(build(BoomGeometry{}, {BoomLift{1.0, 0.2, 0.1}, BoomLift{4.0, 0.6, 0.1}}));
    // A zero-length drive still counts as being there, as without lifts.
    const VehiclePlant still({DrivePhase{3.0, 1.0, 0.5}}, BoomGeometry{}, 3.0, {BoomLift{1.0, 0.2, 0.1}});
    EXPECT_EQ(still.time_when_nozzle_line_reaches(3.0), 0.0);
}

// --- field frame

constexpr double kOriginLat_deg = 40.18;
constexpr double kOriginLon_deg = 116.44;
constexpr double kOriginHeight_m = 50.0;

TEST(FieldFrame, RoundTripIsWithinAMicrometre) {
    for (const double heading_deg : {0.0, 37.0, 90.0, 180.0, 271.5}) {
        const FieldFrame frame(kOriginLat_deg, kOriginLon_deg, kOriginHeight_m, heading_deg);
        for (const double along_m : {-500.0, -60.0, -1.628, 0.0, 0.3, 5.0, 250.0}) {
            for (const double cross_m : {-6.1, 0.0, 0.05, 12.2}) {
                const GeoPoint point = frame.to_geodetic(along_m, cross_m);
                const auto [back_along_m, back_cross_m] = frame.to_line(point);
                EXPECT_NEAR(back_along_m, along_m, 1e-6) << heading_deg << " " << along_m << " " << cross_m;
                EXPECT_NEAR(back_cross_m, cross_m, 1e-6) << heading_deg << " " << along_m << " " << cross_m;
            }
        }
    }
}

// Azimuth (deg) and distance (m) of `point` seen from the origin, on WGS84.
std::pair<double, double> azimuth_and_distance(const GeoPoint& point) {
    double distance_m = 0.0;
    double azimuth_deg = 0.0;
    double back_azimuth_deg = 0.0;
    GeographicLib::Geodesic::WGS84().Inverse(kOriginLat_deg, kOriginLon_deg, point.lat_deg, point.lon_deg, distance_m,
                                             azimuth_deg, back_azimuth_deg);
    return {azimuth_deg, distance_m};
}

TEST(FieldFrame, HeadingIsACompassBearing) {
    const FieldFrame east_line(kOriginLat_deg, kOriginLon_deg, kOriginHeight_m, 90.0);
    EXPECT_EQ(east_line.heading_deg(), 90.0);
    // Heading 90: along is east.
    const GeoPoint ahead = east_line.to_geodetic(100.0, 0.0);
    EXPECT_GT(ahead.lon_deg, kOriginLon_deg);
    const auto [azimuth_deg, distance_m] = azimuth_and_distance(ahead);
    EXPECT_NEAR(azimuth_deg, 90.0, 1e-3);
    EXPECT_NEAR(distance_m, 100.0, 1e-3);
    // ... and cross (to the right of east) is south.
    const auto [right_azimuth_deg, right_distance_m] = azimuth_and_distance(east_line.to_geodetic(0.0, 10.0));
    EXPECT_NEAR(std::abs(right_azimuth_deg), 180.0, 1e-3);
    EXPECT_NEAR(right_distance_m, 10.0, 1e-4);

    // Heading 0: along is north, cross is east.
    const FieldFrame north_line(kOriginLat_deg, kOriginLon_deg, kOriginHeight_m, 0.0);
    EXPECT_NEAR(azimuth_and_distance(north_line.to_geodetic(50.0, 0.0)).first, 0.0, 1e-3);
    EXPECT_NEAR(azimuth_and_distance(north_line.to_geodetic(0.0, 50.0)).first, 90.0, 1e-3);
    // The origin itself, and its height.
    const GeoPoint origin = north_line.to_geodetic(0.0, 0.0);
    EXPECT_NEAR(origin.lat_deg, kOriginLat_deg, 1e-12);
    EXPECT_NEAR(origin.lon_deg, kOriginLon_deg, 1e-12);
    EXPECT_NEAR(origin.height_m, kOriginHeight_m, 1e-9);
    EXPECT_NEAR(north_line.to_geodetic(0.0, 0.0, 2.5).height_m, kOriginHeight_m + 2.5, 1e-9);
}

TEST(FieldFrame, RejectsBadOrigin) {
    EXPECT_THROW(FieldFrame(91.0, 0.0, 0.0, 0.0), std::invalid_argument);
    EXPECT_THROW(FieldFrame(40.0, 116.0, 0.0, std::nan("")), std::invalid_argument);
}

}  // namespace
