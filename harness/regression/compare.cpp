#include "harness/regression/compare.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "harness/report/sweep.h"
#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

std::string rig_of(const RunSamples& samples) {
    if (samples.rig_version.empty() && samples.rig_commit.empty()) return "unknown";
    return samples.rig_version + " (" + (samples.rig_commit.empty() ? "commit unknown" : samples.rig_commit) + ")";
}

const CaseSamples* find_case(const RunSamples& samples, const std::string& name) {
    for (const CaseSamples& one : samples.cases) {
        if (one.name == name) return &one;
    }
    return nullptr;
}

std::optional<double> median_of(std::vector<double> values) {
    if (values.empty()) return std::nullopt;
    std::sort(values.begin(), values.end());
    return percentile_of_sorted(values, 50.0);
}

MetricSide side_of(const CaseSamples& samples, const std::string& metric) {
    MetricSide side;
    side.runs = samples.runs.size();
    for (const RunSample& run : samples.runs) {
        if (const auto value = run.metrics.find(metric); value != run.metrics.end()) {
            side.values.push_back(value->second);
        } else if (side.not_measured_reason.empty()) {
            const auto why = run.not_measured.find(metric);
            side.not_measured_reason = why != run.not_measured.end() ? why->second : "the run gave no value (" + run.run + ")";
        }
    }
    side.measured = side.values.size();
    side.median = median_of(side.values);
    if (!side.values.empty()) {
        side.min = *std::min_element(side.values.begin(), side.values.end());
        side.max = *std::max_element(side.values.begin(), side.values.end());
    }
    return side;
}

bool metric_appears(const CaseSamples& samples, const std::string& metric) {
    for (const RunSample& run : samples.runs) {
        if (run.metrics.count(metric) || run.not_measured.count(metric)) return true;
    }
    return false;
}

// The digests one side's runs agree on, or "" when unknown or not agreed.
std::set<std::string> digests_of(const CaseSamples& samples, std::string RunSample::*digest) {
    std::set<std::string> digests;
    for (const RunSample& run : samples.runs) {
        if (!(run.*digest).empty()) digests.insert(run.*digest);
    }
    return digests;
}

bool digests_differ(const CaseSamples& base, const CaseSamples& head, std::string RunSample::*digest) {
    const std::set<std::string> a = digests_of(base, digest), b = digests_of(head, digest);
    return !a.empty() && !b.empty() && a != b;
}

std::string seeds_text(const std::vector<std::uint64_t>& seeds) {
    if (seeds.empty()) return "none";
    // Runs of consecutive seeds as "1-30": a sweep's seeds are usually one run.
    std::string text;
    for (std::size_t i = 0; i < seeds.size();) {
        std::size_t j = i;
        while (j + 1 < seeds.size() && seeds[j + 1] == seeds[j] + 1) ++j;
        if (!text.empty()) text += ", ";
        text += std::to_string(seeds[i]);
        if (j > i) text += "-" + std::to_string(seeds[j]);
        i = j + 1;
    }
    return text;
}

// The metric's value on the scale its direction reads: |v| for a signed
// error; a run that gave no value is the worst on that scale.
std::vector<double> judged_scale(const MetricSide& side, WorseDirection worse) {
    std::vector<double> values;
    for (double value : side.values) values.push_back(worse == WorseDirection::away_from_zero ? std::fabs(value) : value);
    const double worst = worse == WorseDirection::down ? -kInfinity : kInfinity;
    if (worse != WorseDirection::none) {
        for (std::size_t k = side.measured; k < side.runs; ++k) values.push_back(worst);
    }
    return values;
}

// How much worse (> 0) or better (< 0) `shift` is on the judged scale.
double worse_by(WorseDirection worse, double shift) { return worse == WorseDirection::down ? -shift : shift; }

std::string value_text(double value) { return significant_text(value, 4); }

void choose_min_effect(MetricComparison& metric, const CaseSamples& base, const CaseSamples& head,
                       const CompareSettings& settings) {
    const auto declaration = declared_metric(metric.metric);
    metric.declared = declaration.has_value();
    metric.worse = declaration ? declaration->worse : WorseDirection::none;
    metric.min_effect = declaration ? declaration->min_effect : 0.0;
    metric.min_effect_from = "declared";
    for (const CaseSamples* side : {&base, &head}) {
        if (const auto found = side->min_effects.find(metric.metric); found != side->min_effects.end()) {
            metric.min_effect = found->second;
            metric.min_effect_from = "case file";
        }
    }
    if (const auto found = settings.min_effects.find(metric.metric); found != settings.min_effects.end()) {
        metric.min_effect = found->second;
        metric.min_effect_from = "command line";
    }
    for (const CaseSamples* side : {&base, &head}) {
        if (const auto limit = side->limits.find(metric.metric); limit != side->limits.end()) metric.limit = limit->second;
    }
}

