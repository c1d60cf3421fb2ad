// Seed 001's boundary and flow metrics (harness/systems/boundary/boundary_metrics.h) on plain
// data with known answers: the paper's own Table 7 / 8 values for the
// statistics, hand-made rasters for the wet edge, Table 3 for Eq. 13's fit.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "emulators/field2d/nozzle_flow_table.h"
#include "harness/systems/boundary/boundary_metrics.h"

namespace {

using namespace rig::harness;

// A 2 cm raster over east [-2, 2) x north [north_min, north_max), wet (dose 1
// uL/cm^2) where `wet(e, n)` says so.
template <class Fn>
DoseRaster raster_where(Fn wet, double north_min_m = -2.0, double north_max_m = 2.0) {
    DoseRaster r;
    r.east0_m = -2.0;
    r.north0_m = north_min_m;
    r.cell_m = 0.02;
    r.nx = 200;
    r.ny = static_cast<std::size_t>(std::lround((north_max_m - north_min_m) / r.cell_m));
    r.dose_ul_cm2.assign(r.nx * r.ny, 0.0);
    for (std::size_t iy = 0; iy < r.ny; ++iy) {
        for (std::size_t ix = 0; ix < r.nx; ++ix) {
            const double e = r.east0_m + (static_cast<double>(ix) + 0.5) * r.cell_m;
            const double n = r.north0_m + (static_cast<double>(iy) + 0.5) * r.cell_m;
            if (wet(e, n)) r.dose_ul_cm2[iy * r.nx + ix] = 1.0;
        }
    }
    return r;
}

// A family's metrics: its values, and why the others have none.
struct Measured {
    std::map<std::string, double> values;
    std::map<std::string, std::string> not_measured;
};
Measured excess(const std::string& prefix, const EdgeProfile& profile) {
    Measured m;
    m.values = excess_metrics(prefix, profile, m.not_measured);
    return m;
}
Measured per_nozzle_excess(const std::string& prefix, const std::vector<EdgeProfile>& per_nozzle) {
    Measured m;
    m.values = per_nozzle_excess_metrics(prefix, per_nozzle, m.not_measured);
    return m;
}
Measured centre_rule(const std::vector<CentreRuleSample>& samples, const rig::field2d::Polygon& area) {
    Measured m;
    m.values = centre_rule_metrics(samples, area, m.not_measured);
    return m;
}

// The edge along north = 0 with the area to the south: from east +1 to east -1
// (heading west, the outside - north - is to the right).
constexpr BoundaryEdge kNorthEdge{1.0, 0.0, -1.0, 0.0};

TEST(BoundaryMetrics, SummaryIsMeanAndSampleSdLikeThePaper) {
    // Table 7, 0.5 m/s, cm: sum 536 over 11 points, mean 48.727 (printed 48.72);
    // squared deviations sum to 36.18, / 10 -> SD 1.902 (printed 1.90).
    const Summary t7 = summarize({50, 48, 47, 52, 50, 50, 45, 48, 48, 48, 50});
    EXPECT_EQ(t7.n, 11u);
    EXPECT_NEAR(t7.mean, 536.0 / 11.0, 1e-12);
    EXPECT_NEAR(t7.sd, 1.902, 0.001);
    EXPECT_EQ(t7.min, 45.0);
    EXPECT_EQ(t7.max, 52.0);
    // Table 8, driving in: sum 80, mean 7.27 (printed 7.20), SD 1.489 (printed 1.48).
    const Summary t8 = summarize({7, 5, 10, 5, 7, 8, 7, 9, 8, 7, 7});
    EXPECT_NEAR(t8.mean, 80.0 / 11.0, 1e-12);
    EXPECT_NEAR(t8.sd, 1.489, 0.001);
    // NaN (a dry station) is skipped; one value has no SD.
    const Summary one = summarize({NAN, 3.0, NAN});
    EXPECT_EQ(one.n, 1u);
    EXPECT_EQ(one.mean, 3.0);
    EXPECT_TRUE(std::isnan(one.sd));
    EXPECT_TRUE(std::isnan(summarize({}).mean));
}

TEST(BoundaryMetrics, ANozzleClosing0_1sLateAt1MetrePerSecondOverruns0_1m) {
    // Spray up to 0.1 m past the edge (1 m/s x 0.1 s), 2.2 m wide (beyond the 2 m edge).
    const DoseRaster r = raster_where([](double e, double n) { return n < 0.1 && std::abs(e) < 1.1; });
    EdgeProbe probe;  // every 0.5 m from the edge's start: stations 0, 0.5, 1.0, 1.5, 2.0
    const EdgeProfile profile = wet_edge_profile(r, kNorthEdge, probe);
    ASSERT_EQ(profile.excess_m.size(), 5u);
    for (std::size_t i = 0; i < 5; ++i) {
        EXPECT_DOUBLE_EQ(profile.station_m[i], 0.5 * static_cast<double>(i));
        // Probes every 5 mm; the edge taken between the last wet (0.095) and the
        // first dry (0.100) probe: 0.0975, within a quarter cell of 0.1.
        EXPECT_NEAR(profile.excess_m[i], 0.1, 0.005) << "station " << i;
    }
    const auto m = excess("boundary_overrun", profile).values;
    EXPECT_NEAR(m.at("boundary_overrun_mean_m"), 0.1, 0.005);
    EXPECT_NEAR(m.at("boundary_overrun_sd_m"), 0.0, 1e-12);
    EXPECT_EQ(m.at("boundary_overrun_stations"), 5.0);
    EXPECT_EQ(m.at("boundary_overrun_stations_dry"), 0.0);
}

TEST(BoundaryMetrics, ShortSprayIsNegativeAndUnreachedStationsAreDry) {
    // Driving in: the spray began 0.2 m inside; only east in [-0.3, 1) was sprayed.
    const DoseRaster r = raster_where([](double e, double n) { return n < -0.2 && e > -0.3 && e < 1.0; });
    const EdgeProfile p = wet_edge_profile(r, kNorthEdge);
    // Stations at east 1.0 (the cell edge: east 1.0 itself is dry), 0.5, 0, -0.5, -1.0.
    EXPECT_TRUE(std::isnan(p.excess_m[0]));
    EXPECT_NEAR(p.excess_m[1], -0.2, 0.005);
    EXPECT_NEAR(p.excess_m[2], -0.2, 0.005);
    EXPECT_TRUE(std::isnan(p.excess_m[3]));
    EXPECT_TRUE(std::isnan(p.excess_m[4]));
    const auto m = excess("drive_in_excess", p).values;
    EXPECT_NEAR(m.at("drive_in_excess_mean_m"), -0.2, 0.005);
    EXPECT_EQ(m.at("drive_in_excess_stations"), 2.0);
    EXPECT_EQ(m.at("drive_in_excess_stations_dry"), 3.0);
    // No wet station at all: mean and SD have no value, and say why (a limit on them fails as not measured).
    const Measured dry =
        excess("drive_out_excess", wet_edge_profile(raster_where([](double, double) { return false; }), kNorthEdge));
    EXPECT_EQ(dry.values.count("drive_out_excess_mean_m"), 0u);
    EXPECT_EQ(dry.values.count("drive_out_excess_sd_m"), 0u);
    EXPECT_EQ(dry.not_measured.at("drive_out_excess_mean_m"), "no wet ground at any station of the edge");
    EXPECT_EQ(dry.values.at("drive_out_excess_stations_dry"), 5.0);
}

TEST(BoundaryMetrics, SlantedEdge) {
    // An edge through the origin running north-west, outside to the north-east:
    // wet where the distance past it, (e + n) / sqrt 2, is below 0.3 m.
    const BoundaryEdge edge{1.0, -1.0, -1.0, 1.0};
    const DoseRaster r = raster_where([](double e, double n) { return (e + n) / std::sqrt(2.0) < 0.3; });
    EdgeProbe probe;
    probe.from_m = 0.5;
    probe.to_m = 2.0;
    const EdgeProfile p = wet_edge_profile(r, edge, probe);
    ASSERT_EQ(p.excess_m.size(), 4u);
    // Cells are wet by their centre: the staircase edge is within half a cell
    // diagonal (1.4 cm) of the true one.
    for (double x : p.excess_m) EXPECT_NEAR(x, 0.3, 0.015);
}

TEST(BoundaryMetrics, PerNozzleNames) {
    const DoseRaster wet_far = raster_where([](double, double n) { return n < 0.3; });
    const DoseRaster wet_near = raster_where([](double, double n) { return n < 0.1; });
    const DoseRaster dry = raster_where([](double, double) { return false; });
    const auto m = per_nozzle_excess(
        "boundary_overrun", {wet_edge_profile(wet_near, kNorthEdge), wet_edge_profile(wet_far, kNorthEdge),
                             wet_edge_profile(dry, kNorthEdge)}).values;
    EXPECT_NEAR(m.at("boundary_overrun_nozzle0_mean_m"), 0.1, 0.005);
    EXPECT_NEAR(m.at("boundary_overrun_nozzle1_max_m"), 0.3, 0.005);
    EXPECT_EQ(m.at("boundary_overrun_nozzle2_stations"), 0.0);
    EXPECT_EQ(m.count("boundary_overrun_nozzle2_mean_m"), 0u);
    // The ground's total is the sum of the layers: its edge is the farthest one.
    const DoseRaster total = sum_rasters({wet_near, wet_far, dry});
    EXPECT_NEAR(wet_edge_profile(total, kNorthEdge).excess_m[2], 0.3, 0.005);
}

TEST(BoundaryMetrics, TheProbeSpansTheJudgedGroundInsideAndOut) {
    // The ground reaches 6 m outside the north edge and 4 m inside. A spray
    // that went on 3.5 m past the edge, and one that stopped 3 m short of it,
    // are measured where they are (the judge once searched only +-2 m).
    const DoseRaster past = raster_where([](double, double n) { return n < 3.5; }, -4.0, 6.0);
    const EdgeProfile far_out = wet_edge_profile(past, kNorthEdge);
    for (std::size_t i = 0; i < far_out.excess_m.size(); ++i) {
        EXPECT_EQ(far_out.finding[i], StationFinding::wet_edge);
        EXPECT_NEAR(far_out.excess_m[i], 3.5, 0.005) << "station " << i;
    }
    EXPECT_NEAR(excess("drive_out_excess", far_out).values.at("drive_out_excess_mean_m"), 3.5, 0.005);
    const DoseRaster short_of = raster_where([](double, double n) { return n < -3.0; }, -4.0, 6.0);
    const Measured m = excess("drive_in_excess", wet_edge_profile(short_of, kNorthEdge));
    EXPECT_NEAR(m.values.at("drive_in_excess_mean_m"), -3.0, 0.005);
    EXPECT_EQ(m.values.at("drive_in_excess_stations_dry"), 0.0);
}

TEST(BoundaryMetrics, ProbesKeepTheirPlacesSoEveryExcessMeasuredBeforeIsTheSame) {
    // The probes lie at 2 m - j x (a quarter cell), however far the ground
    // reaches: the edge 0.1 m out is found between j = 380 (2 - 380 x 0.005
    // rounds to just under 0.1 m: wet) and 379 (0.105 m, dry), to the last
    // bit as when the probe started at +2 m.
    for (const double north_max : {2.0, 3.0, 6.0}) {
        const EdgeProfile p = wet_edge_profile(raster_where([](double, double n) { return n < 0.1; }, -2.0, north_max), kNorthEdge);
        for (const double excess : p.excess_m) EXPECT_EQ(excess, (2.0 - 380.0 * 0.005) + 0.5 * 0.005) << north_max;
    }
}

TEST(BoundaryMetrics, WetToTheEndOfTheGroundIsNotMeasuredNeverTheBound) {
    // A controller that never shut off: wet up to where the ground ends, 2 m
    // out. The old window reported 2.000 as the excess; the edge lies beyond.
    const EdgeProfile p = wet_edge_profile(raster_where([](double, double) { return true; }), kNorthEdge);
    for (std::size_t i = 0; i < p.excess_m.size(); ++i) {
        EXPECT_EQ(p.finding[i], StationFinding::wet_to_ground_end);
        EXPECT_TRUE(std::isnan(p.excess_m[i]));
        EXPECT_NEAR(p.at_least_m[i], 1.995, 1e-9);  // the last probe on the ground
    }
    const Measured m = excess("drive_out_excess", p);
    for (const char* name : {"drive_out_excess_mean_m", "drive_out_excess_sd_m", "drive_out_excess_min_m", "drive_out_excess_max_m"}) {
        EXPECT_EQ(m.values.count(name), 0u) << name;
        EXPECT_EQ(m.not_measured.at(name),
                  "wet to the end of the judged ground (judge.ground) at 5 of 5 stations: the wet edge lies beyond it, "
                  "at least 1.995 m past the boundary (+ outside); a larger ground would measure it")
            << name;
    }
    EXPECT_EQ(m.values.at("drive_out_excess_stations"), 0.0);
    EXPECT_EQ(m.values.at("drive_out_excess_stations_dry"), 0.0);
    // Some stations measured, some beyond: no mean or max, but the smallest
    // measured excess (0.1 m, below every "at least") is the minimum.
    const Measured mixed =
        excess("drive_out_excess", wet_edge_profile(raster_where([](double e, double n) { return e < 0.25 || n < 0.1; }),
                                                            kNorthEdge));
    EXPECT_NEAR(mixed.values.at("drive_out_excess_min_m"), 0.1, 0.005);
    EXPECT_EQ(mixed.values.at("drive_out_excess_stations"), 2.0);  // stations at east 1.0 and 0.5
    EXPECT_EQ(mixed.not_measured.count("drive_out_excess_mean_m"), 1u);
    EXPECT_EQ(mixed.not_measured.count("drive_out_excess_max_m"), 1u);
    // Per nozzle alike.
    const Measured pn = per_nozzle_excess("drive_out_excess", {p});
    EXPECT_EQ(pn.values.count("drive_out_excess_nozzle0_mean_m"), 0u);
    EXPECT_EQ(pn.not_measured.count("drive_out_excess_nozzle0_mean_m"), 1u);
    EXPECT_EQ(pn.not_measured.count("drive_out_excess_nozzle0_max_m"), 1u);
}

TEST(BoundaryMetrics, AStationWhoseProbeMissesTheGroundIsNotADryOne) {
    // An edge along north = 0 from east 10 to 8: its probes run north-south at
    // east 8-10, off the ground (east -2 ... 2).
    const EdgeProfile p = wet_edge_profile(raster_where([](double, double) { return true; }), BoundaryEdge{10.0, 0.0, 8.0, 0.0});
    ASSERT_EQ(p.finding.size(), 5u);
    for (const StationFinding finding : p.finding) EXPECT_EQ(finding, StationFinding::off_ground);
    const Measured m = excess("boundary_overrun", p);
    EXPECT_EQ(m.values.at("boundary_overrun_stations_dry"), 0.0);
    EXPECT_EQ(m.not_measured.at("boundary_overrun_mean_m"),
              "5 of 5 stations probe off the judged ground (judge.ground does not reach them)");
}

TEST(BoundaryMetrics, BadInputIsRejected) {
    DoseRaster r = raster_where([](double, double) { return false; });
    EXPECT_THROW(wet_edge_profile(r, BoundaryEdge{1, 1, 1, 1}), std::invalid_argument);
    EdgeProbe probe;
    probe.spacing_m = 0.0;
    EXPECT_THROW(wet_edge_profile(r, kNorthEdge, probe), std::invalid_argument);
    r.dose_ul_cm2.pop_back();
    EXPECT_THROW(wet_edge_profile(r, kNorthEdge), std::invalid_argument);
    DoseRaster other = raster_where([](double, double) { return false; });
    other.cell_m = 0.01;
    EXPECT_THROW(sum_rasters({raster_where([](double, double) { return false; }), other}), std::invalid_argument);
}

// The square east 0 ... 10, north 0 ... 10; the centre drives north along
// east = 10 + offset at 1 m/s, sampled every 0.1 s, each sample delivering 1 mL
// while `open(t)` says so.
template <class Offset, class Open>
std::vector<CentreRuleSample> along_east_edge(Offset offset_m, double from_s, double to_s, Open open) {
    std::vector<CentreRuleSample> samples;
    for (int k = 0; from_s + 0.1 * k <= to_s + 1e-9; ++k) {
        const double t = from_s + 0.1 * k;
        samples.push_back(CentreRuleSample{t, {10.0 + offset_m(t), t}, open(t) ? 0.001 : 0.0});
    }
    return samples;
}

const rig::field2d::Polygon kSquare({{0, 0}, {10, 0}, {10, 10}, {0, 10}}, "square");

TEST(CentreRuleMetrics, AllOffWithTheCentreOutsideScoresZero) {
    // The centre 0.2 m outside all along, nothing delivered: the start counts as one spell.
    const auto m =
        centre_rule(along_east_edge([](double) { return 0.2; }, 0.0, 8.0, [](double) { return false; }), kSquare).values;
    EXPECT_EQ(m.at("centre_out_crossings"), 1.0);
    EXPECT_EQ(m.at("centre_out_samples"), 81.0);
    EXPECT_EQ(m.at("centre_out_spray_ml"), 0.0);
    EXPECT_EQ(m.at("centre_out_close_s"), 0.0);
    EXPECT_EQ(m.at("centre_out_close_m"), 0.0);
}

TEST(CentreRuleMetrics, ACentreThatNeverLeftTheAreaLeavesTheClosingNotMeasured) {
    // Inside all along (east 9.8), spraying: nothing to close, and no 0 s passed off as a rule obeyed.
    const Measured m =
        centre_rule(along_east_edge([](double) { return -0.2; }, 0.0, 4.0, [](double) { return true; }), kSquare);
    EXPECT_EQ(m.values.at("centre_out_crossings"), 0.0);
    EXPECT_EQ(m.values.at("centre_out_spray_ml"), 0.0);
    for (const char* name : {"centre_out_close_s", "centre_out_close_m"}) {
        EXPECT_EQ(m.values.count(name), 0u) << name;
        EXPECT_EQ(m.not_measured.at(name), "the boom centre never left the target area: the rule was never put to the test");
    }
}

TEST(CentreRuleMetrics, ClosingLateAfterTheCentreCrossesOutIsMeasuredFromTheCrossing) {
    // Inside (east 9.8) until t = 3, outside (10.2) after; the spray stops at
    // t = 3.3 (last delivering sample 3.3): 0.3 s, the centre's travel 0.3 m
    // along plus nothing across (it jumped out between samples), 3 samples x 1 mL.
    const auto m = centre_rule(
        along_east_edge([](double t) { return t < 3.0 - 1e-9 ? -0.2 : 0.2; }, 0.0, 6.0, [](double t) { return t < 3.35; }),
        kSquare).values;
    EXPECT_EQ(m.at("centre_out_crossings"), 1.0);
    EXPECT_NEAR(m.at("centre_out_close_s"), 0.3, 1e-9);
    EXPECT_NEAR(m.at("centre_out_close_m"), 0.3, 1e-9);
    EXPECT_NEAR(m.at("centre_out_spray_ml"), 4.0, 1e-9);  // t = 3.0, 3.1, 3.2, 3.3
    // A controller that ignores the rule sprays all the way: the longest spell's 3 s.
    const auto ignored = centre_rule(
        along_east_edge([](double t) { return t < 3.0 - 1e-9 ? -0.2 : 0.2; }, 0.0, 6.0, [](double) { return true; }),
        kSquare).values;
    EXPECT_NEAR(ignored.at("centre_out_close_s"), 3.0, 1e-9);
    EXPECT_NEAR(ignored.at("centre_out_spray_ml"), 31.0, 1e-9);
}

TEST(CentreRuleMetrics, TheLongestOfSeveralSpellsCountsAndBadInputIsNamed) {
    // Out 1-2 s (spray until 1.2), in, out 4-6 s (spray until 4.5).
    const auto out = [](double t) { return (t > 0.95 && t < 2.05) || t > 3.95 ? 0.2 : -0.2; };
    const auto open = [](double t) { return t < 1.25 || (t > 2.5 && t < 4.55); };
    const auto m = centre_rule(along_east_edge(out, 0.0, 6.0, open), kSquare).values;
    EXPECT_EQ(m.at("centre_out_crossings"), 2.0);
    EXPECT_NEAR(m.at("centre_out_close_s"), 0.5, 1e-9);
    std::vector<CentreRuleSample> bad = along_east_edge(out, 0.0, 1.0, open);
    bad[3].volume_l = -1.0;
    try {
        centre_rule(bad, kSquare);
        FAIL() << "a negative volume passed";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("sample 3"), std::string::npos) << e.what();
    }
    bad[3].volume_l = 0.0;
    bad[5].t_s = 0.1;
    EXPECT_THROW(centre_rule(bad, kSquare), std::invalid_argument);
}

