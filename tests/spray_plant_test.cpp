// The spray plant without DDS: ball valve, flow map, spray circuit (Table 1
// timing, unloading, pipeline lag, nozzles, deposition, determinism), and the
// transfer functions of the pump-outlet and boom-height sensors, round-tripped
// through the controller's Eq. 8 / pull-wire conversions. The KF11 meter needs a
// DDS writer for its step(); it is in tests/flow_meter_kf11_test.cpp (label dds).
//
// Hand-worked numbers are in the comments; the paper is seed 000 (Table 1,
// Fig. 11, Table 2, sec. 2.4.1-2.4.2, 3.1).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "controller/flow_equations.h"
#include "emulators/ball_valve.h"
#include "emulators/boom_height_sensor.h"
#include "emulators/deposition_grid.h"
#include "emulators/flow_map.h"
#include "emulators/panel_switch.h"
#include "emulators/plant.h"
#include "emulators/pump_flow_sensor.h"
#include "emulators/spray_circuit.h"

namespace {

using namespace rig::emulators;
using rig::TimeNs;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kS = 1'000'000'000;

// ---------------------------------------------------------------- ball valve

// An ideal gear train (no start delay, no backlash) so that travel is exact.
BallValveParams ideal_valve(double initial_pct) {
    BallValveParams params;
    params.motor_start_delay_s = 0.0;
    params.backlash_pct = 0.0;
    params.initial_opening_pct = initial_pct;
    return params;
}

// Runs the drive for `seconds` in 1 ms steps, as the spray circuit does.
void run_ms_steps(BallValve& valve, BallValve::Drive drive, double seconds) {
    valve.set_drive(drive);
    const auto steps = static_cast<int>(std::lround(seconds * 1000.0));
    for (int i = 0; i < steps; ++i) valve.step(0.001);
    valve.set_drive(BallValve::Drive::off);
}

TEST(BallValve, FullTravelClosedToOpenTakes11SecondsAndBack) {
    BallValve valve(ideal_valve(0.0));
    run_ms_steps(valve, BallValve::Drive::forward, 5.5);
    EXPECT_NEAR(valve.opening_pct(), 50.0, 1e-9);  // 5.5 s of 11 s
    run_ms_steps(valve, BallValve::Drive::forward, 5.49);
    EXPECT_LT(valve.opening_pct(), 100.0);         // 10.99 s: not there yet
    EXPECT_NEAR(valve.opening_pct(), 99.909090909, 1e-6);
    run_ms_steps(valve, BallValve::Drive::forward, 0.01);
    EXPECT_NEAR(valve.opening_pct(), 100.0, 1e-9);
    run_ms_steps(valve, BallValve::Drive::reverse, 11.0);
    EXPECT_NEAR(valve.opening_pct(), 0.0, 1e-9);
}

TEST(BallValve, StartDelayIsLostAtEveryRelayClosure) {
    BallValveParams params = ideal_valve(0.0);
    params.motor_start_delay_s = 0.02;
    BallValve valve(params);
    // 11 s of drive moves (11 - 0.02) / 11 x 100 = 99.8181 %; 0.02 s more reaches the stop.
    run_ms_steps(valve, BallValve::Drive::forward, 11.0);
    EXPECT_NEAR(valve.opening_pct(), 100.0 - 0.02 / 11.0 * 100.0, 1e-9);
    // A 0.1 s pulse: (0.1 - 0.02) / 11 x 100 = 0.72727 %.
    run_ms_steps(valve, BallValve::Drive::reverse, 0.1);
    EXPECT_NEAR(valve.opening_pct(), 100.0 - 0.02 / 11.0 * 100.0 - 0.08 / 11.0 * 100.0, 1e-9);
}

TEST(BallValve, PulseShorterThanTheStartDelayMovesNothing) {
    BallValveParams params = ideal_valve(50.0);
    params.motor_start_delay_s = 0.02;
    BallValve valve(params);
    // Repeated 15 ms pulses never add up: the delay is lost again at each closure.
    for (int pulse = 0; pulse < 20; ++pulse) run_ms_steps(valve, BallValve::Drive::forward, 0.015);
    EXPECT_EQ(valve.opening_pct(), 50.0);
    // One step longer than the delay does move.
    valve.set_drive(BallValve::Drive::forward);
    valve.step(0.021);
    EXPECT_NEAR(valve.opening_pct(), 50.0 + 0.001 / 11.0 * 100.0, 1e-12);
}

TEST(BallValve, BacklashIsTakenUpOnReversalOnly) {
    BallValveParams params = ideal_valve(50.0);
    params.backlash_pct = 0.3;
    BallValve valve(params);
    run_ms_steps(valve, BallValve::Drive::forward, 1.1);  // first move ever: no play to take up
    EXPECT_NEAR(valve.opening_pct(), 60.0, 1e-9);
    run_ms_steps(valve, BallValve::Drive::forward, 1.1);  // same direction again: none either
    EXPECT_NEAR(valve.opening_pct(), 70.0, 1e-9);
    run_ms_steps(valve, BallValve::Drive::reverse, 1.1);  // reversal: 10 % of motor travel, 0.3 % of it play
    EXPECT_NEAR(valve.opening_pct(), 60.3, 1e-9);
    run_ms_steps(valve, BallValve::Drive::reverse, 1.1);
    EXPECT_NEAR(valve.opening_pct(), 50.3, 1e-9);
    run_ms_steps(valve, BallValve::Drive::forward, 0.011);  // 0.1 % of motor travel: all of it play
    EXPECT_NEAR(valve.opening_pct(), 50.3, 1e-9);
    run_ms_steps(valve, BallValve::Drive::forward, 1.1);    // the remaining 0.2 % of play, then 9.8 %
    EXPECT_NEAR(valve.opening_pct(), 60.1, 1e-9);
}

// A relay click too short to turn the motor leaves the gear play where it was
// (found by this suite: the valve used to re-arm the play on every reversal of
// the relays, turned or not).
TEST(BallValve, ReversalPulseShorterThanTheStartDelayDoesNotArmBacklash) {
    BallValveParams params = ideal_valve(50.0);
    params.motor_start_delay_s = 0.02;
    params.backlash_pct = 0.3;
    BallValve valve(params);
    run_ms_steps(valve, BallValve::Drive::forward, 1.12);  // 0.02 s delay, then 10 %
    ASSERT_NEAR(valve.opening_pct(), 60.0, 1e-9);
    run_ms_steps(valve, BallValve::Drive::reverse, 0.01);  // relay click, motor never turns
    ASSERT_NEAR(valve.opening_pct(), 60.0, 1e-9);
    run_ms_steps(valve, BallValve::Drive::forward, 1.12);  // same direction as the gears last turned
    EXPECT_NEAR(valve.opening_pct(), 70.0, 1e-9);
}

TEST(BallValve, EndStopsHoldAndDoNotStoreTravel) {
    BallValve valve(ideal_valve(95.0));
    run_ms_steps(valve, BallValve::Drive::forward, 3.0);  // 27 % more would be 122 %
    EXPECT_EQ(valve.opening_pct(), 100.0);
    run_ms_steps(valve, BallValve::Drive::reverse, 0.55);  // 5 % back from the stop, not from 122 %
    EXPECT_NEAR(valve.opening_pct(), 95.0, 1e-9);
    run_ms_steps(valve, BallValve::Drive::reverse, 20.0);
    EXPECT_EQ(valve.opening_pct(), 0.0);
    run_ms_steps(valve, BallValve::Drive::forward, 1.1);
    EXPECT_NEAR(valve.opening_pct(), 10.0, 1e-9);
}

TEST(BallValve, BothRelaysBrakeTheMotorAndAreCounted) {
    BallValve valve(ideal_valve(50.0));
    EXPECT_EQ(valve.both_relays_events(), 0u);
    valve.set_drive(BallValve::Drive::both);
    for (int i = 0; i < 1000; ++i) valve.step(0.001);
    EXPECT_EQ(valve.opening_pct(), 50.0);
    EXPECT_EQ(valve.both_relays_events(), 1u);
    valve.set_drive(BallValve::Drive::both);  // still both: the same event
    EXPECT_EQ(valve.both_relays_events(), 1u);
    valve.set_drive(BallValve::Drive::forward);
    valve.set_drive(BallValve::Drive::both);  // forward -> both: a second one
    valve.step(1.0);
    EXPECT_EQ(valve.opening_pct(), 50.0);
    EXPECT_EQ(valve.both_relays_events(), 2u);
}

TEST(BallValve, RejectsImpossibleParameters) {
    BallValveParams params;
    params.travel_s = 0.0;
    EXPECT_THROW(BallValve{params}, std::invalid_argument);
    params = BallValveParams{};
    params.backlash_pct = -0.1;
    EXPECT_THROW(BallValve{params}, std::invalid_argument);
    params = BallValveParams{};
    params.initial_opening_pct = 100.5;
    EXPECT_THROW(BallValve{params}, std::invalid_argument);
}

// ---------------------------------------------------------------- flow map

FlowMapParams calibrated_truth() {
    FlowMapParams params;
    params.interpolation_bulge_pct = 0.0;
    params.calibration_drift_pct = 0.0;
    return params;
}

TEST(FlowMap, DefaultLinesReproduceFig11AndTable2) {
    const FlowMap map(calibrated_truth());
    // flow_map.h: at 31.1 L/min pump flow 14.2 / 16.0 / 19.0 / 22.0 / 25.5 L/min at
    // 87 / 90 / 93 / 94 / 95 %; 38.6 L/min at 95 % and 57.3 L/min (Fig. 11's range
    // 14.20-38.6 L/min for 31.10-57.30 L/min).
    EXPECT_NEAR(map.main_flow_l_min(87.0, 31.1), 14.2, 1e-9);
    EXPECT_NEAR(map.main_flow_l_min(90.0, 31.1), 16.0, 1e-9);
    EXPECT_NEAR(map.main_flow_l_min(93.0, 31.1), 19.0, 1e-9);
    EXPECT_NEAR(map.main_flow_l_min(94.0, 31.1), 22.0, 1e-9);
    EXPECT_NEAR(map.main_flow_l_min(95.0, 31.1), 25.5, 1e-9);
    EXPECT_NEAR(map.main_flow_l_min(95.0, 57.3), 38.6, 1e-9);
    // Table 2's targets sit on their openings at the low pump flow: 15-17 L/min
    // around 90 %, 18-20 around 93 %, 21-23 around 94 %, 24-27 around 95 %.
    EXPECT_GT(map.main_flow_l_min(90.0, 31.1), 15.0);
    EXPECT_LT(map.main_flow_l_min(90.0, 31.1), 17.0);
    EXPECT_GT(map.main_flow_l_min(93.0, 31.1), 18.0);
    EXPECT_LE(map.main_flow_l_min(93.0, 31.1), 20.0);
    EXPECT_GE(map.main_flow_l_min(94.0, 31.1), 21.0);
    EXPECT_LE(map.main_flow_l_min(94.0, 31.1), 23.0);
    EXPECT_GE(map.main_flow_l_min(95.0, 31.1), 24.0);
    EXPECT_LE(map.main_flow_l_min(95.0, 31.1), 27.0);
    // Over the whole calibrated box the lowest is 14.2 and the highest 38.6.
    double lowest = 1e9;
    double highest = 0.0;
    for (double opening : {87.0, 90.0, 93.0, 94.0, 95.0}) {
        for (double pump = 31.1; pump <= 57.3 + 1e-9; pump += 0.1) {
            lowest = std::min(lowest, map.main_flow_l_min(opening, pump));
            highest = std::max(highest, map.main_flow_l_min(opening, pump));
        }
    }
    EXPECT_NEAR(lowest, 14.2, 1e-9);
    EXPECT_NEAR(highest, 38.6, 1e-6);
}

TEST(FlowMap, FlowRisesWithOpeningAtEveryPumpFlow) {
    // Default plant (bulge 3 %, drift 1.5 %): strictly rising from the zero-flow
    // opening up to where the cap takes over, never falling after it.
    const FlowMap map{FlowMapParams{}};
    for (double pump : {30.0, 31.1, 45.0, 57.3, 70.0, 81.0}) {
        SCOPED_TRACE(pump);
        const double cap = map.params().max_fraction_of_pump * pump;
        double previous = map.main_flow_l_min(60.0, pump);
        for (int tenth = 601; tenth <= 1000; ++tenth) {
            const double opening = tenth / 10.0;
            const double flow = map.main_flow_l_min(opening, pump);
            if (previous < cap) {
                EXPECT_GT(flow, previous) << "opening " << opening;
            } else {
                EXPECT_EQ(flow, cap) << "opening " << opening;
            }
            previous = flow;
        }
    }
}

TEST(FlowMap, NoFlowBelowTheZeroFlowOpeningAndLinearUpToTheFirstLine) {
    const FlowMap map(calibrated_truth());
    EXPECT_EQ(map.main_flow_l_min(0.0, 57.3), 0.0);
    EXPECT_EQ(map.main_flow_l_min(40.0, 57.3), 0.0);
    EXPECT_EQ(map.main_flow_l_min(60.0, 31.1), 0.0);  // zero_flow_opening_pct
    // Half way from 60 to 87 %: half of 14.2.
    EXPECT_NEAR(map.main_flow_l_min(73.5, 31.1), 7.1, 1e-9);
    EXPECT_GT(map.main_flow_l_min(60.5, 31.1), 0.0);
}

TEST(FlowMap, CappedAtTheShareOfPumpFlowThatCanReachTheBoom) {
    const FlowMap map(calibrated_truth());
    // Past 95 % the last slope (3.5 L/min per % at 31.1) would give 43 L/min at 100 %;
    // at most 95 % of the 31.1 L/min pump flow reaches the boom.
    EXPECT_NEAR(map.main_flow_l_min(100.0, 31.1), 0.95 * 31.1, 1e-12);
    EXPECT_NEAR(map.main_flow_l_min(96.0, 31.1), 29.0, 1e-9);  // 25.5 + 3.5: still under the cap
    FlowMapParams drifted = calibrated_truth();
    drifted.calibration_drift_pct = 50.0;  // drift cannot push it past the cap either
    EXPECT_NEAR(FlowMap(drifted).main_flow_l_min(95.0, 31.1), 0.95 * 31.1, 1e-12);
}

TEST(FlowMap, BulgeIsZeroAtCalibratedOpeningsAndFullAtMidInterval) {
    FlowMapParams bulged = calibrated_truth();
    bulged.interpolation_bulge_pct = 3.0;
    const FlowMap map(bulged);
    const FlowMap straight(calibrated_truth());
    for (double opening : {87.0, 90.0, 93.0, 94.0, 95.0}) {
        for (double pump : {31.1, 45.0, 57.3}) {
            EXPECT_NEAR(map.main_flow_l_min(opening, pump), straight.main_flow_l_min(opening, pump), 1e-12)
                << opening << " % at " << pump;
        }
    }
    // Mid-way between 90 and 93 %: straight (16 + 19) / 2 = 17.5, bulged by 3 %.
    EXPECT_NEAR(map.main_flow_l_min(91.5, 31.1), 17.5 * 1.03, 1e-9);
    EXPECT_NEAR(straight.main_flow_l_min(91.5, 31.1), 17.5, 1e-9);
}

TEST(FlowMap, CalibrationDriftScalesTheWholeMap) {
    FlowMapParams drifted = calibrated_truth();
    drifted.calibration_drift_pct = 1.5;
    const FlowMap map(drifted);
    EXPECT_NEAR(map.main_flow_l_min(95.0, 57.3), 38.6 * 1.015, 1e-9);
    EXPECT_NEAR(map.main_flow_l_min(87.0, 31.1), 14.2 * 1.015, 1e-9);
}

TEST(FlowMap, RejectsLinesThatAreUnsortedTooFewOrNotRising) {
    FlowMapParams one = calibrated_truth();
    one.lines.resize(1);
    EXPECT_THROW(FlowMap{one}, std::invalid_argument);
    FlowMapParams unsorted = calibrated_truth();
    std::swap(unsorted.lines[1], unsorted.lines[2]);
    EXPECT_THROW(FlowMap{unsorted}, std::invalid_argument);
    FlowMapParams falling = calibrated_truth();
    falling.lines[2].intercept_l_min = 0.0;  // 93 % below 90 % at every pump flow
    EXPECT_THROW(FlowMap{falling}, std::invalid_argument);
    FlowMapParams zero_too_high = calibrated_truth();
    zero_too_high.zero_flow_opening_pct = 87.0;
    EXPECT_THROW(FlowMap{zero_too_high}, std::invalid_argument);
}

// ---------------------------------------------------------------- spray circuit

PlantParams standing_plant(double nozzle_line_along_m) {
    PlantParams params;
    params.route = {StandPhase{1000.0}};
    params.start_nozzle_line_along_m = nozzle_line_along_m;
    return params;
}

// No pulsation, no drift, no bulge: the flow map's calibrated lines are the truth.
SprayCircuitParams quiet_circuit(double opening_pct) {
    SprayCircuitParams params;
    params.pump_flow_l_min = 31.1;
    params.pump_pulsation_pct = 0.0;
    params.flow_map = calibrated_truth();
    params.valve.initial_opening_pct = opening_pct;
    params.pipeline_time_constant_s = 0.25;  // the numbers worked by hand below use this lag
    params.pipeline_air_l = 0.0;             // and no air: one constant lag at every flow
    return params;
}

// A plant standing still and its spray circuit.
struct StaticRig {
    explicit StaticRig(SprayCircuitParams params, double nozzle_line_along_m = 0.0)
        : plant(standing_plant(nozzle_line_along_m)), circuit(plant, std::move(params)) {}
    Plant plant;
    SprayCircuit circuit;
};

// Litres booked on the ground in one pass, summed over the grid.
double grid_litres(const DepositionGrid& grid, int pass) {
    const double cell_area_cm2 = grid.params().cell_along_m * grid.params().nozzle_spacing_m * 1e4;
    double litres = 0.0;
    for (std::size_t row = 0; row < grid.row_count(); ++row) {
        for (int nozzle = 0; nozzle < grid.params().nozzle_count; ++nozzle) {
            litres += grid.dose_ul_cm2(pass, row, nozzle) * cell_area_cm2 / 1e6;
        }
    }
    return litres;
}

double nozzle_litres(const DepositionGrid& grid, int pass, int nozzle) {
    const double cell_area_cm2 = grid.params().cell_along_m * grid.params().nozzle_spacing_m * 1e4;
    double litres = 0.0;
    for (std::size_t row = 0; row < grid.row_count(); ++row) {
        litres += grid.dose_ul_cm2(pass, row, nozzle) * cell_area_cm2 / 1e6;
    }
    return litres;
}

TEST(SprayCircuit, SectionValvesOpen200msAfterCommandAndDropletsLand267msAfterIt) {
    // Table 1: t3 = 0.200 s signal -> nozzle open, then 0.067 s fall: 0.267 s to
    // landing, whatever the opening of the proportional valve.
    for (double opening : {87.0, 90.0, 93.0, 94.0, 95.0, 100.0}) {
        SCOPED_TRACE(opening);
        StaticRig rig(quiet_circuit(opening));
        SprayCircuit& circuit = rig.circuit;
        circuit.set_unloading_open(false);
        const TimeNs command = 2 * kS;
        circuit.advance_to(command);
        circuit.set_sections_commanded(0b111);
        circuit.advance_to(command + 199 * kMs);
        EXPECT_EQ(circuit.truth().sections_commanded_mask(), 0b111);
        EXPECT_EQ(circuit.truth().sections_spraying_mask(), 0);
        EXPECT_EQ(circuit.truth().main_flow_l_min(), 0.0);
        EXPECT_EQ(circuit.truth().nozzles_spraying(), 0);
        circuit.advance_to(command + 201 * kMs);
        EXPECT_EQ(circuit.truth().sections_spraying_mask(), 0b111);
        EXPECT_GT(circuit.truth().main_flow_l_min(), 0.0);
        EXPECT_GT(circuit.truth().nozzles_spraying(), 0);
        circuit.advance_to(command + 1 * kS);
        ASSERT_EQ(circuit.landing_edges().size(), 1u);
        EXPECT_TRUE(circuit.landing_edges()[0].landing);
        EXPECT_EQ(circuit.landing_edges()[0].at_ns, command + 267 * kMs);

        // Closing: the valve shuts 0.200 s after the command, the last drops land 0.067 s later.
        const TimeNs close = 3 * kS;
        circuit.advance_to(close);
        circuit.set_sections_commanded(0);
        circuit.advance_to(close + 199 * kMs);
        EXPECT_EQ(circuit.truth().sections_spraying_mask(), 0b111);
        EXPECT_GT(circuit.truth().main_flow_l_min(), 0.0);
        circuit.advance_to(close + 201 * kMs);
        EXPECT_EQ(circuit.truth().sections_spraying_mask(), 0);
        EXPECT_EQ(circuit.truth().main_flow_l_min(), 0.0);  // nowhere to go: the boom line stops at once
        circuit.advance_to(close + 1 * kS);
        ASSERT_EQ(circuit.landing_edges().size(), 2u);
        EXPECT_FALSE(circuit.landing_edges()[1].landing);
        EXPECT_EQ(circuit.landing_edges()[1].at_ns, close + 267 * kMs);
    }
}

TEST(SprayCircuit, CommandBetweenGridStepsActsFromTheStepContainingIt) {
    StaticRig rig(quiet_circuit(95.0));
    rig.circuit.set_unloading_open(false);
    const TimeNs command = 2 * kS + 400'000;  // 2.0004 s, inside the 2.000-2.001 s step
    rig.circuit.advance_to(command);
    rig.circuit.set_sections_commanded(0b111);
    rig.circuit.advance_to(3 * kS);
    ASSERT_EQ(rig.circuit.landing_edges().size(), 1u);
    const TimeNs landing = rig.circuit.landing_edges()[0].at_ns;
    EXPECT_LE(landing, command + 267 * kMs);
    EXPECT_GT(landing, command + 267 * kMs - 1 * kMs);
}

TEST(SprayCircuit, OpenUnloadingValveMeansNoMainFlow) {
    StaticRig rig(quiet_circuit(95.0));
    SprayCircuit& circuit = rig.circuit;
    EXPECT_TRUE(circuit.unloading_open());  // power-on state
    circuit.set_sections_commanded(0b111);
    circuit.advance_to(3 * kS);
    EXPECT_EQ(circuit.truth().sections_spraying_mask(), 0b111);
    EXPECT_EQ(circuit.main_flow_l_min(), 0.0);
    EXPECT_EQ(circuit.main_volume_l(), 0.0);
    EXPECT_EQ(circuit.nozzles_spraying(), 0);
    EXPECT_TRUE(circuit.landing_edges().empty());
    EXPECT_EQ(circuit.deposition().total_volume_l(), 0.0);
    EXPECT_NEAR(circuit.pump_flow_l_min(), 31.1, 1e-12);  // the pump still runs

    circuit.set_unloading_open(false);
    circuit.advance_to(5 * kS);  // 8 time constants
    EXPECT_NEAR(circuit.main_flow_l_min(), 25.5, 0.01);
    circuit.set_unloading_open(true);
    circuit.advance_to(5 * kS + 1 * kMs);
    EXPECT_EQ(circuit.main_flow_l_min(), 0.0);
    EXPECT_EQ(circuit.nozzles_spraying(), 0);
    const double volume = circuit.main_volume_l();
    circuit.advance_to(6 * kS);
    EXPECT_EQ(circuit.main_volume_l(), volume);
    ASSERT_EQ(circuit.landing_edges().size(), 2u);
    EXPECT_FALSE(circuit.landing_edges()[1].landing);
}

TEST(SprayCircuit, PipelineLagReaches63PercentAfterOneTimeConstant) {
    // 95 % at 31.1 L/min: 25.5 L/min settled. The sections open at 1.2 s; after
    // tau = 0.25 s the flow is 25.5 (1 - e^-1) = 16.119, after 2 tau 22.049.
    StaticRig rig(quiet_circuit(95.0));
    SprayCircuit& circuit = rig.circuit;
    circuit.set_unloading_open(false);
    circuit.advance_to(1 * kS);
    circuit.set_sections_commanded(0b111);
    circuit.advance_to(1200 * kMs);
    EXPECT_EQ(circuit.main_flow_l_min(), 0.0);
    circuit.advance_to(1450 * kMs);
    EXPECT_NEAR(circuit.main_flow_l_min(), 25.5 * (1.0 - std::exp(-1.0)), 1e-6);
    circuit.advance_to(1700 * kMs);
    EXPECT_NEAR(circuit.main_flow_l_min(), 25.5 * (1.0 - std::exp(-2.0)), 1e-6);
    circuit.advance_to(4 * kS);
    EXPECT_NEAR(circuit.main_flow_l_min(), 25.5, 1e-3);
    EXPECT_EQ(circuit.valve_opening_pct(), 95.0);  // no relay: the ball did not move
}

// Air in the boom (pipeline_air_l) adds its R C to the lag. Worked by hand for
// 0.13 L and 22 IDK 120-03 nozzles at 20 L/min: 0.909 L/min a nozzle is
// 0.3 MPa x (0.909 / 1.2)^2 = 0.1722 MPa gauge, 0.2735 MPa absolute; R C =
// 2 x 0.13 L x 0.101325 x 0.1722 / (0.2735^2 x 0.3333 L/s) = 0.1819 s.
TEST(SprayCircuit, AirInTheBoomSlowsALowFlowMoreThanAHighOne) {
    StaticRig plant_without_air(quiet_circuit(95.0));
    EXPECT_DOUBLE_EQ(plant_without_air.circuit.pipeline_lag_s(20.0, 22), 0.25);
    EXPECT_DOUBLE_EQ(plant_without_air.circuit.pipeline_lag_s(5.0, 22), 0.25);

    SprayCircuitParams params = quiet_circuit(95.0);
    params.pipeline_time_constant_s = 0.30;
    params.pipeline_air_l = 0.13;
    StaticRig rig(params);
    EXPECT_NEAR(rig.circuit.pipeline_lag_s(20.0, 22), 0.30 + 0.1819, 5e-4);
    // The gas cushion is stiffer at higher pressure: the lag falls as the flow rises
    // (Table 2's trend), and through fewer nozzles the same flow is at a higher pressure.
    EXPECT_GT(rig.circuit.pipeline_lag_s(15.0, 22), rig.circuit.pipeline_lag_s(20.0, 22));
    EXPECT_GT(rig.circuit.pipeline_lag_s(20.0, 22), rig.circuit.pipeline_lag_s(27.0, 22));
    EXPECT_LT(rig.circuit.pipeline_lag_s(20.0, 8), rig.circuit.pipeline_lag_s(20.0, 22));
    // No flow, no resistance to speak of: the lag is the line's own.
    EXPECT_DOUBLE_EQ(rig.circuit.pipeline_lag_s(0.0, 22), 0.30);

    // And the flow follows it: 63 % of the settled 25.5 L/min after one lag.
    SprayCircuit& circuit = rig.circuit;
    const double lag_s = circuit.pipeline_lag_s(25.5, 22);
    circuit.set_unloading_open(false);
    circuit.advance_to(1 * kS);
    circuit.set_sections_commanded(0b111);
    circuit.advance_to(1200 * kMs);
    circuit.advance_to(1200 * kMs + static_cast<rig::TimeNs>(std::llround(lag_s * 1e3)) * kMs);
    EXPECT_NEAR(circuit.main_flow_l_min(), 25.5 * (1.0 - std::exp(-1.0)), 0.05);

    params.pipeline_air_l = -0.1;
    EXPECT_THROW(StaticRig{params}, std::invalid_argument);
}

TEST(SprayCircuit, FlowSplitsOverOpenSectionsAndOnlyTheirNozzlesSpray) {
    // Section b alone: 6 of 22 nozzles, 25.5 x 6 / 22 = 6.9545 L/min, enough for all 6.
    StaticRig rig(quiet_circuit(95.0));
    SprayCircuit& circuit = rig.circuit;
    circuit.set_unloading_open(false);
    circuit.set_sections_commanded(0b010);
    circuit.advance_to(4 * kS);
    EXPECT_NEAR(circuit.main_flow_l_min(), 25.5 * 6.0 / 22.0, 1e-3);
    EXPECT_EQ(circuit.nozzles_spraying(), 6);
    const DepositionGrid& grid = circuit.deposition();
    for (int nozzle = 0; nozzle < 22; ++nozzle) {
        const bool in_b = nozzle >= 8 && nozzle < 14;  // sections of 8, 6, 8 nozzles
        if (in_b) {
            EXPECT_GT(nozzle_litres(grid, 0, nozzle), 0.0) << "nozzle " << nozzle;
        } else {
            EXPECT_EQ(nozzle_litres(grid, 0, nozzle), 0.0) << "nozzle " << nozzle;
        }
    }
}

TEST(SprayCircuit, AtLowFlowOnlyTheNozzlesNearestTheFeedSpray) {
    // 70 %: (70 - 60) / (87 - 60) x 14.2 = 5.259 L/min; at 0.64 L/min per nozzle
    // 8 can spray: the ones nearest the boom centre, nozzles 7-14.
    StaticRig rig(quiet_circuit(70.0));
    SprayCircuit& circuit = rig.circuit;
    circuit.set_unloading_open(false);
    circuit.set_sections_commanded(0b111);
    circuit.advance_to(4 * kS);
    EXPECT_NEAR(circuit.main_flow_l_min(), 14.2 * 10.0 / 27.0, 1e-3);
    EXPECT_EQ(circuit.nozzles_spraying(), 8);
    EXPECT_EQ(circuit.truth().nozzles_spraying(), 8);
    const DepositionGrid& grid = circuit.deposition();
    for (int nozzle = 0; nozzle < 22; ++nozzle) {
        if (nozzle >= 7 && nozzle <= 14) {
            EXPECT_GT(nozzle_litres(grid, 0, nozzle), 0.0) << "nozzle " << nozzle;
        } else {
            EXPECT_EQ(nozzle_litres(grid, 0, nozzle), 0.0) << "nozzle " << nozzle;
        }
    }
}

TEST(SprayCircuit, AllNozzlesSprayFrom87PercentAt31LitresPumpFlow) {
    // Sec. 2.4.1: ">= 87 % ensured full spraying of all nozzles". 14.2 L/min over
    // 22 nozzles is 0.645 L/min each, above 0.64; at 86 % (13.67 L/min) one drops out.
    {
        StaticRig rig(quiet_circuit(87.0));
        rig.circuit.set_unloading_open(false);
        rig.circuit.set_sections_commanded(0b111);
        rig.circuit.advance_to(4 * kS);
        EXPECT_EQ(rig.circuit.nozzles_spraying(), 22);
    }
    {
        StaticRig rig(quiet_circuit(86.0));
        rig.circuit.set_unloading_open(false);
        rig.circuit.set_sections_commanded(0b111);
        rig.circuit.advance_to(4 * kS);
        EXPECT_EQ(rig.circuit.nozzles_spraying(), 21);
    }
    // The default plant (pulsating pump, drifted calibration) at 87, 90 and 95 %:
    // all 22 at every millisecond once the line is full.
    for (double opening : {87.0, 90.0, 95.0}) {
        SprayCircuitParams params;
        params.valve.initial_opening_pct = opening;
        StaticRig rig(params);
        rig.circuit.set_unloading_open(false);
        rig.circuit.set_sections_commanded(0b111);
        rig.circuit.advance_to(3 * kS);
        int fewest = 22;
        for (TimeNs t = 3 * kS; t <= 4 * kS; t += kMs) {
            rig.circuit.advance_to(t);
            fewest = std::min(fewest, rig.circuit.nozzles_spraying());
        }
        EXPECT_EQ(fewest, 22) << opening << " %";
    }
}

TEST(SprayCircuit, StaticSprayPutsItsWholeVolumeInTheFootprint) {
    // Standing with the nozzle line at 0: every nozzle's 0.15 m band covers
    // [-0.075, 0.075), i.e. grid rows between -0.1 and 0.1 m.
    StaticRig rig(quiet_circuit(95.0));
    SprayCircuit& circuit = rig.circuit;
    circuit.set_unloading_open(false);
    circuit.set_sections_commanded(0b111);
    circuit.advance_to(3 * kS);
    circuit.set_sections_commanded(0);
    circuit.advance_to(4 * kS);
    const double volume = circuit.main_volume_l();
    // Open from 0.2 to 3.2 s (both valves take 0.200 s): 3 s at 25.5 L/min less
    // what the lag withholds, tau x 25.5 L/min: 25.5 / 60 x (3.0 - 0.25) = 1.16875 L.
    EXPECT_NEAR(volume, 25.5 / 60.0 * (3.0 - 0.25), 1e-3);
    const DepositionGrid& grid = circuit.deposition();
    EXPECT_NEAR(grid.total_volume_l(), volume, 1e-12 * volume);
    EXPECT_EQ(grid.volume_off_grid_l(), 0.0);
    EXPECT_NEAR(grid_litres(grid, 0), volume, 1e-9 * volume);
    for (std::size_t row = 0; row < grid.row_count(); ++row) {
        const double centre = grid.row_centre_m(row);
        double row_dose = 0.0;
        for (int nozzle = 0; nozzle < 22; ++nozzle) row_dose += grid.dose_ul_cm2(0, row, nozzle);
        if (std::abs(centre) > 0.1) {
            EXPECT_EQ(row_dose, 0.0) << "row at " << centre << " m";
        }
    }
    EXPECT_EQ(grid.pass_count(), 1);
}

TEST(SprayCircuit, SprayOffTheGridIsCountedNotLost) {
    // Nozzle line at 49.95 m: the band [49.875, 50.025) overhangs the grid's end
    // (50 m) by 0.025 of its 0.15 m: one sixth of the volume is off the grid.
    {
        StaticRig rig(quiet_circuit(95.0), 49.95);
        rig.circuit.set_unloading_open(false);
        rig.circuit.set_sections_commanded(0b111);
        rig.circuit.advance_to(2 * kS);
        const DepositionGrid& grid = rig.circuit.deposition();
        const double volume = rig.circuit.main_volume_l();
        ASSERT_GT(volume, 0.1);
        EXPECT_NEAR(grid.total_volume_l(), volume, 1e-12 * volume);
        EXPECT_NEAR(grid.volume_off_grid_l(), volume / 6.0, 1e-9 * volume);
        EXPECT_NEAR(grid_litres(grid, 0) + grid.volume_off_grid_l(), volume, 1e-9 * volume);
    }
    {
        StaticRig rig(quiet_circuit(95.0), 60.0);  // wholly beyond the grid
        rig.circuit.set_unloading_open(false);
        rig.circuit.set_sections_commanded(0b111);
        rig.circuit.advance_to(2 * kS);
        const double volume = rig.circuit.main_volume_l();
        ASSERT_GT(volume, 0.1);
        EXPECT_NEAR(rig.circuit.deposition().volume_off_grid_l(), volume, 1e-12 * volume);
        EXPECT_EQ(grid_litres(rig.circuit.deposition(), 0), 0.0);
    }
}

// One actuator script, applied at the same instants; only the instants the
// circuit is queried at in between differ.
struct ScriptStep {
    TimeNs at_ns;
    void (*apply)(SprayCircuit&);
};

const std::vector<ScriptStep>& actuator_script() {
    static const std::vector<ScriptStep> script = {
        {0, [](SprayCircuit& c) { c.set_valve_drive(BallValve::Drive::forward); }},
        {500 * kMs, [](SprayCircuit& c) { c.set_unloading_open(false); }},
        {700 * kMs + 300'000, [](SprayCircuit& c) { c.set_sections_commanded(0b111); }},
        {1900 * kMs, [](SprayCircuit& c) { c.set_valve_drive(BallValve::Drive::off); }},
        {2300 * kMs + 123, [](SprayCircuit& c) { c.set_valve_drive(BallValve::Drive::reverse); }},
        {2700 * kMs, [](SprayCircuit& c) { c.set_valve_drive(BallValve::Drive::off); }},
        {3100 * kMs, [](SprayCircuit& c) { c.set_sections_commanded(0b101); }},
        {3600 * kMs + 999'999, [](SprayCircuit& c) { c.set_sections_commanded(0); }},
    };
    return script;
}

struct Snapshot {
    double main_flow, main_volume, opening, pump_flow, deposited;
    int nozzles;
    std::uint16_t sections_open;
    std::size_t edges;
    bool operator==(const Snapshot&) const = default;
};

Snapshot snapshot(const SprayCircuit& circuit) {
    return {circuit.main_flow_l_min(),
            circuit.main_volume_l(),
            circuit.valve_opening_pct(),
            circuit.pump_flow_l_min(),
            circuit.deposition().total_volume_l(),
            circuit.nozzles_spraying(),
            circuit.sections_open(),
            circuit.landing_edges().size()};
}

// Runs the script, calling advance_to at `query` instants besides the script's own.
std::vector<Snapshot> run_script(const std::vector<TimeNs>& query, const std::vector<TimeNs>& checkpoints) {
    SprayCircuitParams params;  // default plant: pulsation, drift, bulge, start delay, backlash
    params.valve.initial_opening_pct = 88.0;
    StaticRig rig(params);
    std::vector<TimeNs> instants = query;
    for (const ScriptStep& step : actuator_script()) instants.push_back(step.at_ns);
    instants.insert(instants.end(), checkpoints.begin(), checkpoints.end());
    std::sort(instants.begin(), instants.end());
    std::vector<Snapshot> out;
    std::size_t next_step = 0;
    std::size_t next_checkpoint = 0;
    for (TimeNs t : instants) {
        rig.circuit.advance_to(t);
        while (next_step < actuator_script().size() && actuator_script()[next_step].at_ns == t) {
            actuator_script()[next_step++].apply(rig.circuit);
        }
        while (next_checkpoint < checkpoints.size() && checkpoints[next_checkpoint] == t) {
            out.push_back(snapshot(rig.circuit));
            ++next_checkpoint;
        }
    }
    return out;
}

TEST(SprayCircuit, StateAtAnInstantDoesNotDependOnWhenItWasQueried) {
    const std::vector<TimeNs> checkpoints = {1 * kS, 2 * kS + 7, 3 * kS + 500 * kMs, 4 * kS};
    std::vector<TimeNs> every_ms;
    for (TimeNs t = 0; t <= 4 * kS; t += kMs) every_ms.push_back(t);
    std::vector<TimeNs> odd;  // 7.3 ms apart, off the grid
    for (TimeNs t = 0; t <= 4 * kS; t += 7'300'001) odd.push_back(t);
    const auto fine = run_script(every_ms, checkpoints);
    const auto coarse = run_script(odd, checkpoints);
    const auto bare = run_script({}, checkpoints);
    ASSERT_EQ(fine.size(), checkpoints.size());
    ASSERT_EQ(coarse.size(), checkpoints.size());
    ASSERT_EQ(bare.size(), checkpoints.size());
    for (std::size_t i = 0; i < checkpoints.size(); ++i) {
        SCOPED_TRACE(checkpoints[i]);
        EXPECT_TRUE(fine[i] == coarse[i]);
        EXPECT_TRUE(fine[i] == bare[i]);
        // Bit for bit, not approximately.
        EXPECT_EQ(fine[i].main_volume, coarse[i].main_volume);
        EXPECT_EQ(fine[i].opening, bare[i].opening);
    }
    // The script did something: the valve moved and spray landed.
    EXPECT_GT(fine.back().main_volume, 0.0);
    EXPECT_NE(fine.front().opening, 88.0);
}

TEST(SprayCircuit, AdvanceToIntegratesWholeStepsOnly) {
    StaticRig rig(quiet_circuit(95.0));
    rig.circuit.set_unloading_open(false);
    rig.circuit.set_sections_commanded(0b111);
    rig.circuit.advance_to(1 * kS + 999'999);  // still inside the 1.000-1.001 s step
    EXPECT_EQ(rig.circuit.truth().time_ns(), 1 * kS);
    const double volume = rig.circuit.main_volume_l();
    rig.circuit.advance_to(1 * kS + 999'999);
    EXPECT_EQ(rig.circuit.main_volume_l(), volume);
    rig.circuit.advance_to(1 * kS + kMs);
    EXPECT_EQ(rig.circuit.truth().time_ns(), 1 * kS + kMs);
    EXPECT_GT(rig.circuit.main_volume_l(), volume);
}

// ---------------------------------------------------------------- pump-outlet sensor (Eq. 8)

PumpFlowSensorParams noiseless_pump_sensor() {
    PumpFlowSensorParams params;
    params.noise_mv = 0.0;
    params.full_scale_m3_h = 6.0;  // Q_F: 100 L/min
    return params;
}

TEST(PumpFlowSensor, FourToTwentyMilliampsMapOntoZeroTo3V3) {
    StaticRig rig(quiet_circuit(95.0));
    const PumpFlowSensor sensor(rig.circuit, noiseless_pump_sensor());
    EXPECT_EQ(sensor.voltage_for(0.0), 0.0);                // 4 mA
    EXPECT_NEAR(sensor.voltage_for(100.0), 3.3, 1e-12);     // 20 mA at Q_F = 6 m^3/h
    EXPECT_NEAR(sensor.voltage_for(50.0), 1.65, 1e-12);     // 12 mA
    EXPECT_NEAR(sensor.voltage_for(31.1), 1.0263, 1e-12);   // 31.1 / 100 x 3.3
    // The transmitter saturates at its range ends.
    EXPECT_NEAR(sensor.voltage_for(150.0), 3.3, 1e-12);
    EXPECT_EQ(sensor.voltage_for(-10.0), 0.0);
}

TEST(PumpFlowSensor, ZeroErrorShiftsTheCurrentThenSaturates) {
    StaticRig rig(quiet_circuit(95.0));
    PumpFlowSensorParams params = noiseless_pump_sensor();
    params.offset_ma = 1.6;  // a tenth of the span: +0.33 V
    const PumpFlowSensor sensor(rig.circuit, params);
    EXPECT_NEAR(sensor.voltage_for(0.0), 0.33, 1e-12);
    EXPECT_NEAR(sensor.voltage_for(50.0), 1.98, 1e-12);
    EXPECT_NEAR(sensor.voltage_for(95.0), 3.3, 1e-12);  // 20.8 mA clipped to 20
}

TEST(PumpFlowSensor, Eq8RoundTripThroughTheControllerGivesTheFlowBack) {
    StaticRig rig(quiet_circuit(95.0));
    const PumpFlowSensor sensor(rig.circuit, noiseless_pump_sensor());
    for (int tenth = 0; tenth <= 1000; ++tenth) {
        const double flow = tenth / 10.0;
        const double volts = sensor.voltage_for(flow);
        EXPECT_NEAR(rig::controller::pump_flow_l_min_from_voltage(volts, 3.3, 6.0), flow, 1e-9) << flow << " L/min";
    }
}

// ---------------------------------------------------------------- boom height (pull wire)

TEST(BoomHeightSensor, VoltageRoundTripsThroughTheControllerConversion) {
    const Plant plant(standing_plant(0.0));
    const BoomHeightSensor sensor(plant, BoomHeightSensorParams{});  // 1 m at 3.3 V
    EXPECT_EQ(sensor.voltage_for(0.0), 0.0);
    EXPECT_NEAR(sensor.voltage_for(0.5), 1.65, 1e-12);  // the paper's 50 cm boom
    EXPECT_NEAR(sensor.voltage_for(1.0), 3.3, 1e-12);
    EXPECT_NEAR(sensor.voltage_for(1.4), 3.3, 1e-12);   // past the end of the wire
    EXPECT_EQ(sensor.voltage_for(-0.2), 0.0);
    for (int cm = 0; cm <= 100; ++cm) {
        const double rise_m = cm / 100.0;
        EXPECT_NEAR(rig::controller::linkage_rise_m_from_voltage(sensor.voltage_for(rise_m), 3.3, 1.0), rise_m, 1e-12);
    }
    BoomHeightSensorParams short_wire;
    short_wire.range_m = 0.8;
    const BoomHeightSensor short_sensor(plant, short_wire);
    EXPECT_NEAR(rig::controller::linkage_rise_m_from_voltage(short_sensor.voltage_for(0.5), 3.3, 0.8), 0.5, 1e-12);
}

// ---------------------------------------------------------------- panel switch

TEST(PanelSwitch, ClosedFromItsClosureForItsHoldTime) {
    const PanelSwitch button("breakpoint_button", "device/breakpoint_button", {{1.0, 0.2}, {5.0, 0.5}});
    EXPECT_FALSE(button.closed_at(0));
    EXPECT_FALSE(button.closed_at(1 * kS - 1));
    EXPECT_TRUE(button.closed_at(1 * kS));
    EXPECT_TRUE(button.closed_at(1200 * kMs - 1));
    EXPECT_FALSE(button.closed_at(1200 * kMs));
    EXPECT_TRUE(button.closed_at(5200 * kMs));
    EXPECT_FALSE(button.closed_at(5500 * kMs));
    const PanelSwitch at_start("spray_switch", "device/spray_switch", {{0.0, 100.0}});
    EXPECT_TRUE(at_start.closed_at(0));
    EXPECT_TRUE(at_start.closed_at(99 * kS));
    EXPECT_FALSE(at_start.closed_at(100 * kS));
}

}  // namespace
