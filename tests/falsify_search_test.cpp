// rig falsify's parts that need no run (harness/falsify/): the Latin
// hypercube, the robustness margin against the judge's limits, the search
// over a margin whose answer is known (a function of the point, no case),
// and the key ranges.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "harness/falsify/falsify_search.h"
#include "harness/falsify/latin_hypercube.h"
#include "harness/falsify/robustness.h"
#include "harness/falsify/search_space.h"
#include "harness/judge/verdict.h"

using namespace rig::harness;

namespace {

// A margin known in closed form: 0.5 everywhere but a narrow notch in x0 at
// `centre` (half width `half_width`), reaching `depth` below 0.5 at its centre;
// x1 and x2 play no part. Counts the points it is asked for.
class NotchEvaluator final : public PointEvaluator {
public:
    NotchEvaluator(double centre, double half_width, double depth)
        : centre_(centre), half_width_(half_width), depth_(depth) {}
    std::vector<RunMargin> evaluate(const std::vector<std::vector<double>>& points) override {
        std::vector<RunMargin> margins;
        for (const auto& point : points) {
            ++calls;
            batches.insert(points.size());
            RunMargin margin;
            margin.margin = 0.5 - depth_ * std::max(0.0, 1.0 - std::fabs(point[0] - centre_) / half_width_);
            margin.limiting_metric = "overlap_m";
            margins.push_back(margin);
        }
        return margins;
    }
    std::size_t calls = 0;
    std::set<std::size_t> batches;

private:
    double centre_;
    double half_width_;
    double depth_;
};

std::vector<VaryRange> three_keys() {
    return {parse_vary("vehicle.speed_km_h=3:12"), parse_vary("gnss.latency_s=0.02:0.3"),
            parse_vary("gnss.dropouts[0].before_breakpoint_s=0.5:8")};
}

}  // namespace

TEST(LatinHypercube, EveryStratumOfEveryDimensionHoldsExactlyOnePoint) {
    const std::size_t n = 17;
    const auto points = latin_hypercube(n, 3, 42);
    ASSERT_EQ(points.size(), n);
    for (std::size_t dimension = 0; dimension < 3; ++dimension) {
        std::set<std::size_t> strata;
        for (const auto& point : points) {
            ASSERT_GE(point[dimension], 0.0);
            ASSERT_LT(point[dimension], 1.0);
            strata.insert(static_cast<std::size_t>(point[dimension] * static_cast<double>(n)));
        }
        EXPECT_EQ(strata.size(), n) << "dimension " << dimension;
    }
    // Deterministic, and the seed matters.
    EXPECT_EQ(latin_hypercube(n, 3, 42), points);
    EXPECT_NE(latin_hypercube(n, 3, 43), points);
}

TEST(Robustness, TheMarginIsTheDistanceToTheLimitScaledByItAndAgreesWithTheVerdict) {
    EXPECT_DOUBLE_EQ(limit_margin(3.0, 3.3), 0.3 / 3.3);
    EXPECT_DOUBLE_EQ(limit_margin(3.63, 3.3), -0.33 / 3.3);
    EXPECT_DOUBLE_EQ(limit_margin(0.0, 0.0), 0.0);   // a zero limit scales by 1: on it passes
    EXPECT_DOUBLE_EQ(limit_margin(2.0, 0.0), -2.0);  // two missed where none may be
    // Negative exactly where the judge fails the metric (equal to the limit passes).
    for (const double value : {0.0, 1.0, 3.2999, 3.3, 3.3001, 10.0}) {
        const bool fails = !judge({{"overlap_m", value}}, {{"overlap_m", 3.3}}).empty();
        EXPECT_EQ(limit_margin(value, 3.3) < 0.0, fails) << value;
    }
}

