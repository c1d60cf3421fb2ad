// The valve calibration of seed 000 sec. 2.4.2 (Fig. 11): the controller's
// procedure on known readings, the rig's Fig. 11 metrics on known truth, and the
// case itself: the lines the reference controller ships with are the ones it
// measures on the rig (cases/fig11-calibration), not the plant's own.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <functional>
#include <regex>
#include <string>
#include <vector>

#include "controller/valve_calibration.h"
#include "controller/valve_calibration_procedure.h"
#include "harness/systems/breakpoint/breakpoint_metrics.h"
#include "run_support.h"

namespace fs = std::filesystem;
using rig::TimeNs;
using rig::controller::CalibrationRunConfig;
using rig::controller::ValveCalibrationProcedure;

namespace {

constexpr TimeNs kPeriod = 100'000'000;  // the controller's 0.1 s period

// Runs the procedure for `seconds` with the valve arriving at once and readings
// from `pump(t)` and main = slope(opening) x pump + intercept(opening).
void run(ValveCalibrationProcedure& procedure, TimeNs from, double seconds, const std::function<double(TimeNs)>& pump,
         double* opening_now) {
    const TimeNs to = from + static_cast<TimeNs>(seconds * 1e9);
    for (TimeNs t = from; t < to; t += kPeriod) {
        const double p = pump(t);
        const double main = (0.3 + 0.01 * (*opening_now - 87.0)) * p + 2.0;
        *opening_now = procedure.update(t, true, p, main);
    }
}

}  // namespace

