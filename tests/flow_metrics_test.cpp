// The harness's flow and deposition metrics (docs/metrics.md; seed 000 Table 2,
// 5, 6 and Eq. 10-12) on hand-built truth with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <cstdint>
#include <vector>

#include "emulators/field_frame.h"
#include "harness/systems/breakpoint/breakpoint_metrics.h"

namespace {

using rig::TimeNs;
using rig::harness::AreaSpan;
using rig::harness::DepositionJudging;
using rig::harness::DoseProfile;
using rig::harness::FlowJudging;
using rig::harness::FlowReading;
using rig::harness::FlowWindow;
using rig::harness::HydraulicsSample;
using rig::harness::MetricSet;
using rig::harness::SectionCommand;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kS = 1'000'000'000;

// Truth samples every 10 ms over [from, to): the flow given by `flow(t)`, the
// section valves physically open from `open_from` (Table 1: 0.2 s after the
// command) while `open(t)`.
std::vector<HydraulicsSample> sampled(TimeNs from, TimeNs to, const std::function<double(TimeNs)>& flow,
                                      const std::function<bool(TimeNs)>& open) {
    std::vector<HydraulicsSample> samples;
    for (TimeNs t = from; t < to; t += 10 * kMs) {
        samples.push_back({t, flow(t), static_cast<std::uint16_t>(open(t) ? 7 : 0)});
    }
    return samples;
}
// Valves open from 1.2 s on (commanded at 1 s).
std::vector<HydraulicsSample> sampled(TimeNs from, TimeNs to, const std::function<double(TimeNs)>& flow) {
    return sampled(from, to, flow, [](TimeNs t) { return t >= 1200 * kMs; });
}

double at(const std::map<std::string, double>& metrics, const std::string& name) {
    const auto it = metrics.find(name);
    if (it == metrics.end()) {
        ADD_FAILURE() << "metric " << name << " missing";
        return std::nan("");
    }
    return it->second;
}
double at(const MetricSet& metrics, const std::string& name) { return at(metrics.values, name); }

// Sections commanded open at 1 s; the judged window ends at 5 s.
const std::vector<SectionCommand> kOpenAtOne{{0, 0}, {1 * kS, 7}};
const FlowWindow kWindow{500 * kMs, 5 * kS};

MetricSet flow(const std::vector<HydraulicsSample>& samples, const std::vector<SectionCommand>& commands = kOpenAtOne,
               const std::vector<FlowReading>& kf11 = {}) {
    return rig::harness::flow_metrics(samples, commands, kf11, kWindow, FlowJudging{20.0, 3.0, 1.7}).metrics;
}

// ---------------------------------------------------------------- flow_metrics

TEST(FlowMetrics, StepOntoTargetGivesItsAdjustTimeFromTheNozzlesAndFromTheCommand) {
    // Near Table 2's mean (1.359 s): the flow jumps onto 20 L/min at 2.56 s; the
    // nozzles started at 1.2 s (open command 1 s).
    const auto metrics = flow(sampled(0, 6 * kS, [](TimeNs t) { return t >= 2560 * kMs ? 20.0 : 0.0; }));
    EXPECT_EQ(at(metrics, "flow_settled"), 1.0);
    EXPECT_NEAR(at(metrics, "flow_adjust_time_s"), 1.36, 1e-12);  // judged: sec. 3.1.2 "from nozzle start"
    EXPECT_NEAR(at(metrics, "flow_adjust_time_from_command_s"), 1.56, 1e-12);
    EXPECT_EQ(at(metrics, "flow_error_pct"), 0.0);
    EXPECT_EQ(at(metrics, "flow_mean_l_min"), 20.0);
    EXPECT_TRUE(metrics.not_measured.empty());
}

TEST(FlowMetrics, EnteringTheBandCountsNotReachingTheTarget) {
    // 19.5 L/min is inside +-3 % (19.4-20.6): settled from there on; error 2.5 %.
    const auto metrics = flow(sampled(0, 6 * kS, [](TimeNs t) { return t >= 2200 * kMs ? 19.5 : 10.0; }));
    EXPECT_NEAR(at(metrics, "flow_adjust_time_s"), 1.0, 1e-12);
    EXPECT_NEAR(at(metrics, "flow_error_pct"), 2.5, 1e-9);
    EXPECT_NEAR(at(metrics, "flow_mean_l_min"), 19.5, 1e-9);
}

TEST(FlowMetrics, LeavingTheBandRestartsTheSettling) {
    // On target at 2.0 s, out (21 L/min, +5 %) from 3.00 to 3.10 s, back for good at 3.10 s.
    const auto metrics = flow(sampled(0, 6 * kS, [](TimeNs t) {
        if (t < 2 * kS) return 0.0;
        if (t >= 3 * kS && t < 3100 * kMs) return 21.0;
        return 20.0;
    }));
    EXPECT_EQ(at(metrics, "flow_settled"), 1.0);
    EXPECT_NEAR(at(metrics, "flow_adjust_time_s"), 1.9, 1e-12);
    // The flow was due to be steady 1.7 s after the nozzles started (2.9 s): the
    // excursion after that counts in the error (10 samples of 5 % in 210).
    EXPECT_NEAR(at(metrics, "flow_error_pct"), 10 * 5.0 / 210.0, 1e-9);
}

TEST(FlowMetrics, NeverSettlingIsNotMeasuredWithTheReasonNeverASmallNumber) {
    // 25 L/min throughout (+25 %): never in the band.
    const auto metrics = flow(sampled(0, 6 * kS, [](TimeNs t) { return t >= 1200 * kMs ? 25.0 : 0.0; }));
    EXPECT_EQ(at(metrics, "flow_settled"), 0.0);
    EXPECT_EQ(metrics.values.count("flow_adjust_time_s"), 0u);
    EXPECT_EQ(metrics.values.count("flow_adjust_time_from_command_s"), 0u);
    ASSERT_EQ(metrics.not_measured.count("flow_adjust_time_s"), 1u);
    EXPECT_NE(metrics.not_measured.at("flow_adjust_time_s").find("never settled"), std::string::npos);
    // The error still counts from when the flow was due to be steady: 25 %.
    EXPECT_NEAR(at(metrics, "flow_error_pct"), 25.0, 1e-9);
    // Leaving the band in the window's last sample also counts as not settled.
    const auto late = flow(sampled(0, 6 * kS, [](TimeNs t) { return t >= 4990 * kMs ? 30.0 : 20.0; }));
    EXPECT_EQ(at(late, "flow_settled"), 0.0);
}

TEST(FlowMetrics, SectionsThatNeverOpenLeaveNothingToMeasure) {
    const auto metrics = flow(sampled(0, 6 * kS, [](TimeNs) { return 0.0; }, [](TimeNs) { return false; }),
                              {{0, 0}});
    EXPECT_EQ(at(metrics, "flow_settled"), 0.0);
    for (const char* name : {"flow_adjust_time_s", "flow_adjust_time_from_command_s", "flow_error_pct"}) {
        ASSERT_EQ(metrics.not_measured.count(name), 1u) << name;
        EXPECT_NE(metrics.not_measured.at(name).find("never opened"), std::string::npos) << name;
    }
}

TEST(FlowMetrics, FlickeringSectionsNeverSettle) {
    // The sections chatter: commanded shut for 50 ms every 0.5 s; each time the
    // valves shut (0.2 s later), the boom line empties and refills over 0.8 s.
    std::vector<SectionCommand> commands{{0, 0}, {1 * kS, 7}};
    for (TimeNs t = 1500 * kMs; t < 5 * kS; t += 500 * kMs) {
        commands.push_back({t, 0});
        commands.push_back({t + 50 * kMs, 7});
    }
    auto shut = [](TimeNs t) {  // valves shut 50 ms, 0.2 s after each drop
        if (t < 1700 * kMs) return t < 1200 * kMs;
        return (t - 1700 * kMs) % (500 * kMs) < 50 * kMs;
    };
    auto refill = [&](TimeNs t) {
        if (t < 1200 * kMs) return 0.0;
        const TimeNs since_shut = t < 1700 * kMs ? t - 1200 * kMs : (t - 1700 * kMs) % (500 * kMs) - 50 * kMs;
        return since_shut < 0 ? 0.0 : 20.0 * std::min(1.0, static_cast<double>(since_shut) / (800.0 * kMs));
    };
    const auto metrics =
        flow(sampled(0, 6 * kS, [&](TimeNs t) { return shut(t) ? 0.0 : refill(t); }, [&](TimeNs t) { return !shut(t); }),
             commands);
    EXPECT_EQ(at(metrics, "flow_settled"), 0.0);
    ASSERT_EQ(metrics.not_measured.count("flow_adjust_time_s"), 1u);
    EXPECT_NE(metrics.not_measured.at("flow_adjust_time_s").find("started 8 times"), std::string::npos)
        << metrics.not_measured.at("flow_adjust_time_s");
    EXPECT_EQ(at(metrics, "flow_nozzle_starts_count"), 8.0);
    EXPECT_GT(at(metrics, "flow_error_pct"), 3.0);
}

TEST(FlowMetrics, ACommandBlipTooShortForTheValvesIsNoRestart) {
    // Open at 1 s, a 20 ms drop at 2 s that the valves (0.2 s dead time, nominal)
    // never act on here: the flow was on target from 2.5 s and stays; the
    // adjust time counts from the real start (1.2 s), not from the blip.
    const std::vector<SectionCommand> commands{{0, 0}, {1 * kS, 7}, {2 * kS, 0}, {2020 * kMs, 7}};
    const auto metrics = flow(sampled(0, 6 * kS, [](TimeNs t) { return t >= 2500 * kMs ? 20.0 : 0.0; }), commands);
    EXPECT_NEAR(at(metrics, "flow_adjust_time_s"), 1.3, 1e-12);
    EXPECT_NEAR(at(metrics, "flow_adjust_time_from_command_s"), 1.5, 1e-12);
    EXPECT_EQ(metrics.values.count("flow_nozzle_starts_count"), 0u);
}

TEST(FlowMetrics, ARealRestartTimesTheAdjustmentFromTheLastStart) {
    // Open 1 s, shut 2.5-2.9 s (valves 2.7-3.1 s), open again: the flow refills
    // and settles at 4.0 s; the last start was at 3.1 s: 0.9 s.
    const std::vector<SectionCommand> commands{{0, 0}, {1 * kS, 7}, {2500 * kMs, 0}, {2900 * kMs, 7}};
    const auto metrics = flow(
        sampled(0, 6 * kS, [](TimeNs t) { return t >= 4 * kS ? 20.0 : (t >= 2 * kS && t < 2700 * kMs ? 20.0 : 5.0); },
                [](TimeNs t) { return t >= 1200 * kMs && !(t >= 2700 * kMs && t < 3100 * kMs); }),
        commands);
    EXPECT_NEAR(at(metrics, "flow_adjust_time_s"), 0.9, 1e-12);
    EXPECT_NEAR(at(metrics, "flow_adjust_time_from_command_s"), 1.1, 1e-12);
    EXPECT_EQ(at(metrics, "flow_nozzle_starts_count"), 2.0);
}

TEST(FlowMetrics, FlowErrorIsTheMeanRelativeDeviationAfterSettling) {
    // Settled at 2 s; then alternately 20.4 (+2 %) and 19.8 (-1 %): mean 1.5 %, mean
    // flow 20.1. Outside the window (before the opening, at and after its end) wild values must not count.
    const auto metrics = flow(sampled(0, 7 * kS, [](TimeNs t) {
        if (t < 1 * kS || t >= 5 * kS) return 100.0;
        if (t < 2 * kS) return 0.0;
        return (t / (10 * kMs)) % 2 == 0 ? 20.4 : 19.8;
    }));
    EXPECT_NEAR(at(metrics, "flow_adjust_time_s"), 0.8, 1e-12);
    EXPECT_NEAR(at(metrics, "flow_error_pct"), 1.5, 1e-9);
    EXPECT_NEAR(at(metrics, "flow_mean_l_min"), 20.1, 1e-9);
}

TEST(FlowMetrics, FlowErrorIsRelativeToTheTarget) {
    // Table 5 at 3 km/h: 19.58 L/min against 20 is 2.1 % of the target (2.145 % of
    // the measured flow). The paper prints -2.08 %, presumably from unrounded means.
    const auto metrics = flow(sampled(0, 6 * kS, [](TimeNs t) { return t >= 2 * kS ? 19.58 : 0.0; }));
    EXPECT_NEAR(at(metrics, "flow_error_pct"), 2.1, 1e-9);
}

TEST(FlowMetrics, Kf11ReadingsGiveThePapersSignedError) {
    // The meter reads 19.58 L/min from 2 s on (the controller's own readings,
    // Table 5's way): -2.1 % over the settled stretch; from the nozzles' start
    // (1.2 s) the zeros of the filling line count too.
    std::vector<FlowReading> kf11;
    for (TimeNs t = 0; t < 6 * kS; t += 10 * kMs) kf11.push_back({t, t >= 2 * kS ? 19.58 : 0.0});
    const auto metrics = flow(sampled(0, 6 * kS, [](TimeNs t) { return t >= 2 * kS ? 20.0 : 0.0; }), kOpenAtOne, kf11);
    EXPECT_NEAR(at(metrics, "flow_error_kf11_settled_signed_pct"), -2.1, 1e-9);
    EXPECT_NEAR(at(metrics, "flow_error_kf11_signed_pct"), 100.0 * (300 * 19.58 / 380.0 - 20.0) / 20.0, 1e-9);
}

TEST(Kf11Readings, Eq3OnTheRecordedCountsAndCaptureTimes) {
    // 90 pulses/L at 20 L/min: 30 pulses/s, an edge every 33 333 us; samples every 10 ms.
    std::vector<rig::harness::FlowMeterCountSample> samples;
    for (TimeNs t = 0; t <= 2 * kS; t += 10 * kMs) {
        const auto edges = static_cast<std::uint32_t>(t / 33'333'333);
        samples.push_back({t, edges, edges * 33'333u});
    }
    const auto readings = rig::harness::kf11_readings(samples, 90.0, 0.25);
    ASSERT_EQ(readings.size(), samples.size());
    // Over the last edges' spacing: 60 w / (k t2) with t2 from the capture timer.
    EXPECT_NEAR(readings.back().flow_l_min, 20.0, 0.01);
    // Counter and capture timer wrap: unsigned differences carry across.
    std::vector<rig::harness::FlowMeterCountSample> wrapped;
    for (const auto& sample : samples) {
        wrapped.push_back({sample.t_ns, sample.count_pulses - 20u, sample.last_edge_capture_us - 500'000u});
    }
    EXPECT_NEAR(rig::harness::kf11_readings(wrapped, 90.0, 0.25).back().flow_l_min, 20.0, 0.01);
    // No new edge for more than two windows: the flow has stopped.
    samples.push_back({3 * kS, samples.back().count_pulses, samples.back().last_edge_capture_us});
    EXPECT_EQ(rig::harness::kf11_readings(samples, 90.0, 0.25).back().flow_l_min, 0.0);
}

// Fig. 12's "does it oscillate": the band exits after the flow first came in,
// and the last 3 s's peak-to-peak (the window ends at 5 s: from 2 s on).
TEST(FlowMetrics, AFlowThatComesInAndStaysNeverLeavesTheBandAndBarelySwings) {
    const auto metrics = flow(sampled(0, 6 * kS, [](TimeNs t) {
        if (t < 1500 * kMs) return 0.0;
        return 20.0 + ((t / (10 * kMs)) % 2 == 0 ? 0.05 : -0.05);  // ripple of 0.1 L/min
    }));
    EXPECT_EQ(at(metrics, "flow_band_exits_count"), 0.0);
    EXPECT_NEAR(at(metrics, "flow_oscillation_pct"), 0.5, 1e-9);
}

TEST(FlowMetrics, APreAdjustmentThatOvershootsAndIsTrimmedLeavesTheBandOnce) {
    // Filling passes through the band, overshoots to 22 (10 % high), trimmed back by 3 s.
    const auto metrics = flow(sampled(0, 6 * kS, [](TimeNs t) {
        if (t < 1500 * kMs) return 0.0;
        if (t < 1700 * kMs) return 20.0;
        if (t < 3 * kS) return 22.0;
        return 20.0;
    }));
    EXPECT_EQ(at(metrics, "flow_band_exits_count"), 1.0);
    EXPECT_NEAR(at(metrics, "flow_oscillation_pct"), 10.0, 1e-9);  // 22 -> 20 lies in the last 3 s
    EXPECT_NEAR(at(metrics, "flow_adjust_time_s"), 1.8, 1e-9);
}

TEST(FlowMetrics, ASustainedOscillationLeavesTheBandEverySwingAndNeverSettles) {
    // +-2 L/min about the target, period 1 s, from 1.75 s on: out of the band twice a period.
    const auto metrics = flow(sampled(0, 6 * kS, [](TimeNs t) {
        if (t < 1750 * kMs) return 0.0;
        const double phase = 2.0 * M_PI * static_cast<double>(t - 1750 * kMs) / static_cast<double>(kS);
        return 20.0 + 2.0 * std::sin(phase);
    }));
    // In the band from 1.75 s, out at each crest and trough (2.0, 2.5, ... 5.0 s): 7 exits.
    EXPECT_EQ(at(metrics, "flow_band_exits_count"), 7.0);
    EXPECT_NEAR(at(metrics, "flow_oscillation_pct"), 20.0, 0.1);
    EXPECT_EQ(at(metrics, "flow_settled"), 0.0);
    EXPECT_EQ(metrics.not_measured.count("flow_adjust_time_s"), 1u);
}

TEST(FlowMetrics, NoOscillationFigureUnlessTheNozzlesSprayedThroughTheLastSeconds) {
    // The sections shut at 4 s, inside the last 3 s of the window.
    const auto metrics = flow(sampled(0, 6 * kS, [](TimeNs t) { return t >= 1500 * kMs && t < 4 * kS ? 20.0 : 0.0; },
                                      [](TimeNs t) { return t >= 1200 * kMs && t < 4 * kS; }));
    EXPECT_EQ(metrics.values.count("flow_oscillation_pct"), 0u);
    ASSERT_EQ(metrics.not_measured.count("flow_oscillation_pct"), 1u);
    EXPECT_NE(metrics.not_measured.at("flow_oscillation_pct").find("did not spray through the last 3.0 s"),
              std::string::npos);
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

// The strip that must be sprayed: -8 to +8 m (the profile spans -10 to +10 m).
DepositionJudging judging(double strip_from_m = -8.0, double strip_to_m = 8.0) {
    DepositionJudging j;
    j.nominal_dose_ul_cm2 = kNominal;
    j.strip_from_m = strip_from_m;
    j.strip_to_m = strip_to_m;
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
    EXPECT_NEAR(at(result.metrics.values, "overlap_m"), 1.5, 1e-12);
    EXPECT_EQ(at(result.metrics.values, "missed_m"), 0.0);
    EXPECT_NEAR(at(result.metrics.values, "repeated_from_m"), -1.5, 1e-9);
    EXPECT_NEAR(at(result.metrics.values, "repeated_to_m"), 0.0, 1e-9);
    const AreaSpan* repeated = find_area(result.areas, "repeated");
    ASSERT_NE(repeated, nullptr);
    EXPECT_NEAR(repeated->from_along_m, -1.5, 1e-9);
    EXPECT_NEAR(repeated->to_along_m, 0.0, 1e-9);
    EXPECT_EQ(find_area(result.areas, "missed"), nullptr);
    // Uniform doses: every area's CV is 0.
    EXPECT_NEAR(at(result.metrics.values, "cv_operational_pct"), 0.0, 1e-9);
    EXPECT_NEAR(at(result.metrics.values, "cv_repeated_pct"), 0.0, 1e-9);
    EXPECT_NEAR(at(result.metrics.values, "cv_continuation_pct"), 0.0, 1e-9);
}

TEST(DepositionMetrics, GapOfSixtyCentimetresIsMissed) {
    // The continuation lands 0.6 m after the breakpoint (row 212).
    const auto p = profile([](int i) { return i < 200 ? kNominal : 0.0; },
                           [](int i) { return i >= 212 ? kNominal : 0.0; });
    const auto result = rig::harness::deposition_metrics(p, judging(), 0.0);
    EXPECT_NEAR(at(result.metrics.values, "missed_m"), 0.6, 1e-12);
    EXPECT_EQ(at(result.metrics.values, "overlap_m"), 0.0);
    const AreaSpan* missed = find_area(result.areas, "missed");
    ASSERT_NE(missed, nullptr);
    EXPECT_NEAR(missed->from_along_m, 0.0, 1e-9);
    EXPECT_NEAR(missed->to_along_m, 0.6, 1e-9);
    EXPECT_EQ(find_area(result.areas, "repeated"), nullptr);
    EXPECT_EQ(result.metrics.values.count("cv_repeated_pct"), 0u);
}

TEST(DepositionMetrics, PassesMeetingExactlyGiveNeitherOverlapNorGap) {
    const auto p = profile([](int i) { return i < 200 ? kNominal : 0.0; },
                           [](int i) { return i >= 200 ? kNominal : 0.0; });
    const auto result = rig::harness::deposition_metrics(p, judging(), 0.0);
    EXPECT_EQ(at(result.metrics.values, "overlap_m"), 0.0);
    EXPECT_EQ(at(result.metrics.values, "missed_m"), 0.0);
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

TEST(DepositionMetrics, OnlyTheStripThatMustBeSprayedIsJudged) {
    // Spray only between -5 and +5 m: with the strip -5..+5 nothing is missed; the
    // bare ground outside it is not the controller's business.
    const auto p = profile([](int i) { return i >= 100 && i < 200 ? kNominal : 0.0; },
                           [](int i) { return i >= 200 && i < 300 ? kNominal : 0.0; });
    EXPECT_EQ(at(rig::harness::deposition_metrics(p, judging(-5.0, 5.0), 0.0).metrics.values, "missed_m"), 0.0);
    // With the strip -8..+8 the unsprayed 3 m at each end are missed (row
    // centres -7.975..-5.025 and 5.025..7.975: 60 + 60 rows of 0.05 m).
    const auto wider = rig::harness::deposition_metrics(p, judging(), 0.0);
    EXPECT_NEAR(at(wider.metrics.values, "missed_m"), 6.0, 1e-9);
    EXPECT_NEAR(at(wider.metrics.values, "strip_length_m"), 16.0, 1e-12);
}

TEST(DepositionMetrics, NeverResumingMissesTheWholeSpanAfterTheBreakpoint) {
    // The first pass sprays up to the breakpoint; the continuation never comes:
    // everything from the breakpoint to the strip's end (8 m) is missed, however
    // the sprayed rows lie (the old rule counted only between sprayed rows: 0).
    const auto p = profile([](int i) { return i < 200 ? kNominal : 0.0; }, [](int) { return 0.0; });
    const auto result = rig::harness::deposition_metrics(p, judging(), 0.0);
    EXPECT_NEAR(at(result.metrics.values, "missed_m"), 8.0, 1e-9);
    EXPECT_EQ(at(result.metrics.values, "overlap_m"), 0.0);
    const AreaSpan* missed = find_area(result.areas, "missed");
    ASSERT_NE(missed, nullptr);
    EXPECT_NEAR(missed->from_along_m, 0.0, 1e-9);
    EXPECT_NEAR(missed->to_along_m, 8.0, 1e-9);
}

TEST(DepositionMetrics, NeverSprayingMissesTheWholeStrip) {
    const auto p = profile([](int) { return 0.0; }, [](int) { return 0.0; });
    const auto result = rig::harness::deposition_metrics(p, judging(), 0.0);
    EXPECT_NEAR(at(result.metrics.values, "missed_m"), 16.0, 1e-9);
    EXPECT_EQ(at(result.metrics.values, "overlap_m"), 0.0);
    // A strip reaching past the recorded ground (-10 to +10 m): the rows out
    // there are unknown ground, neither sprayed nor missed. It used to count
    // them missed (24 m): a number the ground's extent made, not the controller.
    const MetricSet beyond = rig::harness::deposition_metrics(p, judging(-12.0, 12.0), 0.0).metrics;
    EXPECT_EQ(beyond.values.count("missed_m"), 0u);
    const std::string why = beyond.not_measured.at("missed_m");
    EXPECT_NE(why.find("rows of the strip that must be sprayed (-12.00 to 12.00 m along) lie off the ground: "
                       "the recorded ground spans -10.00 to 10.00 m"),
              std::string::npos)
        << why;
}

TEST(DepositionMetrics, GroundWithNoPassLaidOnItIsMissedNotUnknown) {
    // A controller that never sprayed leaves no pass layer (the trace's grid
    // has 0 passes), but the ground was there: the whole strip is missed.
    DoseProfile p;
    p.first_row_centre_m = -9.975;
    p.row_m = 0.05;
    p.ground_rows = 400;
    const auto result = rig::harness::deposition_metrics(p, judging(), 0.0);
    EXPECT_NEAR(at(result.metrics.values, "missed_m"), 16.0, 1e-9);
    // Without the ground's rows the strip lies on no recorded ground at all.
    p.ground_rows = 0;
    EXPECT_EQ(rig::harness::deposition_metrics(p, judging(), 0.0).metrics.not_measured.count("missed_m"), 1u);
}

// ---------------------------------------------------------------- where the nozzle line was

TEST(VehicleTrack, NoPositionOutsideTheRecordedTruth) {
    // Truth from 1 s to 2 s, the nozzle line moving 1 m/s from 10 m.
    const rig::harness::VehicleTrack track({{1 * kS, 10.0, 0}, {2 * kS, 11.0, 0}});
    EXPECT_DOUBLE_EQ(*track.nozzle_line_along_m(1500 * kMs), 10.5);
    EXPECT_DOUBLE_EQ(*track.nozzle_line_along_m(2 * kS), 11.0);
    // Before the first sample or after the last, truth does not say: never the
    // nearest sample held as if the vehicle stood there.
    EXPECT_FALSE(track.nozzle_line_along_m(999 * kMs).has_value());
    EXPECT_FALSE(track.nozzle_line_along_m(2001 * kMs).has_value());
    EXPECT_EQ(track.describe_span(), "the vehicle truth recorded spans 1.000 s to 2.000 s");
}

TEST(BreakpointMetrics, ADeclarationOutsideTheRecordedTruthIsNotMeasured) {
    const rig::harness::VehicleTrack track({{1 * kS, 10.0, 0}, {2 * kS, 11.0, 0}});
    const rig::emulators::FieldFrame field(40.18, 116.44, 50.0, 90.0);
    // Declared at 1.5 s: 0.5 m past the breakpoint at 10 m.
    const MetricSet on_track =
        rig::harness::breakpoint_metrics({{1500 * kMs, "reached", std::nullopt, std::nullopt}}, track, field, 10.0);
    EXPECT_DOUBLE_EQ(at(on_track, "breakpoint_error_m"), 0.5);
    // Declared at 3 s, after the last truth sample: where the nozzle line was is unknown.
    const MetricSet after =
        rig::harness::breakpoint_metrics({{3 * kS, "reached", std::nullopt, std::nullopt}}, track, field, 10.0);
    EXPECT_EQ(after.values.count("breakpoint_error_m"), 0u);
    EXPECT_EQ(after.values.at("breakpoint_reached_count"), 1.0);
    EXPECT_EQ(after.not_measured.at("breakpoint_error_m"),
              "declared at 3.000 s, where truth has no position of the nozzle line: the vehicle truth recorded spans "
              "1.000 s to 2.000 s");
}

// The stored breakpoint is judged against where the vehicle stood when it
// stored: on autosteer the antenna stops some cm off the A-B line, and a
// controller storing that place is right (across the line); along it, the
// breakpoint. On the exact route (antenna on the line) the same as before.
// (0.2 mm: the event's point is read back at the ellipsoid, 50 m below the
// field's origin, where the frame's metres are a little shorter.)
TEST(BreakpointMetrics, TheStoredPositionIsJudgedAgainstWhereTheVehicleStood) {
    const rig::emulators::FieldFrame field(40.18, 116.44, 50.0, 90.0);
    const auto stored_at = [&](double along_m, double cross_m) {
        const rig::emulators::GeoPoint point = field.to_geodetic(along_m, cross_m);
        return rig::harness::BreakpointEventSample{1500 * kMs, "stored", point.lat_deg, point.lon_deg};
    };
    // Stopped 12 cm right of the line at the breakpoint (10 m), from 1 s to 2 s.
    const rig::harness::VehicleTrack guided({{1 * kS, 10.0, 0, 0.12}, {2 * kS, 10.0, 0, 0.12}});
    EXPECT_NEAR(at(rig::harness::breakpoint_metrics({stored_at(10.03, 0.12)}, guided, field, 10.0),
                   "breakpoint_store_error_m"),
                0.03, 2e-4);
    // Storing the line's point instead of where it stood is 12 cm off.
    EXPECT_NEAR(at(rig::harness::breakpoint_metrics({stored_at(10.0, 0.0)}, guided, field, 10.0),
                   "breakpoint_store_error_m"),
                0.12, 2e-4);
    // The exact route: the antenna on the line, the distance from the breakpoint.
    const rig::harness::VehicleTrack exact({{1 * kS, 10.0, 0}, {2 * kS, 10.0, 0}});
    EXPECT_NEAR(at(rig::harness::breakpoint_metrics({stored_at(10.03, 0.04)}, exact, field, 10.0),
                   "breakpoint_store_error_m"),
                0.05, 2e-4);
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
    EXPECT_NEAR(at(result.metrics.values, "missed_m"), 0.05, 1e-12);
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
    EXPECT_NEAR(at(result.metrics.values, "cv_continuation_pct"), 50.0, 1e-9);
    EXPECT_NEAR(at(result.metrics.values, "cv_operational_pct"), 0.0, 1e-9);
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
    EXPECT_NEAR(at(result.metrics.values, "cv_operational_pct"), 0.0, 1e-9);
    EXPECT_NEAR(at(result.metrics.values, "cv_continuation_pct"), 0.0, 1e-9);
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