std::string neither_why(const MetricComparison& metric) {
    if (!metric.declared) return "its direction is not declared (harness/judge/metric_direction.cpp)";
    const auto declaration = declared_metric(metric.metric);
    return std::string(declaration->why);
}

// One run a side at one seed: any difference is the controller's (or the
// case's, or the rig's), never noise.
void judge_exact(MetricComparison& metric, bool same_trace) {
    const MetricSide& base = metric.base;
    const MetricSide& head = metric.head;
    if (base.median && head.median) {
        metric.difference = *head.median - *base.median;
        if (*base.median != 0.0) metric.ratio = *head.median / *base.median;
    }
    if (same_trace) {
        metric.reason = "same behaviour: the same trace";
        return;
    }
    const bool directional = metric.worse != WorseDirection::none;
    if (base.median && !head.median) {
        metric.verdict = directional ? CompareVerdict::regressed : CompareVerdict::unchanged;
        metric.reason = "no longer measured: " + head.not_measured_reason;
        return;
    }
    if (!base.median && head.median) {
        metric.verdict = directional ? CompareVerdict::improved : CompareVerdict::unchanged;
        metric.reason = "measured now; the base did not: " + base.not_measured_reason;
        return;
    }
    if (!base.median) {
        metric.reason = "not measured on either side";
        return;
    }
    const double moved = *metric.difference;
    if (moved == 0.0) {
        metric.reason = "the same value";
        return;
    }
    if (!directional) {
        metric.reason = "moved by " + value_text(moved) + ", neither better nor worse: " + neither_why(metric);
        return;
    }
    const double scale_base = metric.worse == WorseDirection::away_from_zero ? std::fabs(*base.median) : *base.median;
    const double scale_head = metric.worse == WorseDirection::away_from_zero ? std::fabs(*head.median) : *head.median;
    const double worse = worse_by(metric.worse, scale_head - scale_base);
    if (std::fabs(worse) < metric.min_effect) {
        metric.reason = "moved by " + value_text(moved) + ", less than its minimum effect " + value_text(metric.min_effect);
        return;
    }
    metric.verdict = worse > 0.0 ? CompareVerdict::regressed : CompareVerdict::improved;
    metric.reason = value_text(*base.median) + " -> " + value_text(*head.median) + " (" + (moved > 0 ? "+" : "") +
                    value_text(moved) + ")";
}

// Many seeds: the test now, the verdict once Holm's correction knows the family.
void test_samples(MetricComparison& metric) {
    metric.difference.reset();
    if (metric.base.median && metric.head.median && *metric.base.median != 0.0) {
        metric.ratio = *metric.head.median / *metric.base.median;
    }
    const std::vector<double> base = judged_scale(metric.base, metric.worse);
    const std::vector<double> head = judged_scale(metric.head, metric.worse);
    if (base.empty() || head.empty()) return;
    metric.p_value = mann_whitney(base, head).p_two_sided;
}

void judge_samples(MetricComparison& metric, double alpha) {
    const std::vector<double> base = judged_scale(metric.base, metric.worse);
    const std::vector<double> head = judged_scale(metric.head, metric.worse);
    const Shift shift = hodges_lehmann(base, head, 1.0 - alpha);
    metric.difference = shift.estimate;
    metric.shift_low = shift.low;
    metric.shift_high = shift.high;
    const std::string p_text = metric.p_adjusted ? "p " + significant_text(*metric.p_adjusted, 2) + " after Holm" : "";
    if (!metric.p_value) {
        metric.reason = metric.base.measured == 0 && metric.head.measured == 0 ? "not measured on either side"
                                                                                : "no values to test";
        return;
    }
    if (metric.worse == WorseDirection::none) {
        metric.reason = "neither better nor worse: " + neither_why(metric);
        return;
    }
    if (!(*metric.p_adjusted < alpha)) {
        metric.reason = "no significant shift (" + p_text + ")";
        return;
    }
    const std::size_t base_lost = metric.base.runs - metric.base.measured;
    const std::size_t head_lost = metric.head.runs - metric.head.measured;
    const double worse = shift.estimate ? worse_by(metric.worse, *shift.estimate) : 0.0;
    // Runs that lost the metric are a change whatever the measured ones did.
    const bool lost_more = head_lost > base_lost, lost_fewer = head_lost < base_lost;
    const bool big_enough = std::fabs(worse) >= metric.min_effect;
    if ((worse > 0.0 && big_enough) || (lost_more && worse >= 0.0)) {
        metric.verdict = CompareVerdict::regressed;
    } else if ((worse < 0.0 && big_enough) || (lost_fewer && worse <= 0.0)) {
        metric.verdict = CompareVerdict::improved;
    } else {
        metric.reason = "significant (" + p_text + "), but the shift " + value_text(worse) +
                        " is less than its minimum effect " + value_text(metric.min_effect);
        return;
    }
    std::string text = "median " + (metric.base.median ? value_text(*metric.base.median) : std::string("none")) +
                       " -> " + (metric.head.median ? value_text(*metric.head.median) : std::string("none"));
    if (shift.estimate) {
        text += ", shift " + std::string(*shift.estimate > 0 ? "+" : "") + value_text(*shift.estimate);
        if (shift.low && shift.high) text += " [" + value_text(*shift.low) + ", " + value_text(*shift.high) + "]";
    }
    if (base_lost != head_lost) {
        text += ", not measured in " + std::to_string(base_lost) + " -> " + std::to_string(head_lost) + " runs";
    }
    metric.reason = text + " (" + p_text + ")";
}

