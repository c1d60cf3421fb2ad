#include "harness/regression/history_change_points.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>

namespace rig::harness {

namespace {

// Mid-ranks (from 1) of the values: a run of ties shares the mean of its ranks.
std::vector<double> mid_ranks(const std::vector<double>& values) {
    std::vector<std::size_t> order(values.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
    std::vector<double> ranks(values.size());
    for (std::size_t start = 0; start < order.size();) {
        std::size_t end = start;
        while (end < order.size() && values[order[end]] == values[order[start]]) ++end;
        const double mid = (static_cast<double>(start + 1) + static_cast<double>(end)) / 2.0;
        for (std::size_t k = start; k < end; ++k) ranks[order[k]] = mid;
        start = end;
    }
    return ranks;
}

// Hawkins and Deng's statistic over the boundaries of one segment: for the
// boundary before group s, |W_s - n_s (N + 1) / 2| / sqrt(n_s (N - n_s) (N + 1) / 12),
// W_s the rank sum of the n_s values before it (Pettitt's U_s is 2 W_s - n_s (N + 1)).
class BoundaryStatistic {
public:
    explicit BoundaryStatistic(const std::vector<std::size_t>& group_sizes) : sizes_(group_sizes) {
        total_ = std::accumulate(sizes_.begin(), sizes_.end(), std::size_t{0});
        const double n = static_cast<double>(total_);
        std::size_t before = 0;
        for (std::size_t s = 1; s < sizes_.size(); ++s) {
            before += sizes_[s - 1];
            const double m = static_cast<double>(before);
            spread_.push_back(std::sqrt(m * (n - m) * (n + 1.0) / 12.0));
            centre_.push_back(m * (n + 1.0) / 2.0);
        }
    }
    // The largest statistic and the group after its boundary (the first of equals).
    std::pair<double, std::size_t> maximum(const std::vector<double>& ranks) const {
        double best = 0.0;
        std::size_t best_group = 0;
        double rank_sum = 0.0;
        std::size_t position = 0;
        for (std::size_t s = 1; s < sizes_.size(); ++s) {
            for (std::size_t k = 0; k < sizes_[s - 1]; ++k) rank_sum += ranks[position++];
            const double statistic = std::abs(rank_sum - centre_[s - 1]) / spread_[s - 1];
            if (statistic > best) {
                best = statistic;
                best_group = s;
            }
        }
        return {best, best_group};
    }
    std::size_t total() const { return total_; }

private:
    std::vector<std::size_t> sizes_;
    std::size_t total_ = 0;
    std::vector<double> spread_, centre_;
};

// An integer uniform in [0, bound) from the generator's raw output by
// rejection: std::uniform_int_distribution's algorithm is the library's own,
// and the same history must give the same p-values wherever it is read.
std::size_t uniform_below(std::mt19937_64& generator, std::size_t bound) {
    const std::uint64_t range = static_cast<std::uint64_t>(bound);
    const std::uint64_t limit = std::numeric_limits<std::uint64_t>::max() - std::numeric_limits<std::uint64_t>::max() % range;
    std::uint64_t draw = 0;
    do {
        draw = generator();
    } while (draw >= limit);
    return static_cast<std::size_t>(draw % range);
}

struct Split {
    std::size_t group = 0;  // within the segment: the first group after the boundary
    double p_value = 1.0;
    bool significant = false;
};

// The best boundary of a segment (groups all non-empty) and its permutation p-value.
Split best_split(const std::vector<std::vector<double>>& groups, const ChangePointOptions& options) {
    Split split;
    if (groups.size() < 2) return split;
    std::vector<double> values;
    std::vector<std::size_t> sizes;
    for (const std::vector<double>& group : groups) {
        values.insert(values.end(), group.begin(), group.end());
        sizes.push_back(group.size());
    }
    const BoundaryStatistic statistic(sizes);
    std::vector<double> ranks = mid_ranks(values);
    const auto [observed, group] = statistic.maximum(ranks);
    split.group = group;
    if (observed <= 0.0) return split;  // every value the same
    // Besag and Clifford: stop at the exceedance that puts (exceedances + 1) /
    // (permutations + 1) above alpha, and estimate p as exceedances / done.
    const double allowed = options.alpha * static_cast<double>(options.permutations + 1);
    const double at_least = observed * (1.0 - 1e-12);  // the observed order itself reaches it
    std::mt19937_64 generator(options.prng_seed);
    std::size_t exceedances = 0;
    for (std::size_t done = 1; done <= options.permutations; ++done) {
        for (std::size_t i = ranks.size() - 1; i > 0; --i) std::swap(ranks[i], ranks[uniform_below(generator, i + 1)]);
        if (statistic.maximum(ranks).first >= at_least) ++exceedances;
        if (static_cast<double>(exceedances + 1) > allowed + 1e-9) {
            split.p_value = static_cast<double>(exceedances) / static_cast<double>(done);
            return split;
        }
    }
    split.p_value = static_cast<double>(exceedances + 1) / static_cast<double>(options.permutations + 1);
    split.significant = split.p_value <= options.alpha + 1e-12;
    return split;
}

struct Boundary {
    std::size_t group = 0;  // in the compacted series
    double p_value = 1.0;
};

// Binary segmentation of groups [first, last): a significant split is kept and both sides tested again.
void segment(const std::vector<std::vector<double>>& groups, std::size_t first, std::size_t last,
             const ChangePointOptions& options, std::vector<Boundary>& found) {
    if (last - first < 2) return;
    const std::vector<std::vector<double>> part(groups.begin() + static_cast<std::ptrdiff_t>(first),
                                                groups.begin() + static_cast<std::ptrdiff_t>(last));
    const Split split = best_split(part, options);
    if (!split.significant) return;
    found.push_back({first + split.group, split.p_value});
    segment(groups, first, first + split.group, options, found);
    segment(groups, first + split.group, last, options, found);
}

double median_of(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const std::size_t half = values.size() / 2;
    if (values.size() % 2 == 1) return values[half];
    const double low = values[half - 1], high = values[half];
    return low == high ? low : (low + high) / 2.0;  // (inf + inf) / 2 is inf; -inf and +inf never share a series
}

// after - before, 0 when both are the same infinity.
double shift_between(double before, double after) { return before == after ? 0.0 : after - before; }

bool moved_worse(WorseDirection worse, double before, double after, double min_effect) {
    if (!is_worse(worse, before, after)) return false;
    const double moved = worse == WorseDirection::away_from_zero ? std::abs(after) - std::abs(before)
                                                                 : std::abs(shift_between(before, after));
    return moved >= min_effect;
}

}  // namespace

std::vector<ChangePoint> find_change_points(const std::vector<std::vector<double>>& groups, WorseDirection worse,
                                            double min_effect, const ChangePointOptions& options) {
    if (!(options.alpha > 0.0 && options.alpha < 1.0)) throw std::invalid_argument("alpha must be between 0 and 1");
    if (options.permutations == 0) throw std::invalid_argument("permutations must be at least 1");
    // Empty groups (a commit with no value) take no side of their own.
    std::vector<std::vector<double>> compact;
    std::vector<std::size_t> original;
    for (std::size_t index = 0; index < groups.size(); ++index) {
        for (double value : groups[index]) {
            if (std::isnan(value)) throw std::invalid_argument("a change point series holds NaN");
        }
        if (groups[index].empty()) continue;
        compact.push_back(groups[index]);
        original.push_back(index);
    }
    std::vector<Boundary> boundaries;
    segment(compact, 0, compact.size(), options, boundaries);
    std::sort(boundaries.begin(), boundaries.end(), [](const Boundary& a, const Boundary& b) { return a.group < b.group; });

    auto values_between = [&](std::size_t first, std::size_t last) {
        std::vector<double> values;
        for (std::size_t g = first; g < last; ++g) values.insert(values.end(), compact[g].begin(), compact[g].end());
        return values;
    };
    // Drop the boundary with the smallest shift below the min effect until none is left.
    std::vector<ChangePoint> points;
    for (;;) {
        points.clear();
        for (std::size_t i = 0; i < boundaries.size(); ++i) {
            const std::size_t first = i == 0 ? 0 : boundaries[i - 1].group;
            const std::size_t last = i + 1 == boundaries.size() ? compact.size() : boundaries[i + 1].group;
            const std::vector<double> before = values_between(first, boundaries[i].group);
            const std::vector<double> after = values_between(boundaries[i].group, last);
            ChangePoint point;
            point.group = boundaries[i].group;
            point.p_value = boundaries[i].p_value;
            point.before_median = median_of(before);
            point.after_median = median_of(after);
            point.shift = shift_between(point.before_median, point.after_median);
            point.before_values = before.size();
            point.after_values = after.size();
            points.push_back(point);
        }
        std::size_t smallest = points.size();
        for (std::size_t i = 0; i < points.size(); ++i) {
            const double size = std::abs(points[i].shift);
            if ((size == 0.0 || size < min_effect) && (smallest == points.size() || size < std::abs(points[smallest].shift))) {
                smallest = i;
            }
        }
        if (smallest == points.size()) break;
        boundaries.erase(boundaries.begin() + static_cast<std::ptrdiff_t>(smallest));
    }
    for (ChangePoint& point : points) {
        point.worse = moved_worse(worse, point.before_median, point.after_median, min_effect);
        point.group = original[point.group];
    }
    return points;
}

SeriesChangePoints series_change_points(const HistorySeries& series, const ChangePointOptions& options) {
    SeriesChangePoints judged;
    if (const std::optional<MetricDeclaration> declaration = declared_metric(series.metric)) {
        judged.declared = true;
        judged.worse = declaration->worse;
        judged.min_effect = declaration->min_effect;
        judged.min_effect_from = "declared";
    } else {
        judged.min_effect_from = "none";
    }
    for (auto point = series.points.rbegin(); point != series.points.rend(); ++point) {
        if (point->case_min_effect) {
            judged.min_effect = *point->case_min_effect;
            judged.min_effect_from = "case";
            break;
        }
    }
    const double worst = judged.worse == WorseDirection::down ? -std::numeric_limits<double>::infinity()
                                                              : std::numeric_limits<double>::infinity();
    std::vector<std::vector<double>> groups;
    for (const HistoryPoint& point : series.points) {
        std::vector<double> values;
        for (const SeedValue& seed : point.seeds) {
            if (seed.value) {
                values.push_back(*seed.value);
            } else if (judged.worse != WorseDirection::none) {
                values.push_back(worst);
            }
        }
        groups.push_back(std::move(values));
    }
    judged.change_points = find_change_points(groups, judged.worse, judged.min_effect, options);
    return judged;
}

}  // namespace rig::harness