TEST(FlowMetrics, DeliveredAgainstTable3) {
    const auto table = rig::field2d::NozzleFlowTable::paper_table3();
    // Nozzle 0 at 40 %: 0.390 L in 60 s is Table 3's 390 mL/min; nozzle 3 at
    // 95 % (interpolated 635) delivering 10 % more; 10 % duty is outside the table.
    const std::vector<FlowCheckRow> rows = flow_against_table(
        {{0, 40.0, 0.390, 60.0}, {3, 95.0, 0.6985, 60.0}, {1, 10.0, 0.05, 60.0}}, table);
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_NEAR(rows[0].delivered_ml_min, 390.0, 1e-9);
    EXPECT_NEAR(rows[0].error_pct, 0.0, 1e-9);
    EXPECT_NEAR(rows[1].table_ml_min, 635.0, 1e-9);
    EXPECT_NEAR(rows[1].error_pct, 10.0, 1e-9);
    EXPECT_TRUE(std::isnan(rows[2].table_ml_min));
    const auto m = flow_table_metrics(rows);
    EXPECT_EQ(m.at("flow_table_points"), 2.0);
    EXPECT_NEAR(m.at("flow_table_max_abs_error_pct"), 10.0, 1e-9);
    EXPECT_NEAR(m.at("flow_table_mean_abs_error_pct"), 5.0, 1e-9);
    EXPECT_THROW(flow_against_table({{6, 40.0, 0.3, 60.0}}, table), std::invalid_argument);
    EXPECT_THROW(flow_against_table({{0, 40.0, 0.3, 0.0}}, table), std::invalid_argument);
}

