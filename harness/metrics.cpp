#include "harness/metrics.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "idl/topics.h"

namespace rig::harness {

std::map<std::string, double> breakpoint_metrics(const TraceRecorder& trace, const emulators::Plant& plant,
                                                 double breakpoint_along_m) {
    std::map<std::string, double> metrics;
    int reached = 0;
    for (const auto& [t, event] : trace.samples(topics::kBreakpointEvent)) {
        const std::string kind = event.at("kind");
        // A board on Modbus or HID reports only that it stored one, not where (null position).
        if (kind == "stored" && !metrics.count("breakpoint_store_error_m") && event.at("lat_deg").is_number() &&
            std::isfinite(event.at("lat_deg").get<double>())) {
            const emulators::GeoPoint stored{event.at("lat_deg"), event.at("lon_deg"), 0.0};
            const auto [along_m, cross_m] = plant.field().to_line(stored);
            metrics["breakpoint_store_error_m"] = std::hypot(along_m - breakpoint_along_m, cross_m);
        }
        if (kind == "reached") {
            if (++reached == 1) {
                // Truth at the instant the controller decided (its sample time).
                const double nozzle_along_m = plant.truth_at(t).nozzle_line_along_m();
                metrics["breakpoint_error_signed_m"] = nozzle_along_m - breakpoint_along_m;
                metrics["breakpoint_error_m"] = std::abs(nozzle_along_m - breakpoint_along_m);
                metrics["breakpoint_reached_at_s"] = ns_to_seconds(t);
            }
        }
    }
    metrics["breakpoint_reached_count"] = reached;
    return metrics;
}

std::map<std::string, double> flow_metrics(const std::vector<MainFlowSample>& samples, const FlowEpisode& episode,
                                           double target_l_min, double band_pct, double never_settled_after_s) {
    std::map<std::string, double> metrics;
    const double band_l_min = band_pct / 100.0 * target_l_min;
    // The last instant the flow was outside the band; settled from the next sample on.
    bool settled = false;
    TimeNs settled_ns = episode.end_ns;
    bool any = false;
    for (const MainFlowSample& sample : samples) {
        if (sample.t_ns < episode.open_command_ns || sample.t_ns > episode.end_ns) continue;
        any = true;
        if (std::abs(sample.main_flow_l_min - target_l_min) > band_l_min) {
            settled = false;
        } else if (!settled) {
            settled = true;
            settled_ns = sample.t_ns;
        }
    }
    if (!any) return metrics;
    if (!settled) settled_ns = episode.end_ns;
    const TimeNs error_from_ns = settled ? settled_ns : episode.open_command_ns + seconds_to_ns(never_settled_after_s);
    metrics["flow_settled"] = settled ? 1.0 : 0.0;
    metrics["flow_adjust_time_s"] = ns_to_seconds(settled_ns - episode.open_command_ns);
    double error_sum = 0.0;
    double flow_sum = 0.0;
    int count = 0;
    for (const MainFlowSample& sample : samples) {
        if (sample.t_ns < error_from_ns || sample.t_ns > episode.end_ns) continue;
        error_sum += std::abs(sample.main_flow_l_min - target_l_min) / target_l_min;
        flow_sum += sample.main_flow_l_min;
        ++count;
    }
    if (count > 0) {
        metrics["flow_error_pct"] = 100.0 * error_sum / count;
        metrics["flow_mean_l_min"] = flow_sum / count;
    }
    return metrics;
}

double coefficient_of_variation_pct(const std::vector<double>& rows) {
    if (rows.empty()) return std::numeric_limits<double>::quiet_NaN();
    const double mean = std::accumulate(rows.begin(), rows.end(), 0.0) / static_cast<double>(rows.size());  // Eq. 10
    double squares = 0.0;
    for (double x : rows) squares += (x - mean) * (x - mean);
    // Eq. 11 as printed sums from i = 2; read as the usual population deviation over all n rows.
    const double deviation = std::sqrt(squares / static_cast<double>(rows.size()));
    return mean > 0.0 ? 100.0 * deviation / mean : std::numeric_limits<double>::quiet_NaN();  // Eq. 12
}

namespace {

// Rows of `cv_row_m` (sums of grid rows) whose centres lie in [from_m, to_m).
std::vector<double> cv_rows(const DoseProfile& profile, const std::vector<double>& total, double from_m, double to_m,
                            double cv_row_m) {
    std::vector<double> rows;
    if (!(to_m > from_m)) return rows;
    const auto per_row = std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(cv_row_m / profile.row_m)));
    double sum = 0.0;
    std::size_t in_row = 0;
    for (std::size_t row = 0; row < total.size(); ++row) {
        const double centre = profile.row_centre_m(row);
        if (centre < from_m || centre >= to_m) continue;
        sum += total[row];
        if (++in_row == per_row) {
            rows.push_back(sum);
            sum = 0.0;
            in_row = 0;
        }
    }
    return rows;
}

}  // namespace

