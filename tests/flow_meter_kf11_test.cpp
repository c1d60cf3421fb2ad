// The KF11-P10 main-pipeline meter emulator (seed 000 sec. 2.1, Eq. 3: 90
// pulses/L, 0.27-14.14 m^3/h) driven by a real SprayCircuit at a steady flow.
// FlowMeterKf11::step() publishes its sample, so each test makes a DdsContext
// (loopback profile, a leased domain): this executable is labelled `dds`.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "emulators/flow_meter_kf11.h"
#include "emulators/plant.h"
#include "emulators/spray_circuit.h"
#include "rig/runtime/dds_context.h"
#include "rig/host/domain_lease.h"

namespace {

using namespace rig::emulators;
using rig::TimeNs;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kS = 1'000'000'000;

// A standing sprayer whose circuit delivers a constant flow: no pump pulsation,
// no drift or bulge, the valve parked at `opening_pct`, everything open from t = 0.
// 95 % at 31.1 L/min pump flow gives 25.5 L/min (emulators/flow_map.h).
struct MeterRig {
    MeterRig(double opening_pct, Kf11Params meter_params)
        : plant(plant_params()), circuit(plant, circuit_params(opening_pct)), meter(circuit, meter_params) {
        meter.configure(dds);
        circuit.set_unloading_open(false);
        circuit.set_sections_commanded(0b111);
    }
    static PlantParams plant_params() {
        PlantParams params;
        params.route = {StandPhase{1000.0}};
        return params;
    }
    static SprayCircuitParams circuit_params(double opening_pct) {
        SprayCircuitParams params;
        params.pump_flow_l_min = 31.1;
        params.pump_pulsation_pct = 0.0;
        params.flow_map.interpolation_bulge_pct = 0.0;
        params.flow_map.calibration_drift_pct = 0.0;
        params.valve.initial_opening_pct = opening_pct;
        params.pipeline_time_constant_s = 0.25;  // the flow is steady to well under 1e-4 by 3 s
        params.pipeline_air_l = 0.0;
        return params;
    }

    struct Sample {
        TimeNs at_ns;
        std::uint32_t count;
        std::uint32_t capture_us;
        double volume_l;
    };
    // Steps the meter on its own schedule (100 Hz) up to `end_ns`, recording each
    // sample; the test is the master here, advancing the plant before the meter
    // samples it.
    std::vector<Sample> run_until(TimeNs end_ns) {
        std::vector<Sample> samples;
        while (next_ns <= end_ns) {
            const TimeNs now = next_ns;
            circuit.advance_to(now);
            next_ns = meter.step(now);
            samples.push_back({now, meter.count(), meter.last_edge_capture_us(), circuit.main_volume_l()});
        }
        return samples;
    }