TEST(ValveCalibrationProcedure, FitsTheLinesItMeasuredAtSteadyPumpFlows) {
    CalibrationRunConfig config;
    config.openings_pct = {87.0, 95.0};
    config.settle_s = 1.0;
    config.measure_s = 1.0;
    ValveCalibrationProcedure procedure(config);
    double opening = 87.0;
    // Three throttle levels, 20 s each: each opening is held about three times per level.
    for (int level = 0; level < 3; ++level) {
        const double flow = 31.1 + 13.1 * level;
        run(procedure, level * 20'000'000'000LL, 20.0, [flow](TimeNs) { return flow; }, &opening);
    }
    const auto lines = procedure.fit();
    ASSERT_EQ(lines.size(), 2u);
    EXPECT_EQ(lines[0].line.opening_pct, 87.0);
    EXPECT_NEAR(lines[0].line.slope, 0.30, 1e-9);
    EXPECT_NEAR(lines[0].line.intercept_l_min, 2.0, 1e-9);
    EXPECT_NEAR(lines[1].line.slope, 0.38, 1e-9);
    EXPECT_NEAR(lines[1].r2, 1.0, 1e-12);
    EXPECT_GE(lines[0].points, 6);
    EXPECT_NEAR(lines[0].pump_max_l_min - lines[0].pump_min_l_min, 26.2, 1e-9);
    // The file is what the controller config's valve.calibration reads.
    EXPECT_NE(procedure.yaml().find("  - { opening_pct: 95.0, slope: 0.3800, intercept_l_min: 2.000 }"),
              std::string::npos)
        << procedure.yaml();
}

TEST(ValveCalibrationProcedure, APointTakenWhileTheThrottleMovedIsDropped) {
    CalibrationRunConfig config;
    config.openings_pct = {90.0};
    config.settle_s = 1.0;
    config.measure_s = 1.0;
    ValveCalibrationProcedure procedure(config);
    double opening = 90.0;
    // The pump ramps 10 % per second the whole time: no measurement is steady.
    run(procedure, 0, 30.0, [](TimeNs t) { return 31.1 * (1.0 + 0.1 * static_cast<double>(t) / 1e9); }, &opening);
    EXPECT_TRUE(procedure.points().empty());
    EXPECT_TRUE(procedure.fit().empty());
    // Steady again: points come.
    run(procedure, 30'000'000'000LL, 10.0, [](TimeNs) { return 40.0; }, &opening);
    EXPECT_FALSE(procedure.points().empty());
    // One pump flow is not a line.
    EXPECT_TRUE(procedure.fit().empty());
}

TEST(ValveCalibrationProcedure, PointsAtOnePumpFlowGiveNoLineEvenWithNoSpanAsked) {
    CalibrationRunConfig config;
    config.openings_pct = {90.0};
    config.settle_s = 1.0;
    config.measure_s = 1.0;
    config.min_span_l_min = 0.0;
    ValveCalibrationProcedure procedure(config);
    double opening = 90.0;
    run(procedure, 0, 30.0, [](TimeNs) { return 40.0; }, &opening);
    EXPECT_GE(procedure.points().size(), 3u);
    EXPECT_TRUE(procedure.fit().empty());  // no slope through one pump flow, and no NaN line
}

TEST(Fig11Metrics, HoldsAtSteadyPumpFlowsGiveALinePerOpening) {
    // Truth every 10 ms: three openings held 5 s each at each of three pump flows.
    std::vector<rig::harness::HydraulicsSample> samples;
    TimeNs t = 0;
    for (double pump : {31.1, 44.2, 57.3}) {
        for (double opening : {87.0, 90.0, 93.0}) {
            for (int i = 0; i < 500; ++i, t += 10'000'000) {
                const double main = (0.3 + 0.01 * (opening - 87.0)) * pump + 2.0 + (i % 2 == 0 ? 0.01 : -0.01);
                samples.push_back({t, main, 7, pump, opening});
            }
        }
    }
    const auto result = rig::harness::fig11_metrics(samples, {0, t});
    ASSERT_EQ(result.lines.size(), 3u);
    EXPECT_NEAR(result.lines[2].slope, 0.36, 1e-6);
    EXPECT_NEAR(result.lines[2].intercept_l_min, 2.0, 1e-4);
    EXPECT_EQ(result.metrics.values.at("fig11_lines_count"), 3.0);
    EXPECT_EQ(result.metrics.values.at("fig11_lines_missing_count"), 2.0);  // of the paper's five
    EXPECT_LT(result.metrics.values.at("fig11_unexplained_pct"), 1e-6);
    EXPECT_NEAR(result.metrics.values.at("fig11_pump_span_l_min"), 26.2, 1e-9);
    // The +-0.01 ripple over an odd count of samples leaves 1e-4 in the mean.
    EXPECT_NEAR(result.metrics.values.at("fig11_main_flow_min_l_min"), 0.3 * 31.1 + 2.0, 1e-3);

    // Sections shut throughout: nothing to fit, and the judged metric says why.
    for (auto& sample : samples) sample.sections_spraying_mask = 0;
    const auto shut = rig::harness::fig11_metrics(samples, {0, t});
    EXPECT_TRUE(shut.lines.empty());
    EXPECT_EQ(shut.metrics.not_measured.count("fig11_unexplained_pct"), 1u);
}

// The case: the controller measures its lines on the rig, and the lines it
// ships with (default_calibration) are those, to the file's printed precision.
TEST(ValveCalibrationRun, TheShippedCalibrationIsTheOneMeasuredOnTheRig) {
    const fs::path out = rig::testing::fresh_dir("fig11-run");
    const std::string command = "'" RIG_BINARY_DIR "/bin/rig' run --in-process '" RIG_SOURCE_DIR
                                "/cases/fig11-calibration/fig11-valve-calibration.yaml' -q --out '" +
                                out.string() + "'";
    const auto outcome = rig::testing::run_shell(command + " 2>&1");
    ASSERT_EQ(outcome.exit_code, 0) << outcome.output;

    const std::string file =
        rig::testing::read_all(out / "cases" / "fig11-valve-calibration" / "controller-state" / "valve-calibration.yaml");
    const std::regex line(R"(opening_pct: ([0-9.]+), slope: ([0-9.-]+), intercept_l_min: ([0-9.-]+) \}   # R\^2 ([0-9.]+))");
    std::vector<rig::controller::CalibratedOpening> measured;
    for (auto it = std::sregex_iterator(file.begin(), file.end(), line); it != std::sregex_iterator(); ++it) {
        measured.push_back({std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3])});
        EXPECT_GT(std::stod((*it)[4]), 0.9525) << "R^2 below the paper's worst line: " << (*it)[0];
    }
    const auto shipped = rig::controller::default_calibration();
    ASSERT_EQ(measured.size(), shipped.size()) << file;
    for (std::size_t i = 0; i < shipped.size(); ++i) {
        SCOPED_TRACE("opening " + std::to_string(shipped[i].opening_pct));
        EXPECT_EQ(measured[i].opening_pct, shipped[i].opening_pct);
        // The file prints 4 and 3 decimals: re-run the case and copy its lines
        // into controller/valve_calibration.cpp when the plant changes.
        EXPECT_NEAR(measured[i].slope, shipped[i].slope, 0.5e-4 + 1e-12) << file;
        EXPECT_NEAR(measured[i].intercept_l_min, shipped[i].intercept_l_min, 0.5e-3 + 1e-12) << file;
    }

    // The rig's own Fig. 11, from truth: five lines.
    const nlohmann::json results = nlohmann::json::parse(rig::testing::read_all(out / "results.json"));
    const nlohmann::json& metrics = results.at("cases").at(0).at("metrics");
    EXPECT_EQ(metrics.at("fig11_lines_count").get<double>(), 5.0);
    EXPECT_EQ(metrics.at("fig11_lines_missing_count").get<double>(), 0.0);
    EXPECT_LT(metrics.at("fig11_unexplained_pct").get<double>(), 4.75);
}
