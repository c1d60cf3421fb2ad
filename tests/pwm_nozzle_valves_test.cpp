// Seed 001's six PWM nozzle valves (emulators/pwm_nozzle_valves.h): 9 Hz PWM
// (Sec. 3.2.1), 10-20 ms response (Table 1), flow per duty from Table 3.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "emulators/field2d/nozzle_flow_table.h"
#include "emulators/pwm_nozzle_valves.h"

namespace {

using rig::TimeNs;
using rig::seconds_to_ns;
using rig::emulators::PwmNozzleValves;
using rig::emulators::PwmValveParams;
using rig::field2d::NozzleFlowTable;

PwmNozzleValves paper_valves(bool latched = true, double response_s = 0.015) {
    PwmValveParams p;
    p.latch_at_period_start = latched;
    p.response_s = response_s;
    p.pwm_phase_s = 0.0;  // periods start at t = 0: the hand-worked edges below
    return PwmNozzleValves(p, NozzleFlowTable::paper_table3());
}

TEST(PwmNozzleValves, OneMinuteAtEachDutyDeliversTable3) {
    // The paper's calibration (Sec. 3.2.1): 1 min per duty, measured per nozzle.
    const NozzleFlowTable table = NozzleFlowTable::paper_table3();
    for (double duty : {100.0, 90.0, 80.0, 70.0, 60.0, 50.0, 40.0, 30.0, 35.0}) {
        SCOPED_TRACE(duty);
        PwmNozzleValves valves = paper_valves();
        for (int n = 0; n < 6; ++n) valves.command(n, duty, 0);
        const std::vector<double> litres = valves.advance(seconds_to_ns(60.0));
        if (duty == 100.0) {
            // The start-up stroke exactly: 610 x (60 - 0.0075) / 60 for nozzle 0.
            EXPECT_NEAR(litres[0] * 1000.0, 610.0 * (60.0 - 0.0075) / 60.0, 1e-9);
        }
        for (int n = 0; n < 6; ++n) {
            const double ml_min = litres[static_cast<std::size_t>(n)] * 1000.0;
            // 540 whole periods; only the first stroke differs from the steady
            // state: the valve starts closed, so at 100 % the first 15 ms open
            // at half flow on average, 7.5 ms of 60 s short (0.0125 %); less at
            // 90 % (the steady state starts part open), none below.
            EXPECT_NEAR(ml_min, table.flow_ml_min(n, duty), 0.0002 * table.flow_ml_min(n, duty))
                << "nozzle " << n << " at " << duty << " %";
        }
    }
}

TEST(PwmNozzleValves, PulseShapeFollowsTheStroke) {
    // 40 %, 9 Hz: on for 44.44 ms of 111.11 ms; 15 ms stroke. Nozzle 0 delivers
    // Table 3's 390 mL/min on average, so 390 / 0.4 = 975 mL/min while open.
    PwmNozzleValves valves = paper_valves();
    valves.command(0, 40.0, 0);
    const auto opening_at = [&](double t_s) {
        valves.advance(seconds_to_ns(t_s));
        return valves.opening(0);
    };
    EXPECT_NEAR(opening_at(0.0075), 0.5, 1e-9);   // half way up after 7.5 ms
    EXPECT_NEAR(opening_at(0.0150), 1.0, 1e-9);   // open after 15 ms
    EXPECT_NEAR(valves.flow_ml_min(0), 975.0, 1e-9);
    EXPECT_NEAR(opening_at(0.0400), 1.0, 1e-9);
    const double fall_s = 0.4 / 9.0;              // 44.44 ms
    EXPECT_NEAR(opening_at(fall_s + 0.0075), 0.5, 1e-6);
    EXPECT_NEAR(opening_at(fall_s + 0.0150), 0.0, 1e-6);
    EXPECT_EQ(opening_at(0.1100), 0.0);
    EXPECT_NEAR(opening_at(1.0 / 9.0 + 0.0030), 0.2, 1e-6);  // the next pulse: 3 ms into it
}

TEST(PwmNozzleValves, ANewDutyWaitsForTheNextPeriodUnlessUnlatched) {
    // Command 100 % at 50 ms, inside period 0 (0-111 ms) at 0 %.
    PwmNozzleValves latched = paper_valves(true, 0.0);
    latched.command(1, 100.0, seconds_to_ns(0.050));
    latched.advance(seconds_to_ns(0.100));
    EXPECT_EQ(latched.opening(1), 0.0);
    EXPECT_EQ(latched.delivered_l(1), 0.0);
    latched.advance(seconds_to_ns(0.200));
    // Open from 1/9 s: (0.2 - 0.111111) s x 610 mL/min.
    EXPECT_NEAR(latched.delivered_l(1) * 60000.0, (0.2 - 1.0 / 9.0) * 610.0, 1e-9);

    PwmNozzleValves immediate = paper_valves(false, 0.0);
    immediate.command(1, 100.0, seconds_to_ns(0.050));
    immediate.advance(seconds_to_ns(0.100));
    EXPECT_NEAR(immediate.delivered_l(1) * 60000.0, 0.050 * 610.0, 1e-9);
}

TEST(PwmNozzleValves, TurningOffAfterFullFlowClosesAtTheNextPeriodThenStrokes) {
    // 100 % from 0; 0 % commanded at 1.02 s; the period starting at 10/9 s =
    // 1.111111 s latches it; the valve closes over 15 ms, delivering half of it:
    // after 1.02 s: (1.111111 - 1.02 + 0.0075) s x 610 mL/min.
    PwmNozzleValves valves = paper_valves();
    valves.command(0, 100.0, 0);
    valves.advance(seconds_to_ns(1.02));
    const double before_l = valves.delivered_l(0);
    valves.command(0, 0.0, seconds_to_ns(1.02));
    valves.advance(seconds_to_ns(2.0));
    EXPECT_NEAR((valves.delivered_l(0) - before_l) * 60000.0, (10.0 / 9.0 - 1.02 + 0.0075) * 610.0, 1e-6);
    EXPECT_EQ(valves.opening(0), 0.0);
    EXPECT_EQ(valves.active_duty_pct(0), 0.0);
}

TEST(PwmNozzleValves, BelowTheTableTheMeanFallsWithTheOpenTime) {
    // 10 %: an 11.1 ms pulse against a 15 ms stroke never opens fully: open
    // time per period on^2 / tau = 0.011111^2 / 0.015 = 8.230 ms; at the open
    // flow of the 30 % point (350 / 0.3 = 1166.7 mL/min for nozzle 0) the mean
    // is 1166.7 x 8.230 / 111.11 = 86.42 mL/min.
    PwmNozzleValves valves = paper_valves();
    EXPECT_NEAR(valves.mean_flow_ml_min(0, 10.0), 86.42, 0.01);
    valves.command(0, 10.0, 0);
    EXPECT_NEAR(valves.advance(seconds_to_ns(60.0))[0] * 1000.0, 86.42, 0.01);
    EXPECT_EQ(valves.mean_flow_ml_min(0, 0.0), 0.0);
}

TEST(PwmNozzleValves, HowTimeIsCutDoesNotChangeTheVolume) {
    const auto run = [](const std::vector<double>& stops) {
        PwmNozzleValves valves = paper_valves();
        valves.command(2, 40.0, 0);
        valves.command(3, 100.0, 0);
        double t = 0.0;
        for (double stop : stops) {
            if (t < 1.0 && stop >= 1.0) {
                valves.advance(seconds_to_ns(1.0));
                valves.command(2, 100.0, seconds_to_ns(1.0));
                valves.command(3, 0.0, seconds_to_ns(1.0));
            }
            valves.advance(seconds_to_ns(stop));
            t = stop;
        }
        return std::vector<double>{valves.delivered_l(2), valves.delivered_l(3)};
    };
    std::vector<double> fine;
    for (int k = 1; k <= 3000; ++k) fine.push_back(k * 0.001);
    const std::vector<double> a = run({3.0});
    const std::vector<double> b = run(fine);
    const std::vector<double> c = run({0.0371, 0.5, 0.99, 1.5, 2.2222, 3.0});
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_NEAR(a[i], b[i], 1e-12 * a[i]);
        EXPECT_NEAR(a[i], c[i], 1e-12 * a[i]);
        EXPECT_GT(a[i], 0.0);
    }
}