TEST(Robustness, ARunsMarginIsItsSmallestAndNeverMadeUp) {
    CaseResult result;
    result.limits = {{"overlap_m", 3.3}, {"flow_adjust_time_s", 1.7}, {"missed_m", 0.5}};
    result.metrics = {{"overlap_m", 1.65}, {"flow_adjust_time_s", 1.53}, {"missed_m", 0.0}};
    const RunMargin both = run_margin(result, limited_metrics(result.limits));
    ASSERT_TRUE(both.margin.has_value());
    EXPECT_DOUBLE_EQ(*both.margin, limit_margin(1.53, 1.7));
    EXPECT_EQ(both.limiting_metric, "flow_adjust_time_s");
    EXPECT_FALSE(both.falsifying());
    // Nothing missed against a zero limit does not hide the others' margins.
    result.limits["missed_m"] = 0.0;
    EXPECT_DOUBLE_EQ(*run_margin(result, limited_metrics(result.limits)).margin, limit_margin(1.53, 1.7));
    EXPECT_DOUBLE_EQ(*run_margin(result, {"missed_m"}).margin, 0.0);
    result.metrics["missed_m"] = 0.4;
    EXPECT_DOUBLE_EQ(*run_margin(result, limited_metrics(result.limits)).margin, -0.4);
    result.metrics["missed_m"] = 0.0;
    // Only the metric asked for.
    EXPECT_DOUBLE_EQ(*run_margin(result, {"overlap_m"}).margin, 0.5);
    // Not measured: broken, without a number.
    result.metrics.erase("flow_adjust_time_s");
    result.not_measured["flow_adjust_time_s"] = "never settled";
    const RunMargin unsettled = run_margin(result, limited_metrics(result.limits));
    EXPECT_FALSE(unsettled.margin.has_value());
    EXPECT_TRUE(unsettled.falsifying());
    EXPECT_EQ(unsettled.broken, "flow_adjust_time_s not measured: never settled");
    // The controller's failure breaks the run; the rig's own makes it invalid.
    CaseResult crashed = result;
    crashed.error_kind = "node_exited";
    crashed.error = "the controller exited";
    EXPECT_TRUE(run_margin(crashed, {"overlap_m"}).falsifying());
    CaseResult overloaded = result;
    overloaded.error_kind = "rig_overloaded";
    overloaded.error = "late";
    EXPECT_FALSE(run_margin(overloaded, {"overlap_m"}).invalid.empty());
    // A metric the case does not limit cannot give a margin.
    EXPECT_FALSE(run_margin(result, {"breakpoint_error_m"}).invalid.empty());
    // A point is its worst seed.
    RunMargin low;
    low.margin = -0.1;
    RunMargin high;
    high.margin = 0.2;
    EXPECT_DOUBLE_EQ(*worst_margin({high, low}).margin, -0.1);
    EXPECT_FALSE(worst_margin({high, unsettled}).broken.empty());
}

TEST(SearchSpace, RangesParseSnapAndWriteValuesExactly) {
    const VaryRange range = parse_vary("gnss.dropouts[0].at_s=1.5:9");
    EXPECT_EQ(range.key, "gnss.dropouts[0].at_s");
    EXPECT_EQ(range.keys, std::vector<std::string>{"gnss.dropouts[0].at_s"});
    EXPECT_DOUBLE_EQ(range.low, 1.5);
    EXPECT_DOUBLE_EQ(range.high, 9.0);
    const VaryRange tied = parse_vary("route.start.speed_m_s,route.segments[0].straight.speed_m_s=0.5:2");
    EXPECT_EQ(tied.keys.size(), 2u);
    const auto settings = point_settings({{"seed", "3"}}, {tied}, {1.25});
    ASSERT_EQ(settings.size(), 3u);
    EXPECT_EQ(settings[2].key, "route.segments[0].straight.speed_m_s");
    EXPECT_EQ(settings[2].value, "1.25");
    VaryRange whole = parse_vary("encoder.pulses_per_rev=100:2000");
    whole.integer = true;
    EXPECT_EQ(value_text(whole, 517.6), "518");
    EXPECT_EQ(value_text(whole, 5000.0), "2000");
    const double awkward = 2.0 + 1e-15;
    EXPECT_EQ(std::stod(value_text(range, awkward)), awkward);  // reads back as the same double
    for (const char* bad : {"vehicle.speed_km_h", "vehicle.speed_km_h=3", "vehicle.speed_km_h=9:3",
                            "vehicle.speed_km_h=a:3", "vehicle.speed_km_h=3:inf", "=3:4", "a,,b=1:2"}) {
        EXPECT_THROW(parse_vary(bad), std::invalid_argument) << bad;
    }
}

