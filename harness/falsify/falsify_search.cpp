#include "harness/falsify/falsify_search.h"

#include <nlopt.hpp>

#include <algorithm>
#include <exception>
#include <map>
#include <optional>
#include <random>
#include <stdexcept>

#include "harness/falsify/latin_hypercube.h"

namespace rig::harness {

namespace {

// The search's state: every point evaluated, found again by its values.
class SearchState {
public:
    SearchState(const std::vector<VaryRange>& space, const SearchOptions& options, PointEvaluator& evaluator)
        : space_(space), options_(options), evaluator_(evaluator), values_(space.size(), 0.0),
          cell_limit_(options.budget) {
        for (std::size_t index = 0; index < space.size(); ++index) free_.push_back(index);
    }

    // Searches one cell from now on: the choice keys at the given choices
    // (their indexes, in the space's order), the other keys free, until the
    // outcome holds `limit` points.
    void enter_cell(const std::vector<double>& choices, std::size_t limit) {
        free_.clear();
        for (std::size_t index = 0, choice = 0; index < space_.size(); ++index) {
            if (space_[index].is_choice()) {
                values_[index] = choices.at(choice++);
            } else {
                free_.push_back(index);
            }
        }
        cell_limit_ = std::min(limit, options_.budget);
    }
    std::size_t free_dimensions() const { return free_.size(); }

    // A point of the free keys' unit cube, with the cell's choices.
    std::vector<double> values_of(const std::vector<double>& unit) const {
        std::vector<double> values = values_;
        for (std::size_t free = 0; free < free_.size(); ++free) {
            const VaryRange& range = space_[free_[free]];
            values[free_[free]] = snapped(range, range.low + std::clamp(unit[free], 0.0, 1.0) * (range.high - range.low));
        }
        return values;
    }

    // The whole search is over: its budget spent, its first falsifying
    // point found when asked for, or stopped.
    bool finished() const {
        return outcome_.points.size() >= options_.budget || (options_.stop_at_first && outcome_.first_falsifying) ||
               evaluator_.stopped();
    }
    // The cell's share of the budget is spent too.
    bool done() const { return finished() || outcome_.points.size() >= cell_limit_; }
    std::size_t left() const { return cell_limit_ - std::min(cell_limit_, outcome_.points.size()); }

    // Evaluates the unit points not yet evaluated (at most what the budget
    // leaves); returns each one's index in the outcome.
    std::vector<std::size_t> evaluate(const std::vector<std::vector<double>>& units, const std::string& phase) {
        std::vector<std::size_t> indexes;
        std::vector<std::vector<double>> fresh;
        for (const auto& unit : units) {
            std::vector<double> values = values_of(unit);
            if (const auto known = index_of_.find(values); known != index_of_.end()) {
                indexes.push_back(known->second);
                ++outcome_.repeated_requests;
                continue;
            }
            if (fresh.size() >= left()) break;
            if (std::find(fresh.begin(), fresh.end(), values) != fresh.end()) continue;
            fresh.push_back(std::move(values));
        }
        if (fresh.empty()) return indexes;
        const std::vector<RunMargin> margins = evaluator_.evaluate(fresh);
        for (std::size_t index = 0; index < fresh.size(); ++index) {
            const std::size_t at = outcome_.points.size();
            outcome_.points.push_back(SearchedPoint{fresh[index], margins.at(index), phase});
            index_of_[fresh[index]] = at;
            indexes.push_back(at);
            note(at);
        }
        return indexes;
    }

    // What NLopt minimises at a point: its margin; a broken point (no number)
    // lies below every margin seen, an invalid one (the rig's own error says
    // nothing of the controller) at the largest, so it attracts nothing.
    double objective_of(std::size_t index) const {
        const RunMargin& margin = outcome_.points[index].margin;
        if (margin.margin) return *margin.margin;
        if (!margin.broken.empty()) return std::min(lowest_, 0.0) - 1.0;
        return highest_;
    }

    // The cell's best point so far on its unit cube (the centre before any).
    std::vector<double> best_unit() const {
        std::vector<double> unit(free_.size(), 0.5);
        std::optional<std::size_t> best;
        for (std::size_t at = 0; at < outcome_.points.size(); ++at) {
            if (in_cell(outcome_.points[at].values) && (!best || objective_of(at) < objective_of(*best))) best = at;
        }
        if (!best) return unit;
        const std::vector<double>& values = outcome_.points[*best].values;
        for (std::size_t free = 0; free < free_.size(); ++free) {
            unit[free] = unit_of(space_[free_[free]], values[free_[free]]);
        }
        return unit;
    }

