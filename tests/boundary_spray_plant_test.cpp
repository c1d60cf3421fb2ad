// Seed 001's spray on the ground (emulators/boundary_spray_plant.h): valves,
// kinematics and the deposition grid together, judged with the boundary
// metrics. Known answers by hand beside each check.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "emulators/boundary_spray_plant.h"
#include "emulators/field2d/nozzle_flow_table.h"
#include "harness/systems/boundary/boundary_metrics.h"

namespace {

using namespace rig::field2d;
using rig::seconds_to_ns;
using rig::emulators::BoundarySprayPlant;
using rig::emulators::PwmNozzleValves;
using rig::emulators::PwmValveParams;
using rig::emulators::SprayDepositionParams;
using rig::harness::BoundaryEdge;
using rig::harness::DoseRaster;
using rig::harness::EdgeProbe;
using rig::harness::raster_of;
using rig::harness::wet_edge_profile;

const LocalFrame kFrame(35.1, 113.3, 90.0);

// North at 1 m/s from the rear axle at (0, -5): the boom centre (1.6 + 1.0 m
// ahead, Eq. 18 at 0.5 m) is at north t - 2.4 and crosses north = 0 at 2.4 s.
SprayerKinematics north_at_1_m_s() {
    return SprayerKinematics(kFrame,
                             Route2d({{0, -5}, 0.0, 1.0},
                                     {StraightSegment{10.0, 1.0, 0.5}, StraightSegment{1.0, 1.0, 0.5, true}}),
                             SprayerMounting{}, BoomHeightProfile{});
}

DepositionGrid2d grid_around_edge(double cell_m, double north_min_m = -3.0) {
    DepositionGrid2dParams g;
    g.east_min_m = -3.0;
    g.east_max_m = 3.0;
    g.north_min_m = north_min_m;
    g.north_max_m = 1.0;
    g.cell_m = cell_m;
    return DepositionGrid2d(g);
}

// The edge north = 0, area to the south: from east 3 to east -3 (outside on its right).
constexpr BoundaryEdge kEdge{3.0, 0.0, -3.0, 0.0};

TEST(BoundarySprayPlant, ANozzleClosing0_1sLateAt1MetrePerSecondWetsA0_1mLongerEdge) {
    // Ideal valves (no stroke, duty applied at once) and a 2 cm thin fan band on a
    // 1 cm grid, so the wet edge is where the nozzle was when it closed, plus 1 cm.
    const SprayerKinematics k = north_at_1_m_s();
    PwmValveParams valves;
    valves.response_s = 0.0;
    valves.latch_at_period_start = false;
    SprayDepositionParams deposition;
    deposition.band_thickness_m = 0.02;
    BoundarySprayPlant plant(k, PwmNozzleValves(valves, NozzleFlowTable::paper_table3()), grid_around_edge(0.01),
                             deposition);
    for (int n = 0; n < 6; ++n) plant.command_duty(n, 100.0, 0);
    plant.advance_to(seconds_to_ns(2.4));
    for (int n = 0; n < 6; ++n) {
        if (n != 2) plant.command_duty(n, 0.0, seconds_to_ns(2.4));  // on time, at the edge
    }
    plant.advance_to(seconds_to_ns(2.5));
    plant.command_duty(2, 0.0, seconds_to_ns(2.5));  // 0.1 s late
    plant.advance_to(seconds_to_ns(4.0));

    // Stations every 0.5 m from east 3 westward. Nozzle 2 (0.25 m left of the
    // centre, at east -0.25) sprays east -0.96 ... 0.46: stations at 3.0 and 3.5 m
    // (east 0 and -0.5); nozzle 5 (east 1.25, fan 0.54 ... 1.96): 1.5 and 2.0 m.
    const auto late = wet_edge_profile(raster_of(plant.grid(), 2), kEdge);
    const auto on_time = wet_edge_profile(raster_of(plant.grid(), 5), kEdge);
    ASSERT_EQ(late.excess_m.size(), 13u);
    for (std::size_t s : {6u, 7u}) {
        // Last 5 ms step of spray placed at its middle, 2.4975 s: centre at 0.0975 m,
        // band edge 1 cm further: 0.1075, found within 2.5 mm on a 1 cm grid.
        EXPECT_NEAR(late.excess_m[s], 0.1075, 0.005) << "station " << late.station_m[s];
    }
    for (std::size_t s : {3u, 4u}) EXPECT_NEAR(on_time.excess_m[s], 0.0075, 0.005);
    // The lateness itself: 1 m/s x 0.1 s, to the millimetre.
    EXPECT_NEAR(late.excess_m[6] - on_time.excess_m[3], 0.100, 0.001);
    // Where nozzle 2 never sprayed its layer is dry.
    EXPECT_TRUE(std::isnan(late.excess_m[0]));
    // The ground as a whole: its edge at station 3.0 m is the late nozzle's.
    std::vector<DoseRaster> layers;
    for (int n = 0; n < 6; ++n) layers.push_back(raster_of(plant.grid(), n));
    EXPECT_NEAR(wet_edge_profile(rig::harness::sum_rasters(layers), kEdge).excess_m[6], 0.1075, 0.005);
}

TEST(BoundarySprayPlant, EverythingSprayedLandsSomewhereAndHowTimeJumpsChangesNothing) {
    const SprayerKinematics k = north_at_1_m_s();
    const auto run = [&](const std::vector<double>& stops) {
        // The grid starts at north -2: the first 0.4 m (from -2.4) land off it.
        // PWM periods from t = 0, so spraying starts at once.
        PwmValveParams valves;
        valves.pwm_phase_s = 0.0;
        BoundarySprayPlant plant(k, PwmNozzleValves(valves, NozzleFlowTable::paper_table3()),
                                 grid_around_edge(0.02, -2.0));
        for (int n = 0; n < 6; ++n) plant.command_duty(n, n % 2 == 0 ? 40.0 : 100.0, 0);
        bool switched = false;
        for (double stop : stops) {
            if (!switched && stop >= 2.4) {
                plant.advance_to(seconds_to_ns(2.4));
                for (int n = 0; n < 6; ++n) plant.command_duty(n, 0.0, seconds_to_ns(2.4));
                switched = true;
            }
            plant.advance_to(seconds_to_ns(stop));
        }
        return plant;
    };
    std::vector<double> many;
    for (double t = 0.0013; t < 4.0; t += 0.0137) many.push_back(t);
    many.push_back(4.0);
    const BoundarySprayPlant once = run({4.0});
    const BoundarySprayPlant often = run(many);
    for (int n = 0; n < 6; ++n) {
        // Bit for bit: the plant steps on its own 5 ms grid whatever the caller does.
        EXPECT_EQ(once.grid().dose_layer_ul_cm2(n), often.grid().dose_layer_ul_cm2(n)) << "nozzle " << n;
        EXPECT_EQ(once.valves().delivered_l(n), often.valves().delivered_l(n));
    }
    // Litres on the grid + off it = litres the valves delivered.
    double delivered = 0.0;
    for (int n = 0; n < 6; ++n) delivered += once.valves().delivered_l(n);
    EXPECT_GT(delivered, 0.0);
    EXPECT_NEAR(once.grid().total_volume_l(), delivered, 1e-12 * delivered);
    double on_grid = 0.0;
    for (int n = 0; n < 6; ++n) {
        for (double d : once.grid().dose_layer_ul_cm2(n)) on_grid += d * 4.0 * 1e-6;  // 4 cm^2 cells
    }
    EXPECT_NEAR(on_grid + once.grid().volume_off_grid_l(), delivered, 1e-9 * delivered);
    // About 0.4 m of 2.44 m of spraying (the 0 % at 2.4 s is latched at the
    // period from 22 / 9 = 2.444 s) was south of the grid: a sixth of the volume.
    EXPECT_NEAR(once.grid().volume_off_grid_l() / delivered, 0.4 / 2.4, 0.02);
}

TEST(BoundarySprayPlant, FlowPerDutyDeliveredIsTable3) {
    // Standing (deposition on coarse 1 m cells: only the volumes matter here);
    // each duty held for 1 min as in the paper's calibration, commanded 50 ms
    // before the minute so the PWM latches it on the minute (540 periods each).
    const SprayerKinematics k(kFrame, Route2d({{0, 0}, 0.0}, {StandSegment{600.0}}), SprayerMounting{},
                              BoomHeightProfile{});
    PwmValveParams valves;
    valves.pwm_phase_s = 0.0;  // periods on the minute
    BoundarySprayPlant plant(k, PwmNozzleValves(valves, NozzleFlowTable::paper_table3()), grid_around_edge(1.0));
    const std::vector<double> duties{100, 90, 80, 70, 60, 50, 40, 30};
    std::vector<rig::harness::FlowRecord> records;
    for (std::size_t i = 0; i < duties.size(); ++i) {
        const double start_s = 60.0 * static_cast<double>(i + 1);
        plant.advance_to(seconds_to_ns(start_s - 0.05));
        for (int n = 0; n < 6; ++n) plant.command_duty(n, duties[i], seconds_to_ns(start_s - 0.05));
        plant.advance_to(seconds_to_ns(start_s));
        std::vector<double> before(6);
        for (int n = 0; n < 6; ++n) before[static_cast<std::size_t>(n)] = plant.valves().delivered_l(n);
        plant.advance_to(seconds_to_ns(start_s + 60.0 - 0.05));
        // (the last 50 ms are booked with the next window's lead-in; measure 59.95 s)
        for (int n = 0; n < 6; ++n) {
            records.push_back({n, duties[i], plant.valves().delivered_l(n) - before[static_cast<std::size_t>(n)], 59.95});
        }
    }
    const auto rows = rig::harness::flow_against_table(records, NozzleFlowTable::paper_table3());
    const auto m = rig::harness::flow_table_metrics(rows);
    EXPECT_EQ(m.at("flow_table_points"), 48.0);
    // A window of 59.95 s is 539.55 periods: the part period costs at most about
    // 0.45 / 539.55 of the flow's ripple, well under 0.2 %.
    EXPECT_LT(m.at("flow_table_max_abs_error_pct"), 0.2);
    // The controller's Eq. 13 comes back from what the plant delivered.
    const auto fit = rig::harness::eq13_fit_metrics(rows);
    EXPECT_NEAR(fit.at("eq13_slope_l_min_per_pct"), 0.00375, 2e-5);
    EXPECT_NEAR(fit.at("eq13_intercept_l_min"), 0.296, 0.002);
}

TEST(BoundarySprayPlant, MismatchedNozzleCountsAreRejected) {
    const SprayerKinematics k = north_at_1_m_s();
    DepositionGrid2dParams g;
    g.nozzle_count = 5;
    EXPECT_THROW(BoundarySprayPlant(k, PwmNozzleValves(PwmValveParams{}, NozzleFlowTable::paper_table3()),
                                    DepositionGrid2d(g)),
                 std::invalid_argument);
    SprayDepositionParams bad;
    bad.step_s = 0.0;
    EXPECT_THROW(BoundarySprayPlant(k, PwmNozzleValves(PwmValveParams{}, NozzleFlowTable::paper_table3()),
                                    grid_around_edge(0.05), bad),
                 std::invalid_argument);
}

}  // namespace