TEST(SearchSpace, ChoiceKeysParseSnapToAChoiceAndWriteTheChoice) {
    const VaryRange positioning = parse_vary("controller.positioning=fusion,rtk_only");
    EXPECT_EQ(positioning.key, "controller.positioning");
    ASSERT_TRUE(positioning.is_choice());
    EXPECT_EQ(positioning.choices, (std::vector<std::string>{"fusion", "rtk_only"}));
    EXPECT_EQ(range_text(positioning), "controller.positioning=fusion,rtk_only");
    // [0, 1) is the first choice, [1, 2] the second: half the range each.
    EXPECT_EQ(value_text(positioning, 0.0), "fusion");
    EXPECT_EQ(value_text(positioning, 0.999), "fusion");
    EXPECT_EQ(value_text(positioning, 1.0), "rtk_only");
    EXPECT_EQ(value_text(positioning, 2.0), "rtk_only");  // the range's top end is the last choice
    EXPECT_EQ(value_text(positioning, -3.0), "fusion");
    // A choice's unit coordinate is the middle of its share, and maps back to it.
    EXPECT_DOUBLE_EQ(unit_of(positioning, 1.0), 0.75);
    EXPECT_EQ(snapped(positioning, positioning.low + unit_of(positioning, 0.0) * positioning.high), 0.0);
    const auto settings = point_settings({}, {positioning}, {1.0});
    ASSERT_EQ(settings.size(), 1u);
    EXPECT_EQ(settings[0].value, "rtk_only");
    // Numbers can be choices too: a discrete set of values.
    const VaryRange pulses = parse_vary("encoder.pulses_per_rev=500,1000,2000");
    EXPECT_EQ(value_text(pulses, 2.5), "2000");
    for (const char* bad : {"controller.positioning=fusion", "controller.positioning=fusion,fusion",
                            "controller.positioning=fusion,", "controller.positioning=,fusion",
                            "controller.positioning=fusion,rtk only", "controller.positioning="}) {
        EXPECT_THROW(parse_vary(bad), std::invalid_argument) << bad;
    }
}

// A margin that breaks only at one choice of a choice key, and there only
// in a band of a number: the search finds the pair, and visits every choice.
class ChoiceEvaluator final : public PointEvaluator {
public:
    std::vector<RunMargin> evaluate(const std::vector<std::vector<double>>& points) override {
        std::vector<RunMargin> margins;
        for (const auto& point : points) {
            RunMargin margin;
            const bool bites = point[0] == 2.0;  // the third choice
            margin.margin = 0.4 - (bites ? 0.6 * std::max(0.0, 1.0 - std::fabs(point[1] - 8.0) / 2.0) : 0.0);
            margin.limiting_metric = "overlap_m";
            margins.push_back(margin);
            choices_seen.insert(point[0]);
        }
        return margins;
    }
    bool stopped() const override { return false; }
    std::set<double> choices_seen;
};

TEST(FalsifySearch, FindsTheOneChoiceThatBreaksAndVisitsEveryChoice) {
    const std::vector<VaryRange> space{parse_vary("gnss.fix=rtk,float,dgps"), parse_vary("vehicle.speed_km_h=3:12")};
    for (const SearchMethod method : {SearchMethod::crs2, SearchMethod::direct}) {
        SearchOptions options;
        options.method = method;
        options.budget = 60;
        options.stop_at_first = true;
        ChoiceEvaluator evaluator;
        const SearchOutcome outcome = falsify_search(space, options, evaluator);
        ASSERT_TRUE(outcome.first_falsifying.has_value()) << search_method_name(method);
        const SearchedPoint& found = outcome.points[*outcome.first_falsifying];
        EXPECT_EQ(value_text(space[0], found.values[0]), "dgps");
        EXPECT_NEAR(found.values[1], 8.0, 2.0 / 3.0);  // where 0.6 * (1 - |v - 8| / 2) passes 0.4
        EXPECT_EQ(evaluator.choices_seen, (std::set<double>{0.0, 1.0, 2.0})) << search_method_name(method);
    }
}

