// rig falsify's methods compared on margins known in closed form, so that
// hundreds of searches cost seconds (docs/falsify.md "Which method"). A real
// case's search (scripts/falsify-bench) runs each point as a case and can
// only afford a few repeats on one fault; this one moves the fault.
//
//   build/bin/falsify_method_bench [--placements 200] [--budget 30] [--dimensions 2] [--band-permille 10]
//
// The margin is 0.4 everywhere but a band of the first parameter (of
// [0, 1]) placed anew for each search, uniformly at random (a fixed seed):
//   - "slope": a notch like the lead-bump fault's (tests/falsify_test.cpp):
//     below 0 within a band --band-permille of the range wide, the margin
//     falling towards it over 23 % of the range either side (the fault's
//     1.5 km/h taper in a range of 6.6 km/h);
//   - "cliff": the same falsifying band, no slope (a fault that is off
//     until it is fully on), where no method that learns from margins can
//     beat random points.
// The other parameters play no part. For each shape and method it prints
// how many searches found a falsifying point within the budget, and the
// median and 90th percentile of runs to the first (the points before it and
// it; a search that found none counts as more than the budget).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "harness/falsify/falsify_search.h"

using namespace rig::harness;

namespace {

struct Shape {
    std::string_view name;
    double slope_half_width;  // 0: a cliff
};

class BandEvaluator final : public PointEvaluator {
public:
    BandEvaluator(Shape shape, double centre, double band_half_width)
        : shape_(shape), centre_(centre), band_half_width_(band_half_width) {}
    std::vector<RunMargin> evaluate(const std::vector<std::vector<double>>& points) override {
        std::vector<RunMargin> margins;
        for (const auto& point : points) {
            const double distance = std::fabs(point[0] - centre_);
            RunMargin margin;
            if (shape_.slope_half_width > 0.0) {
                // 0.4 at the slope's edge, 0 at the band's edge, below inside it.
                const double depth = 0.4 / (1.0 - band_half_width_ / shape_.slope_half_width);
                margin.margin = 0.4 - depth * std::max(0.0, 1.0 - distance / shape_.slope_half_width);
            } else {
                margin.margin = distance < band_half_width_ ? -0.1 : 0.4;
            }
            margin.limiting_metric = "overlap_m";
            margins.push_back(margin);
        }
        return margins;
    }

private:
    Shape shape_;
    double centre_;
    double band_half_width_;
};

std::string runs_text(double runs, std::size_t budget) {
    return std::isinf(runs) ? "> " + std::to_string(budget) : std::to_string(static_cast<long long>(std::lround(runs)));
}

double percentile(std::vector<double> runs, double fraction) {
    std::sort(runs.begin(), runs.end());
    const std::size_t at = static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(runs.size()))) - 1;
    return runs[std::min(at, runs.size() - 1)];
}

std::size_t count_option(int argc, char** argv, std::string_view name, std::size_t fallback) {
    for (int index = 1; index + 1 < argc; ++index) {
        if (argv[index] != name) continue;
        char* end = nullptr;
        const unsigned long long value = std::strtoull(argv[index + 1], &end, 10);
        if (end == argv[index + 1] || *end != '\0' || value == 0 || value > 100000) {
            std::cerr << "falsify_method_bench: " << name << " '" << argv[index + 1]
                      << "' is not a whole number from 1 to 100000\n";
            std::exit(2);
        }
        return static_cast<std::size_t>(value);
    }
    return fallback;
}

}  // namespace

int main(int argc, char** argv) {
    for (int index = 1; index < argc; index += 2) {
        const std::string_view option = argv[index];
        if ((option != "--placements" && option != "--budget" && option != "--dimensions" &&
             option != "--band-permille") ||
            index + 1 >= argc) {
            std::cerr << "usage: falsify_method_bench [--placements N] [--budget N] [--dimensions N] "
                         "[--band-permille N]\n";
            return 2;
        }
    }
    const std::size_t placements = count_option(argc, argv, "--placements", 200);
    const std::size_t budget = count_option(argc, argv, "--budget", 30);
    const std::size_t dimensions = count_option(argc, argv, "--dimensions", 2);
    const std::size_t band_permille = count_option(argc, argv, "--band-permille", 10);
    if (dimensions > 20 || band_permille >= 400) {
        std::cerr << "falsify_method_bench: --dimensions: at most 20; --band-permille: below 400\n";
        return 2;
    }
    const double band_half_width = static_cast<double>(band_permille) / 2000.0;
    std::vector<VaryRange> space(dimensions);
    for (std::size_t key = 0; key < dimensions; ++key) {
        space[key].key = "x" + std::to_string(key);
        space[key].keys = {space[key].key};
        space[key].low = 0.0;
        space[key].high = 1.0;
    }
    std::cout << "falsifying band " << band_permille << " per mille of x0's range, placed at random " << placements
              << " times; " << dimensions
              << " parameter(s); budget " << budget << " points; the start design of rig falsify's default\n";
    for (const Shape shape : {Shape{"slope", 0.23}, Shape{"cliff", 0.0}}) {
        for (const SearchMethod method : {SearchMethod::crs2, SearchMethod::direct, SearchMethod::isres, SearchMethod::random}) {
            std::mt19937_64 placing(20261128);  // the same placements for every method
            std::uniform_real_distribution<double> centre_of(0.23, 1.0 - 0.23);  // the whole slope inside
            std::vector<double> runs;
            std::size_t found = 0;
            for (std::size_t placement = 0; placement < placements; ++placement) {
                BandEvaluator evaluator(shape, centre_of(placing), band_half_width);
                SearchOptions options;
                options.method = method;
                options.budget = budget;
                options.stop_at_first = true;
                options.seed = placement + 1;
                const SearchOutcome outcome = falsify_search(space, options, evaluator);
                if (outcome.first_falsifying) {
                    ++found;
                    runs.push_back(static_cast<double>(*outcome.first_falsifying + 1));
                } else {
                    runs.push_back(std::numeric_limits<double>::infinity());
                }
            }
            std::cout << shape.name << " " << search_method_name(method) << ": found in " << found << " of "
                      << placements << "; runs to the first: median " << runs_text(percentile(runs, 0.5), budget)
                      << ", 90th percentile " << runs_text(percentile(runs, 0.9), budget) << "\n";
        }
    }
    return 0;
}