DepositionResult deposition_metrics(const DoseProfile& profile, const DepositionJudging& judging,
                                    double breakpoint_along_m) {
    DepositionResult result;
    const std::size_t rows = std::max(profile.first_pass.size(), profile.continuation.size());
    const double threshold = judging.sprayed_fraction * judging.nominal_dose_ul_cm2;
    auto dose = [](const std::vector<double>& layer, std::size_t row) { return row < layer.size() ? layer[row] : 0.0; };
    // The one definition of "sprayed": at or above the threshold.
    auto sprayed = [&](const std::vector<double>& layer, std::size_t row) { return dose(layer, row) >= threshold; };
    std::vector<double> total(rows);
    std::optional<std::size_t> first_sprayed, last_sprayed, first_both, last_both;
    double overlap_m = 0.0;
    for (std::size_t row = 0; row < rows; ++row) {
        const bool first = sprayed(profile.first_pass, row);
        const bool second = sprayed(profile.continuation, row);
        total[row] = dose(profile.first_pass, row) + dose(profile.continuation, row);
        if (first || second) {
            if (!first_sprayed) first_sprayed = row;
            last_sprayed = row;
        }
        if (first && second) {
            overlap_m += profile.row_m;
            if (!first_both) first_both = row;
            last_both = row;
        }
    }
    double missed_m = 0.0;
    std::optional<std::size_t> gap_start;
    if (first_sprayed) {
        for (std::size_t row = *first_sprayed; row <= *last_sprayed; ++row) {
            if (!sprayed(profile.first_pass, row) && !sprayed(profile.continuation, row)) {
                missed_m += profile.row_m;
                if (!gap_start) gap_start = row;
            } else if (gap_start) {
                result.areas.push_back({"missed", profile.row_centre_m(*gap_start) - 0.5 * profile.row_m,
                                        profile.row_centre_m(row) - 0.5 * profile.row_m});
                gap_start.reset();
            }
        }
    }
    result.metrics["overlap_m"] = overlap_m;
    result.metrics["missed_m"] = missed_m;

    // Areas for the CV: the repeated one where both passes sprayed; if there is
    // none, the boundary between the passes stands in for it.
    double repeated_from_m = breakpoint_along_m;
    double repeated_to_m = breakpoint_along_m;
    if (first_both) {
        repeated_from_m = profile.row_centre_m(*first_both) - 0.5 * profile.row_m;
        repeated_to_m = profile.row_centre_m(*last_both) + 0.5 * profile.row_m;
        result.areas.push_back({"repeated", repeated_from_m, repeated_to_m});
        result.metrics["repeated_from_m"] = repeated_from_m - breakpoint_along_m;
        result.metrics["repeated_to_m"] = repeated_to_m - breakpoint_along_m;
    }
    // The operational and continuation areas reach cv_window_m either side, but
    // never past the first or last sprayed row: a case that ends its pass inside
    // the window would otherwise count bare ground as uneven deposition.
    double operational_from_m = repeated_from_m - judging.cv_window_m;
    double continuation_to_m = repeated_to_m + judging.cv_window_m;
    if (first_sprayed) {
        operational_from_m = std::max(operational_from_m, profile.row_centre_m(*first_sprayed) - 0.5 * profile.row_m);
        continuation_to_m = std::min(continuation_to_m, profile.row_centre_m(*last_sprayed) + 0.5 * profile.row_m);
    }
    result.areas.insert(result.areas.begin(), {"operational", operational_from_m, repeated_from_m});
    result.areas.push_back({"continuation", repeated_to_m, continuation_to_m});
    const auto cv = [&](double from_m, double to_m) {
        return coefficient_of_variation_pct(cv_rows(profile, total, from_m, to_m, judging.cv_row_m));
    };
    if (const double value = cv(operational_from_m, repeated_from_m); std::isfinite(value)) {
        result.metrics["cv_operational_pct"] = value;
    }
    if (first_both) {
        if (const double value = cv(repeated_from_m, repeated_to_m); std::isfinite(value)) {
            result.metrics["cv_repeated_pct"] = value;
        }
    }
    if (const double value = cv(repeated_to_m, continuation_to_m); std::isfinite(value)) {
        result.metrics["cv_continuation_pct"] = value;
    }
    return result;
}

}  // namespace rig::harness
