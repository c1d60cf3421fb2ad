#pragma once
// Change points in a metric's history (docs/history.md "How a change point is
// found"): the commits at which a metric's distribution over seeds stepped.
//
// The method, and why:
//  - The test statistic is the rank statistic of Pettitt (1979, "A
//    non-parametric approach to the change-point problem", Applied Statistics
//    28(2)): at each boundary between two commits, the Mann-Whitney count of
//    pairs (earlier value, later value) out of order, taken over every seed's
//    value of every commit, not the commits' medians, so that 30 seeds a
//    commit give 30 times the evidence of one. Ranks make it blind to the
//    shape of a metric's spread over seeds and to its outliers, and carry a
//    run that measured nothing as the worst value.
//  - Each boundary's count is standardised by its spread under no change (the
//    Mann-Whitney change-point statistic of Hawkins and Deng, "A nonparametric
//    change-point control chart", J. Quality Technology 42(2), 2010), so that
//    a step at the newest commit, with one commit's seeds after it, is as
//    visible as one in the middle; Pettitt's raw count favours the middle.
//  - Its p-value is a permutation test over the values (under no change every
//    order of them is equally likely), with a fixed-seed generator so that the
//    same history gives the same answer, stopped early once the p-value
//    cannot fall below alpha (Besag and Clifford, "Sequential Monte Carlo
//    p-values", Biometrika 78(2), 1991). The permutations take the maximum
//    over every boundary as the observed one does, so the chance of a change
//    point in a series of noise alone is alpha, however many commits it has.
//  - More than one step is found by binary segmentation (Scott and Knott,
//    Biometrics 30, 1974; Vostrikova, Soviet Math. Dokl. 24, 1981): a found
//    change point splits the series and each side is tested again, as
//    E-Divisive does (Matteson and James, JASA 109, 2014; MongoDB's CI, Daly
//    et al., ICPE 2020).
//  - A change is news only when the medians on its two sides differ by at
//    least the metric's min effect (the case's compare.min_effect, else
//    harness/judge/metric_direction.h's): boundaries with a smaller shift are
//    dropped, the smallest first, and their neighbours' sides merged.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "harness/judge/metric_direction.h"
#include "harness/regression/history_store.h"

namespace rig::harness {

struct ChangePointOptions {
    double alpha = 0.01;             // the chance of a change point in a series of noise alone
    std::size_t permutations = 999;  // at most; p-values resolve to 1 / (permutations + 1)
    std::uint64_t prng_seed = 0x5eed'2026'0026ULL;
};

struct ChangePoint {
    std::size_t group = 0;  // the first group (commit) after the step
    double p_value = 1.0;   // of the split that found it
    double before_median = 0.0, after_median = 0.0;  // over the segments on either side (+-inf: mostly not measured)
    double shift = 0.0;                              // after - before (0 when both are the same infinity)
    std::size_t before_values = 0, after_values = 0;
    bool worse = false;  // moved the declared worse way by at least the min effect
};

// The change points of a series of groups (one group per commit, each its
// seeds' values; +-inf allowed, NaN not; empty groups allowed and never a side
// of their own), in group order.
std::vector<ChangePoint> find_change_points(const std::vector<std::vector<double>>& groups, WorseDirection worse,
                                            double min_effect, const ChangePointOptions& options);

// A history series judged: its direction and min effect, and its change points.
struct SeriesChangePoints {
    WorseDirection worse = WorseDirection::none;
    bool declared = false;         // metric_direction.h declares the metric
    double min_effect = 0.0;       // the one used
    std::string min_effect_from;   // "case" (compare.min_effect at the newest commit having it), "declared" or "none"
    std::vector<ChangePoint> change_points;  // ChangePoint::group indexes the series' points
};

// A run that measured nothing counts as the worst value (+inf when worse is up
// or away from zero, -inf when down); for a metric that is neither it is left out.
SeriesChangePoints series_change_points(const HistorySeries& series, const ChangePointOptions& options);

}  // namespace rig::harness
