#include "harness/regression/rank_statistics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <numeric>
#include <stdexcept>

namespace rig::harness {

namespace {

// The exact null distribution of U (pairs with head above base) for sample
// sizes m and n without ties: P(U = u) for u in [0, m n]. Each arrangement of
// the m + n values is equally likely under no change; adding the largest
// value last, it is a head value (above all i base values, U grows by i) with
// probability n / (m + n), else a base value (U unchanged):
//   P_{i,j}(u) = i/(i+j) P_{i-1,j}(u) + j/(i+j) P_{i,j-1}(u - i).
std::vector<double> exact_u_distribution(std::size_t m, std::size_t n) {
    // row[i][u] holds P_{i,j}(u) for the current j.
    std::vector<std::vector<double>> row(m + 1, std::vector<double>(m * n + 1, 0.0));
    for (std::size_t i = 0; i <= m; ++i) row[i][0] = 1.0;  // j = 0: U = 0
    for (std::size_t j = 1; j <= n; ++j) {
        std::vector<std::vector<double>> next(m + 1, std::vector<double>(m * n + 1, 0.0));
        next[0][0] = 1.0;  // i = 0: U = 0
        for (std::size_t i = 1; i <= m; ++i) {
            const double total = static_cast<double>(i + j);
            for (std::size_t u = 0; u <= i * j; ++u) {
                double p = static_cast<double>(i) / total * next[i - 1][u];
                if (u >= i) p += static_cast<double>(j) / total * row[i][u - i];
                next[i][u] = p;
            }
        }
        row = std::move(next);
    }
    return row[m];
}

constexpr std::size_t kExactLimit = 50;

// A comparison of a whole suite asks for the same sizes hundreds of times.
const std::vector<double>& cached_u_distribution(std::size_t m, std::size_t n) {
    static std::mutex mutex;
    static std::map<std::pair<std::size_t, std::size_t>, std::vector<double>> known;
    std::lock_guard lock(mutex);
    auto found = known.find({m, n});
    if (found == known.end()) found = known.emplace(std::make_pair(m, n), exact_u_distribution(m, n)).first;
    return found->second;
}

}  // namespace

double normal_upper_tail(double z) { return 0.5 * std::erfc(z / std::sqrt(2.0)); }

double normal_upper_quantile(double p) {
    if (!(p > 0.0 && p < 1.0)) throw std::invalid_argument("normal_upper_quantile: p must be in (0, 1)");
    // Bisection on the tail, which erfc gives to full precision: 200 halvings
    // of [-40, 40] are far below a double's resolution.
    double low = -40.0, high = 40.0;
    for (int step = 0; step < 200; ++step) {
        const double middle = 0.5 * (low + high);
        if (normal_upper_tail(middle) > p) {
            low = middle;
        } else {
            high = middle;
        }
    }
    return 0.5 * (low + high);
}

RankTest mann_whitney(const std::vector<double>& base, const std::vector<double>& head) {
    RankTest test;
    const std::size_t m = base.size(), n = head.size();
    if (m == 0 || n == 0) return test;
    struct Ranked {
        double value;
        bool head;
    };
    std::vector<Ranked> all;
    all.reserve(m + n);
    for (double value : base) all.push_back({value, false});
    for (double value : head) all.push_back({value, true});
    for (const Ranked& value : all) {
        if (std::isnan(value.value)) throw std::invalid_argument("mann_whitney: a sample is NaN");
    }
    std::sort(all.begin(), all.end(), [](const Ranked& a, const Ranked& b) { return a.value < b.value; });
    // Mid-ranks over runs of ties; the tie term of the variance.
    double head_rank_sum = 0.0, tie_term = 0.0;
    bool ties = false;
    for (std::size_t start = 0; start < all.size();) {
        std::size_t end = start;
        while (end < all.size() && all[end].value == all[start].value) ++end;
        const double count = static_cast<double>(end - start);
        const double mid_rank = (static_cast<double>(start + 1) + static_cast<double>(end)) / 2.0;
        for (std::size_t k = start; k < end; ++k) {
            if (all[k].head) head_rank_sum += mid_rank;
        }
        if (count > 1) {
            ties = true;
            tie_term += count * count * count - count;
        }
        start = end;
    }
    const double dm = static_cast<double>(m), dn = static_cast<double>(n), total = dm + dn;
    test.u = head_rank_sum - dn * (dn + 1.0) / 2.0;
    if (!ties && m <= kExactLimit && n <= kExactLimit) {
        test.exact = true;
        const std::vector<double>& distribution = cached_u_distribution(m, n);
        const auto observed = static_cast<std::size_t>(std::llround(test.u));
        double at_or_above = 0.0, at_or_below = 0.0;
        for (std::size_t u = 0; u < distribution.size(); ++u) {
            if (u >= observed) at_or_above += distribution[u];
            if (u <= observed) at_or_below += distribution[u];
        }
        test.p_greater = std::min(1.0, at_or_above);
        test.p_less = std::min(1.0, at_or_below);
    } else {
        const double mean = dm * dn / 2.0;
        const double variance = dm * dn / 12.0 * ((total + 1.0) - tie_term / (total * (total - 1.0)));
        if (variance <= 0.0) {
            // Every value the same on both sides: nothing moved.
            test.p_greater = test.p_less = 1.0;
        } else {
            const double sd = std::sqrt(variance);
            // Continuity correction of half a pair towards the mean.
            test.p_greater = normal_upper_tail((test.u - mean - 0.5) / sd);
            test.p_less = normal_upper_tail((mean - test.u - 0.5) / sd);
        }
    }
    test.p_two_sided = std::min(1.0, 2.0 * std::min(test.p_greater, test.p_less));
    return test;
}

Shift hodges_lehmann(const std::vector<double>& base, const std::vector<double>& head, double confidence) {
    Shift shift;
    std::vector<double> differences;
    differences.reserve(base.size() * head.size());
    for (double b : base) {
        for (double h : head) {
            if (std::isfinite(b) && std::isfinite(h)) differences.push_back(h - b);
        }
    }
    if (differences.empty()) return shift;
    std::sort(differences.begin(), differences.end());
    const std::size_t count = differences.size();
    shift.estimate = count % 2 == 1 ? differences[count / 2]
                                    : 0.5 * (differences[count / 2 - 1] + differences[count / 2]);
    // The interval's ends are the (k+1)-th smallest and largest differences,
    // k the largest count with P(U <= k) <= (1 - confidence) / 2 under no
    // change (Hollander et al. sec. 4.3); the normal approximation of U's
    // distribution gives k. Over the finite pairs only: runs that gave no
    // value move the test, not the size of the shift.
    std::size_t finite_base = 0, finite_head = 0;
    for (double b : base) finite_base += std::isfinite(b) ? 1 : 0;
    for (double h : head) finite_head += std::isfinite(h) ? 1 : 0;
    const double mn = static_cast<double>(finite_base) * static_cast<double>(finite_head);
    const double sd = std::sqrt(mn * (static_cast<double>(finite_base + finite_head) + 1.0) / 12.0);
    const double z = normal_upper_quantile((1.0 - confidence) / 2.0);
    const double k = std::floor(mn / 2.0 - z * sd);
    if (k >= 0.0 && static_cast<std::size_t>(k) < count) {
        const auto index = static_cast<std::size_t>(k);
        shift.low = differences[index];
        shift.high = differences[count - 1 - index];
    }
    return shift;
}

std::vector<double> holm_adjusted(const std::vector<double>& p_values) {
    const std::size_t count = p_values.size();
    std::vector<std::size_t> order(count);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return p_values[a] < p_values[b]; });
    std::vector<double> adjusted(count, 1.0);
    double running = 0.0;
    for (std::size_t rank = 0; rank < count; ++rank) {
        const double scaled = std::min(1.0, static_cast<double>(count - rank) * p_values[order[rank]]);
        running = std::max(running, scaled);  // step-down: never below an earlier one
        adjusted[order[rank]] = running;
    }
    return adjusted;
}

}  // namespace rig::harness