std::string case_reason(const CaseComparison& one) {
    std::vector<std::string> regressed, improved;
    for (const MetricComparison& metric : one.metrics) {
        if (metric.verdict == CompareVerdict::regressed) regressed.push_back(metric.metric);
        if (metric.verdict == CompareVerdict::improved) improved.push_back(metric.metric);
    }
    auto listed = [](const std::vector<std::string>& names) {
        std::string text;
        for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
        return text;
    };
    if (!regressed.empty()) return std::to_string(regressed.size()) + " regressed: " + listed(regressed);
    if (!improved.empty()) return std::to_string(improved.size()) + " improved: " + listed(improved);
    if (one.paired_seeds > 0 && one.same_traces == one.paired_seeds) {
        return "same behaviour: " + std::to_string(one.same_traces) + " of " + std::to_string(one.paired_seeds) +
               " traces identical";
    }
    return "no metric moved by its minimum effect";
}

}  // namespace

std::string_view compare_verdict_name(CompareVerdict verdict) {
    switch (verdict) {
        case CompareVerdict::regressed: return "regressed";
        case CompareVerdict::improved: return "improved";
        case CompareVerdict::unchanged: return "unchanged";
        case CompareVerdict::not_comparable: return "not_comparable";
    }
    return "unchanged";
}

std::size_t Comparison::regressions() const {
    const auto found = metric_counts.find(CompareVerdict::regressed);
    return found == metric_counts.end() ? 0 : found->second;
}