    SearchOutcome& outcome() { return outcome_; }

private:
    bool in_cell(const std::vector<double>& values) const {
        for (std::size_t index = 0; index < space_.size(); ++index) {
            if (space_[index].is_choice() && values[index] != values_[index]) return false;
        }
        return true;
    }

    void note(std::size_t at) {
        const RunMargin& margin = outcome_.points[at].margin;
        if (!outcome_.first_falsifying && margin.invalid.empty() && margin.falsifying()) outcome_.first_falsifying = at;
        if (margin.margin) {
            lowest_ = std::min(lowest_, *margin.margin);
            highest_ = std::max(highest_, *margin.margin);
        }
        if (!margin.invalid.empty() || (margin.broken.empty() && !margin.margin)) return;
        if (!outcome_.worst) {
            outcome_.worst = at;
            return;
        }
        const RunMargin& worst = outcome_.points[*outcome_.worst].margin;
        const bool broken = !margin.broken.empty();
        const bool worst_broken = !worst.broken.empty();
        if ((broken && !worst_broken) || (!broken && !worst_broken && *margin.margin < *worst.margin)) {
            outcome_.worst = at;
        }
    }

    const std::vector<VaryRange>& space_;
    const SearchOptions& options_;
    PointEvaluator& evaluator_;
    SearchOutcome outcome_;
    std::map<std::vector<double>, std::size_t> index_of_;
    double lowest_ = 0.0;
    double highest_ = 0.0;
    std::vector<std::size_t> free_;  // the keys the cell searches, by index in the space
    std::vector<double> values_;     // the cell's choices (at the choice keys' indexes)
    std::size_t cell_limit_;         // the points the outcome may hold at the cell's end
};

// Points on the unit cube in batches until the budget, or the first
// falsifying batch when asked.
void evaluate_in_batches(SearchState& state, const std::vector<std::vector<double>>& units, std::size_t batch,
                         const std::string& phase) {
    for (std::size_t first = 0; first < units.size() && !state.done(); first += batch) {
        const std::size_t last = std::min(units.size(), first + batch);
        state.evaluate(std::vector<std::vector<double>>(units.begin() + static_cast<std::ptrdiff_t>(first),
                                                        units.begin() + static_cast<std::ptrdiff_t>(last)),
                       phase);
    }
}

void random_search(SearchState& state, const SearchOptions& options, std::size_t dimensions) {
    std::mt19937_64 random(options.seed);
    while (!state.done()) {
        std::vector<std::vector<double>> batch;
        for (std::size_t k = 0; k < std::min(options.batch, state.left()); ++k) {
            std::vector<double> unit(dimensions);
            for (double& coordinate : unit) coordinate = unit_interval(random);
            batch.push_back(std::move(unit));
        }
        const std::size_t before = state.outcome().points.size();
        state.evaluate(batch, "random");
        // Random points of an integer space can all repeat known ones: then
        // the space is exhausted, as far as random draws go.
        if (state.outcome().points.size() == before && state.outcome().repeated_requests > 100 * options.budget) return;
    }
}

nlopt::algorithm nlopt_algorithm(SearchMethod method) {
    switch (method) {
        case SearchMethod::direct: return nlopt::GN_DIRECT_L;
        case SearchMethod::isres: return nlopt::GN_ISRES;
        default: return nlopt::GN_CRS2_LM;
    }
}

struct NloptCall {
    SearchState* state = nullptr;
    std::string phase;
    std::exception_ptr error;  // what the evaluator threw, rethrown after NLopt stops
};

double nlopt_objective(const std::vector<double>& unit, std::vector<double>& /*gradient*/, void* data) {
    auto* call = static_cast<NloptCall*>(data);
    if (call->state->done()) throw nlopt::forced_stop();
    try {
        const std::vector<std::size_t> at = call->state->evaluate({unit}, call->phase);
        if (at.empty()) throw nlopt::forced_stop();  // nothing left of the budget
        return call->state->objective_of(at.front());
    } catch (const nlopt::forced_stop&) {
        throw;
    } catch (...) {
        call->error = std::current_exception();
        throw nlopt::forced_stop();
    }
}

void nlopt_search(SearchState& state, const SearchOptions& options, std::size_t dimensions) {
    NloptCall call{&state, std::string(search_method_name(options.method)), nullptr};
    // A run of NLopt can end before the budget (DIRECT-L's boxes all divided
    // down to the rounding of an integer key, CRS2's population collapsed):
    // it starts again from the best point with fresh random numbers, a few times.
    constexpr int kStarts = 8;
    for (int start = 0; start < kStarts && !state.done(); ++start) {
        // CRS2 and ISRES draw their populations from NLopt's own generator.
        nlopt::srand(options.seed + static_cast<unsigned long>(start));
        nlopt::opt optimizer(nlopt_algorithm(options.method), static_cast<unsigned>(dimensions));
        optimizer.set_lower_bounds(std::vector<double>(dimensions, 0.0));
        optimizer.set_upper_bounds(std::vector<double>(dimensions, 1.0));
        optimizer.set_min_objective(nlopt_objective, &call);
        // The budget is counted in points run, not in NLopt's calls (a repeated
        // point costs none); this only bounds a search that repeats itself.
        optimizer.set_maxeval(static_cast<int>(std::min<std::size_t>(state.left() * 20 + 100, 1'000'000)));
        if (options.method == SearchMethod::crs2) {
            // NLopt's default, 10 (n + 1), would spend most of a small budget
            // on random points before the first reflection; the start design
            // already covered the space.
            optimizer.set_population(static_cast<unsigned>(std::max<std::size_t>(4 * (dimensions + 1), 8)));
        }
        std::vector<double> unit = state.best_unit();
        double found = 0.0;
        try {
            optimizer.optimize(unit, found);
        } catch (const nlopt::forced_stop&) {
        } catch (const nlopt::roundoff_limited&) {
        }
        if (call.error) std::rethrow_exception(call.error);
    }
}

}  // namespace

std::string_view search_method_name(SearchMethod method) {
    switch (method) {
        case SearchMethod::crs2: return "crs2";
        case SearchMethod::direct: return "direct";
        case SearchMethod::isres: return "isres";
        case SearchMethod::random: return "random";
    }
    return "crs2";
}

std::optional<SearchMethod> search_method_named(std::string_view name) {
    for (const SearchMethod method : {SearchMethod::crs2, SearchMethod::direct, SearchMethod::isres, SearchMethod::random}) {
        if (search_method_name(method) == name) return method;
    }
    return std::nullopt;
}

std::size_t default_start_points(std::size_t dimensions, std::size_t budget, std::size_t batch) {
    const std::size_t wanted = std::max(2 * dimensions + 1, batch);
    return std::max<std::size_t>(1, std::min(wanted, std::max<std::size_t>(1, budget / 3)));
}

std::size_t choice_cells(const std::vector<VaryRange>& space) {
    std::size_t cells = 1;
    for (const VaryRange& range : space) {
        if (range.is_choice()) cells *= range.choices.size();
    }
    return cells;
}

void check_choice_cells(const std::vector<VaryRange>& space, std::size_t budget) {
    if (const std::size_t cells = choice_cells(space); cells > budget) {
        throw std::invalid_argument("the choices give " + std::to_string(cells) + " combinations, each searched "
                                    "on its own, more than the budget of " + std::to_string(budget) +
                                    " points: raise --budget or list fewer choices");
    }
}

namespace {

// One cell's search over its free keys with the points the budget leaves it.
void search_cell(SearchState& state, const SearchOptions& options, std::uint64_t seed) {
    const std::size_t dimensions = state.free_dimensions();
    const std::size_t batch = std::max<std::size_t>(1, options.batch);
    SearchOptions cell = options;
    cell.seed = seed;
    cell.batch = batch;
    if (dimensions == 0) {  // only choices: the cell is one point
        state.evaluate({std::vector<double>{}}, "start");
        return;
    }
    if (options.method == SearchMethod::random) {
        random_search(state, cell, dimensions);
        return;
    }
    const std::size_t start = options.start_points > 0 ? std::min(options.start_points, state.left())
                                                       : default_start_points(dimensions, state.left(), batch);
    evaluate_in_batches(state, latin_hypercube(start, dimensions, seed), batch, "start");
    if (!state.done()) nlopt_search(state, cell, dimensions);
}

}  // namespace

SearchOutcome falsify_search(const std::vector<VaryRange>& space, const SearchOptions& options,
                             PointEvaluator& evaluator) {
    SearchState state(space, options, evaluator);
    // Choice keys split the search into cells, one per combination of
    // choices, each searched over the numeric keys with an even share of
    // what the budget leaves: a method that learns from margins would
    // otherwise settle on the choice its first good point had, however
    // badly another choice breaks (a choice has no slope to follow).
    check_choice_cells(space, options.budget);
    const std::size_t cells = choice_cells(space);
    for (std::size_t cell = 0; cell < cells && !state.finished(); ++cell) {
        std::vector<double> choices;
        std::size_t rest = cell;
        for (const VaryRange& range : space) {
            if (!range.is_choice()) continue;
            choices.push_back(static_cast<double>(rest % range.choices.size()));
            rest /= range.choices.size();
        }
        const std::size_t used = state.outcome().points.size();
        state.enter_cell(choices, used + (options.budget - used) / (cells - cell));
        // Without choices the one cell's seed is the search's, as before choices existed.
        search_cell(state, options, options.seed + cell);
    }
    return state.outcome();
}

}  // namespace rig::harness