TEST(PwmNozzleValves, PwmPhaseComesFromTheSeedUnlessGiven) {
    const auto phase = [](std::uint64_t seed) {
        PwmValveParams p;
        p.seed = seed;
        return PwmNozzleValves(p, NozzleFlowTable::paper_table3()).pwm_phase_s();
    };
    EXPECT_EQ(phase(1), phase(1));
    EXPECT_NE(phase(1), phase(2));
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
        EXPECT_GE(phase(seed), 0.0);
        EXPECT_LT(phase(seed), 1.0 / 9.0);
    }
    // With a phase of 50 ms, the first whole period starts at 50 ms: a 100 %
    // commanded at 0 waits for it (the period before, from -61 ms, latched 0 %).
    PwmValveParams p;
    p.pwm_phase_s = 0.05;
    p.response_s = 0.0;
    PwmNozzleValves valves(p, NozzleFlowTable::paper_table3());
    valves.command(0, 100.0, 0);
    valves.advance(seconds_to_ns(0.05));
    EXPECT_EQ(valves.delivered_l(0), 0.0);
    valves.advance(seconds_to_ns(0.15));
    EXPECT_NEAR(valves.delivered_l(0) * 60000.0, 0.1 * 610.0, 1e-9);
}

TEST(PwmNozzleValves, BadParametersAndCommandsAreRejected) {
    const auto make = [](PwmValveParams p) { return PwmNozzleValves(p, NozzleFlowTable::paper_table3()); };
    PwmValveParams p;
    p.frequency_hz = 0.0;
    EXPECT_THROW(make(p), std::invalid_argument);
    p = PwmValveParams{};
    p.response_s = 0.06;  // half of a 9 Hz period is 55.6 ms
    try {
        make(p);
        ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("response_s"), std::string::npos);
    }
    p = PwmValveParams{};
    p.pwm_phase_s = 0.2;
    EXPECT_THROW(make(p), std::invalid_argument);
    EXPECT_THROW(PwmNozzleValves(PwmValveParams{}, NozzleFlowTable({{{30, 300}, {90, 600}}})), std::invalid_argument);

    PwmNozzleValves valves = paper_valves();
    EXPECT_THROW(valves.command(0, 120.0, 0), std::invalid_argument);
    EXPECT_THROW(valves.command(0, NAN, 0), std::invalid_argument);
    EXPECT_THROW(valves.command(6, 50.0, 0), std::invalid_argument);
    valves.advance(seconds_to_ns(1.0));
    EXPECT_THROW(valves.command(0, 50.0, seconds_to_ns(0.5)), std::logic_error);
    EXPECT_THROW(valves.advance(seconds_to_ns(0.5)), std::logic_error);
}

}  // namespace