    rig::DomainLease lease = rig::DomainLease::acquire();
    rig::DdsContext dds{lease.domain_id(), "kf11_test"};
    Plant plant;
    SprayCircuit circuit;
    FlowMeterKf11 meter;
    TimeNs next_ns = 0;
};

// Opening that gives `flow_l_min` below the lowest calibrated opening: the flow
// falls linearly from 14.2 L/min at 87 % to 0 at 60 % (at 31.1 L/min pump flow).
double opening_for_low_flow(double flow_l_min) { return 60.0 + 27.0 * flow_l_min / 14.2; }

TEST(FlowMeterKf11, NinetyPulsesPerLitreOverAKnownVolume) {
    MeterRig rig(95.0, Kf11Params{});
    rig.run_until(3 * kS);  // the line is full (11 time constants)
    const std::uint32_t count0 = rig.meter.count();
    const double volume0 = rig.circuit.main_volume_l();
    rig.run_until(13 * kS);
    const double litres = rig.circuit.main_volume_l() - volume0;
    EXPECT_NEAR(litres, 25.5 / 6.0, 1e-3);  // 10 s at 25.5 L/min
    const double pulses = static_cast<double>(rig.meter.count() - count0);
    EXPECT_NEAR(pulses, 90.0 * litres, 1.0);  // 382.5: whole pulses only
}

TEST(FlowMeterKf11, KFactorErrorChangesThePulsesPerLitre) {
    for (double error_pct : {2.0, -5.0}) {
        SCOPED_TRACE(error_pct);
        Kf11Params params;
        params.k_factor_error_pct = error_pct;
        MeterRig rig(95.0, params);
        rig.run_until(3 * kS);
        const std::uint32_t count0 = rig.meter.count();
        const double volume0 = rig.circuit.main_volume_l();
        rig.run_until(13 * kS);
        const double litres = rig.circuit.main_volume_l() - volume0;
        const double pulses = static_cast<double>(rig.meter.count() - count0);
        // +2 %: 91.8 /L, 390.2 pulses for 4.25 L; -5 %: 85.5 /L, 363.4 pulses.
        EXPECT_NEAR(pulses, 90.0 * (1.0 + error_pct / 100.0) * litres, 1.0);
        EXPECT_GT(std::abs(pulses - 90.0 * litres), 5.0);  // distinguishable from the nameplate (7.65 at +2 %)
    }
}

TEST(FlowMeterKf11, TurbineStallsBelow4Point5LitresPerMinute) {
    // 0.27 m^3/h = 4.5 L/min. At 4.3 L/min the water passes uncounted.
    {
        MeterRig rig(opening_for_low_flow(4.3), Kf11Params{});
        rig.run_until(20 * kS);
        EXPECT_NEAR(rig.circuit.main_flow_l_min(), 4.3, 1e-6);
        EXPECT_GT(rig.circuit.main_volume_l(), 1.3);  // about 1.4 L went through
        EXPECT_EQ(rig.meter.count(), 0u);
    }
    // At 4.7 L/min it turns and counts 90 /L.
    {
        MeterRig rig(opening_for_low_flow(4.7), Kf11Params{});
        rig.run_until(5 * kS);
        const std::uint32_t count0 = rig.meter.count();
        const double volume0 = rig.circuit.main_volume_l();
        rig.run_until(20 * kS);
        EXPECT_NEAR(rig.circuit.main_flow_l_min(), 4.7, 1e-6);
        const double litres = rig.circuit.main_volume_l() - volume0;
        EXPECT_NEAR(static_cast<double>(rig.meter.count() - count0), 90.0 * litres, 1.0);
        EXPECT_GT(rig.meter.count() - count0, 100u);
    }
}

TEST(FlowMeterKf11, LastEdgeCaptureLiesInTheLastSampleIntervalAndMatchesTheFlow) {
    MeterRig rig(95.0, Kf11Params{});
    rig.run_until(3 * kS);
    const auto samples = rig.run_until(13 * kS);
    ASSERT_GT(samples.size(), 900u);
    // 25.5 L/min x 90 /L = 38.25 pulses/s: an edge every 26143.8 us.
    const double us_per_pulse = 1e6 / (25.5 * 90.0 / 60.0);
    std::vector<std::size_t> changed;
    for (std::size_t i = 1; i < samples.size(); ++i) {
        if (samples[i].count == samples[i - 1].count) {
            EXPECT_EQ(samples[i].capture_us, samples[i - 1].capture_us) << "no edge, yet the capture moved";
            continue;
        }
        changed.push_back(i);
        // The capture timer (1 MHz) holds the last edge's instant, inside (previous sample, this sample].
        const std::uint64_t from_us = static_cast<std::uint64_t>(samples[i - 1].at_ns / 1000);
        const std::uint64_t to_us = static_cast<std::uint64_t>(samples[i].at_ns / 1000);
        EXPECT_GE(samples[i].capture_us, from_us) << "at " << samples[i].at_ns;
        EXPECT_LE(samples[i].capture_us, to_us) << "at " << samples[i].at_ns;
    }
    ASSERT_GT(changed.size(), 300u);
    // Edge to edge, the capture times are one pulse period apart (to the 1 us tick).
    for (std::size_t k = 1; k < changed.size(); ++k) {
        const auto& a = samples[changed[k - 1]];
        const auto& b = samples[changed[k]];
        const double expected_us = us_per_pulse * static_cast<double>(b.count - a.count);
        EXPECT_NEAR(static_cast<double>(b.capture_us - a.capture_us), expected_us, 2.0) << "at " << b.at_ns;
    }
    // And Eq. 3 over the captured edges gives the flow back: 60 w / (90 t2).
    const auto& first = samples[changed.front()];
    const auto& last = samples[changed.back()];
    const double t2_s = static_cast<double>(last.capture_us - first.capture_us) * 1e-6;
    EXPECT_NEAR(60.0 * static_cast<double>(last.count - first.count) / (90.0 * t2_s), 25.5, 0.005);
}

// The meter samples the plant; it never moves the plant's time. Stepped at an
// instant the plant was not advanced to (by the master, rig/runtime/node.h
// TruthModel; by run_until here) it would read the past, so it refuses, naming
// itself and both instants, and counts nothing.
TEST(FlowMeterKf11, RefusesToSampleAPlantNotAdvancedToItsInstant) {
    MeterRig rig(95.0, Kf11Params{});
    rig.run_until(1 * kS);
    const std::uint32_t counted = rig.meter.count();
    ASSERT_GT(counted, 0u);
    try {
        rig.meter.step(1 * kS + 10 * kMs);
        FAIL() << "stepped at an instant the plant was not advanced to";
    } catch (const std::logic_error& error) {
        const std::string what = error.what();
        EXPECT_NE(what.find("main_flow_meter"), std::string::npos) << what;
        EXPECT_NE(what.find("t=1.010000 s"), std::string::npos) << what;
        EXPECT_NE(what.find("t=1.000000 s"), std::string::npos) << what;
    }
    EXPECT_EQ(rig.meter.count(), counted);
    EXPECT_EQ(rig.circuit.advanced_to_ns(), 1 * kS);
}

}  // namespace