Comparison compare_runs(const RunSamples& base, const RunSamples& head, const CompareSettings& settings) {
    Comparison comparison;
    comparison.base_source = base.source.string();
    comparison.head_source = head.source.string();
    comparison.base_kind = base.kind;
    comparison.head_kind = head.kind;
    comparison.base_rig = rig_of(base);
    comparison.head_rig = rig_of(head);
    comparison.rig_differs = comparison.base_rig != comparison.head_rig;
    comparison.settings = settings;

    std::set<std::string> names;
    for (const CaseSamples& one : base.cases) names.insert(one.name);
    for (const CaseSamples& one : head.cases) names.insert(one.name);
    std::vector<MetricComparison*> family;
    for (const std::string& name : names) {
        CaseComparison one;
        one.name = name;
        const CaseSamples* base_case = find_case(base, name);
        const CaseSamples* head_case = find_case(head, name);
        if (base_case == nullptr || head_case == nullptr) {
            one.verdict = CompareVerdict::not_comparable;
            one.reason = base_case == nullptr ? "only in the head" : "only in the base";
            (base_case ? one.base_file : one.head_file) = (base_case ? base_case : head_case)->file;
            comparison.cases.push_back(std::move(one));
            continue;
        }
        one.base_file = base_case->file;
        one.head_file = head_case->file;
        for (const RunSample& run : base_case->runs) one.base_seeds.push_back(run.seed);
        for (const RunSample& run : head_case->runs) one.head_seeds.push_back(run.seed);
        for (const RunSample& b : base_case->runs) {
            for (const RunSample& h : head_case->runs) {
                if (b.seed != h.seed) continue;
                ++one.paired_seeds;
                if (!b.trace_sha256.empty() && b.trace_sha256 == h.trace_sha256) ++one.same_traces;
            }
        }
        if (digests_differ(*base_case, *head_case, &RunSample::case_sha256)) one.changed.push_back("case");
        if (digests_differ(*base_case, *head_case, &RunSample::controller_sha256)) one.changed.push_back("controller");
        if (digests_differ(*base_case, *head_case, &RunSample::controller_config_sha256)) {
            one.changed.push_back("controller configuration");
        }
        const bool one_each = base_case->runs.size() == 1 && head_case->runs.size() == 1;
        one.method = one_each ? "exact" : "u_test";
        if (std::find(one.changed.begin(), one.changed.end(), "case") != one.changed.end()) {
            one.verdict = CompareVerdict::not_comparable;
            one.reason = "the case changed (its file, without the controller section, differs): the runs answer different questions";
        } else if (one_each && one.base_seeds != one.head_seeds) {
            one.verdict = CompareVerdict::not_comparable;
            one.reason = "one run a side at different seeds (" + seeds_text(one.base_seeds) + " and " +
                         seeds_text(one.head_seeds) + "): one run compares only with the same seed; sweep both sides";
        } else if (!one_each && (base_case->runs.size() == 1 || head_case->runs.size() == 1)) {
            one.verdict = CompareVerdict::not_comparable;
            one.reason = "one run against " + std::to_string(std::max(base_case->runs.size(), head_case->runs.size())) +
                         ": sweep both sides over the same seeds";
        } else if (!one_each && one.base_seeds != one.head_seeds && !settings.any_seeds) {
            one.verdict = CompareVerdict::not_comparable;
            one.reason = "different seeds (base " + seeds_text(one.base_seeds) + ", head " + seeds_text(one.head_seeds) +
                         "); --any-seeds compares them as independent samples";
        }
        const bool comparable = one.verdict != CompareVerdict::not_comparable;
        const bool same_behaviour = one.paired_seeds > 0 && one.same_traces == one.paired_seeds &&
                                    one.base_seeds == one.head_seeds;
        std::set<std::string> metrics;
        for (const CaseSamples* side : {base_case, head_case}) {
            for (const RunSample& run : side->runs) {
                for (const auto& [metric, value] : run.metrics) metrics.insert(metric);
                for (const auto& [metric, why] : run.not_measured) metrics.insert(metric);
            }
        }
        for (const std::string& name_of_metric : metrics) {
            MetricComparison metric;
            metric.metric = name_of_metric;
            choose_min_effect(metric, *base_case, *head_case, settings);
            metric.base = side_of(*base_case, name_of_metric);
            metric.head = side_of(*head_case, name_of_metric);
            if (metric.head.median && metric.limit && *metric.limit > 0.0) {
                metric.head_of_limit = *metric.head.median / *metric.limit;
            }
            if (!metric_appears(*base_case, name_of_metric) || !metric_appears(*head_case, name_of_metric)) {
                metric.verdict = CompareVerdict::not_comparable;
                metric.reason = metric_appears(*base_case, name_of_metric) ? "only in the base" : "only in the head";
            } else if (!comparable) {
                metric.verdict = CompareVerdict::not_comparable;
                metric.reason = "the case is not comparable";
            } else if (one.method == "exact") {
                judge_exact(metric, same_behaviour);
            } else {
                test_samples(metric);
            }
            one.metrics.push_back(std::move(metric));
        }
        comparison.cases.push_back(std::move(one));
    }
    // Holm's family: every U test whose metric has a direction, over the whole
    // comparison, so that a controller compared with itself is flagged
    // anywhere with probability at most alpha, however many cases the suite has.
    for (CaseComparison& one : comparison.cases) {
        for (MetricComparison& metric : one.metrics) {
            if (one.method == "u_test" && metric.p_value && metric.worse != WorseDirection::none &&
                metric.verdict != CompareVerdict::not_comparable) {
                family.push_back(&metric);
            }
        }
    }
    std::vector<double> p_values;
    for (const MetricComparison* metric : family) p_values.push_back(*metric->p_value);
    const std::vector<double> adjusted = holm_adjusted(p_values);
    for (std::size_t k = 0; k < family.size(); ++k) family[k]->p_adjusted = adjusted[k];
    comparison.tests = family.size();
    for (CaseComparison& one : comparison.cases) {
        for (MetricComparison& metric : one.metrics) {
            if (one.method == "u_test" && metric.verdict != CompareVerdict::not_comparable) {
                judge_samples(metric, settings.alpha);
            }
            ++comparison.metric_counts[metric.verdict];
        }
        if (one.verdict != CompareVerdict::not_comparable) {
            const auto any = [&](CompareVerdict verdict) {
                return std::any_of(one.metrics.begin(), one.metrics.end(),
                                   [&](const MetricComparison& metric) { return metric.verdict == verdict; });
            };
            one.verdict = any(CompareVerdict::regressed)  ? CompareVerdict::regressed
                          : any(CompareVerdict::improved) ? CompareVerdict::improved
                                                          : CompareVerdict::unchanged;
            one.reason = case_reason(one);
        }
        ++comparison.case_counts[one.verdict];
    }
    return comparison;
}

}  // namespace rig::harness