TEST(FalsifySearch, Crs2FindsANarrowNotchWithinItsBudgetDeterministically) {
    // The notch breaks the limit where |x0 - 7.7| < 0.1 (2.2 % of the range), its slope within 0.6.
    SearchOptions options;
    options.budget = 80;
    options.stop_at_first = true;
    options.seed = 3;
    NotchEvaluator evaluator(7.7, 0.6, 0.6);
    const SearchOutcome outcome = falsify_search(three_keys(), options, evaluator);
    ASSERT_TRUE(outcome.first_falsifying.has_value());
    const SearchedPoint& found = outcome.points[*outcome.first_falsifying];
    EXPECT_LT(*found.margin.margin, 0.0);
    EXPECT_NEAR(found.values[0], 7.7, 0.11);
    EXPECT_EQ(outcome.points.size(), *outcome.first_falsifying + 1);  // --first: nothing after it
    EXPECT_EQ(outcome.worst, outcome.first_falsifying);
    EXPECT_EQ(evaluator.calls, outcome.points.size());
    // The same seed, the same points.
    NotchEvaluator again(7.7, 0.6, 0.6);
    const SearchOutcome repeated = falsify_search(three_keys(), options, again);
    ASSERT_EQ(repeated.points.size(), outcome.points.size());
    for (std::size_t index = 0; index < outcome.points.size(); ++index) {
        EXPECT_EQ(repeated.points[index].values, outcome.points[index].values);
    }
}

TEST(FalsifySearch, SpendsTheWholeBudgetWhenNothingBreaksAndBatchesTheStartDesign) {
    SearchOptions options;
    options.budget = 30;
    options.batch = 4;
    options.start_points = 8;
    NotchEvaluator evaluator(7.7, 0.6, 0.3);  // never below 0.2
    const SearchOutcome outcome = falsify_search(three_keys(), options, evaluator);
    EXPECT_EQ(outcome.points.size(), 30u);
    EXPECT_FALSE(outcome.first_falsifying.has_value());
    ASSERT_TRUE(outcome.worst.has_value());
    EXPECT_LT(*outcome.points[*outcome.worst].margin.margin, 0.45);  // it found the notch's slope
    EXPECT_EQ(std::count_if(outcome.points.begin(), outcome.points.end(),
                            [](const SearchedPoint& point) { return point.phase == "start"; }),
              8);
    EXPECT_TRUE(evaluator.batches.contains(4));  // the design ran four at a time
    for (const SearchedPoint& point : outcome.points) {
        EXPECT_GE(point.values[0], 3.0);
        EXPECT_LE(point.values[0], 12.0);
    }
}

TEST(FalsifySearch, RandomSamplingUsesTheSameBudgetAndEveryMethodRuns) {
    for (const SearchMethod method : {SearchMethod::random, SearchMethod::direct, SearchMethod::isres}) {
        SearchOptions options;
        options.method = method;
        options.budget = 25;
        options.batch = 3;
        NotchEvaluator evaluator(7.7, 0.6, 0.3);
        const SearchOutcome outcome = falsify_search(three_keys(), options, evaluator);
        EXPECT_EQ(outcome.points.size(), 25u) << search_method_name(method);
        EXPECT_EQ(outcome.points.back().phase, search_method_name(method));
    }
    EXPECT_EQ(search_method_named("direct"), SearchMethod::direct);
    EXPECT_FALSE(search_method_named("cmaes").has_value());
}

TEST(FalsifySearch, AnIntegerSpaceSmallerThanTheBudgetEndsWhenEveryValueIsKnown) {
    VaryRange pulses = parse_vary("encoder.pulses_per_rev=1:6");
    pulses.integer = true;
    SearchOptions options;
    options.budget = 40;
    NotchEvaluator evaluator(100.0, 1.0, 0.1);
    const SearchOutcome outcome = falsify_search({pulses}, options, evaluator);
    // Six values, each run once, however often NLopt asks.
    EXPECT_LE(outcome.points.size(), 6u);
    std::set<double> values;
    for (const SearchedPoint& point : outcome.points) values.insert(point.values[0]);
    EXPECT_EQ(values.size(), outcome.points.size());
}
