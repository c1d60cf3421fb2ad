#pragma once
// The search of `rig falsify` (issue 30): the point of a case's parameter
// space with the smallest robustness margin (harness/falsify/robustness.h),
// or the first that breaks a limit.
//
//   1. A Latin hypercube start design (harness/falsify/latin_hypercube.h),
//      evaluated in batches of `batch` points at once.
//   2. A global derivative-free method of NLopt on the margin, started from
//      the design's best point: CRS2 with local mutation (the default),
//      DIRECT-L or ISRES. NLopt asks for one point at a time, each answer
//      steering the next, so this phase evaluates points one by one (a
//      point's seeds run at once); a point it asks for again (an integer key
//      rounds two coordinates to one value) is answered from the points
//      already run and costs nothing.
//   Or plain random sampling (`random`) with the same budget, batched like
//   the start design: the baseline the benchmark compares with.
//
// With choice keys, the space is cut into one cell per combination of
// choices, and each cell is searched so, the numeric keys free, with an even
// share of the budget left.
//
// It stops when `budget` points have been evaluated, or after the first
// falsifying point when asked. The search works on the unit cube, each
// coordinate mapped onto its key's range and snapped (search_space.h).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "harness/falsify/robustness.h"
#include "harness/falsify/search_space.h"

namespace rig::harness {

enum class SearchMethod { crs2, direct, isres, random };
std::string_view search_method_name(SearchMethod method);  // "crs2", "direct", "isres", "random"
std::optional<SearchMethod> search_method_named(std::string_view name);
inline constexpr std::string_view kSearchMethodNames = "crs2, direct, isres or random";

// Runs the points a search asks for: the case with each point's values.
class PointEvaluator {
public:
    virtual ~PointEvaluator() = default;
    // One margin per point, in order (values in the keys' units, snapped).
    // Several points are evaluated at once as far as the evaluator can.
    virtual std::vector<RunMargin> evaluate(const std::vector<std::vector<double>>& points) = 0;
    // The search is to stop now (SIGINT): what was evaluated is its outcome.
    virtual bool stopped() const { return false; }
};

struct SearchOptions {
    SearchMethod method = SearchMethod::crs2;
    std::size_t budget = 60;        // points evaluated at most (>= 1)
    std::size_t start_points = 0;   // of them in the start design; 0: default_start_points()
    std::size_t batch = 1;          // points evaluated at once in the start design and by `random`
    bool stop_at_first = false;     // stop after the first falsifying point
    std::uint64_t seed = 1;         // of the design, of NLopt's own random numbers, of `random`
};

// The start design's size when not given: two points per parameter and one,
// at least a batch, at most a third of the budget (the rest is the method's).
std::size_t default_start_points(std::size_t dimensions, std::size_t budget, std::size_t batch);

struct SearchedPoint {
    std::vector<double> values;  // in the keys' units
    RunMargin margin;
    std::string phase;           // "start", or the method's name
};

struct SearchOutcome {
    std::vector<SearchedPoint> points;  // in the order evaluated
    std::optional<std::size_t> first_falsifying;
    // The smallest margin (a broken point first): none when every point was invalid.
    std::optional<std::size_t> worst;
    std::size_t repeated_requests = 0;  // points NLopt asked for again (answered without a run)
};

// The number of combinations of the space's choice keys' choices (1 without
// any): the search runs one cell per combination, each over the numeric keys.
std::size_t choice_cells(const std::vector<VaryRange>& space);
// Throws std::invalid_argument, saying what to do, when the choices give more
// cells than the budget has points.
void check_choice_cells(const std::vector<VaryRange>& space, std::size_t budget);

// Throws std::invalid_argument when the choices give more cells than the budget.
SearchOutcome falsify_search(const std::vector<VaryRange>& space, const SearchOptions& options,
                             PointEvaluator& evaluator);

}  // namespace rig::harness
