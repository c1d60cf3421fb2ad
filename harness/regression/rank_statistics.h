#pragma once
// Rank statistics for comparing a metric over two sets of seeds
// (docs/regression.md "How a shift is called"): the Mann-Whitney U test, the
// Hodges-Lehmann shift with its distribution-free confidence interval, and
// Holm's step-down correction over the metrics compared.
//
// Why ranks: a metric over seeds is rarely normal (a flow that settles or
// not, a wet edge quantised to the deposition raster), and a run that did
// not measure a metric at all is "worse than any value", which ranks carry
// and means cannot. References: Mann and Whitney (1947); Hollander, Wolfe and
// Chicken, Nonparametric Statistical Methods, 3rd ed. (2014), sec. 4.1-4.3
// (the U test's exact null distribution, its normal approximation with the
// tie correction, and the Hodges-Lehmann estimator and interval); Holm,
// "A simple sequentially rejective multiple test procedure", Scand. J.
// Statist. 6 (1979).
#include <cstddef>
#include <optional>
#include <vector>

namespace rig::harness {

struct RankTest {
    double u = 0.0;             // pairs (base, new) with new above base, ties counting half
    double p_greater = 1.0;     // one-sided: new tends above base
    double p_less = 1.0;        // one-sided: new tends below base
    double p_two_sided = 1.0;   // 2 x the smaller one-sided p, at most 1
    bool exact = false;         // exact null distribution (no ties, both sides <= 50), else normal
};

// The U test of `base` against `head`. Values may be +-infinity (a run that
// gave no value, ranked as the worst); NaN is not allowed (throws
// std::invalid_argument). Either side empty: p = 1.
RankTest mann_whitney(const std::vector<double>& base, const std::vector<double>& head);

struct Shift {
    std::optional<double> estimate;  // median of head - base over the finite pairs; none when there is none
    // The distribution-free interval of the shift at `confidence`
    // (order statistics of the pairwise differences); none where it is unbounded.
    std::optional<double> low, high;
};
Shift hodges_lehmann(const std::vector<double>& base, const std::vector<double>& head, double confidence);

// Holm's adjusted p-values, in the order given: each test is called at level
// alpha when its adjusted p is below alpha, and the chance that any of the
// family is called when none has changed stays at most alpha.
std::vector<double> holm_adjusted(const std::vector<double>& p_values);

// The standard normal's upper-tail probability and its inverse (for 0 < p < 1).
double normal_upper_tail(double z);
double normal_upper_quantile(double p);

}  // namespace rig::harness