TEST(FlowMetrics, Eq13FitOfTable3IsThePapers) {
    // Table 3 delivered exactly: the fit over the nozzles' means at 30-80 % duty
    // is the paper's q = 0.00375 s + 0.296 (Eq. 13): means 406.67 ... 593.33,
    // Sxx = 1750, Sxy = 6562.5 -> A = 3.75 mL/min per %, b = 502.64 - 3.75 x 55 = 296.4 mL/min.
    const auto table = rig::field2d::NozzleFlowTable::paper_table3();
    std::vector<FlowRecord> records;
    for (int n = 0; n < 6; ++n) {
        for (double d : {30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0, 100.0}) {
            records.push_back({n, d, table.flow_ml_min(n, d) / 1000.0, 60.0});
        }
    }
    const auto m = eq13_fit_metrics(flow_against_table(records, table));
    EXPECT_EQ(m.at("eq13_points"), 6.0);
    EXPECT_NEAR(m.at("eq13_slope_l_min_per_pct"), 0.00375, 1e-6);
    EXPECT_NEAR(m.at("eq13_intercept_l_min"), 0.296, 0.0005);
    EXPECT_GT(m.at("eq13_r2"), 0.99);
    EXPECT_THROW(fit_line({1.0, 1.0}, {2.0, 3.0}), std::invalid_argument);
}

}  // namespace
