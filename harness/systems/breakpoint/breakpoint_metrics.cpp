#include "harness/systems/breakpoint/breakpoint_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>

#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

std::string seconds_text(TimeNs t) { return fixed_text(ns_to_seconds(t), 3) + " s"; }

}  // namespace

// ---------------------------------------------------------------- vehicle track

VehicleTrack::VehicleTrack(std::vector<VehicleSample> samples) : samples_(std::move(samples)) {
    std::stable_sort(samples_.begin(), samples_.end(),
                     [](const VehicleSample& a, const VehicleSample& b) { return a.t_ns < b.t_ns; });
}

std::optional<double> VehicleTrack::nozzle_line_along_m(TimeNs t) const { return at(t, &VehicleSample::nozzle_line_along_m); }

std::optional<double> VehicleTrack::antenna_cross_m(TimeNs t) const { return at(t, &VehicleSample::antenna_cross_m); }

std::optional<double> VehicleTrack::at(TimeNs t, double VehicleSample::*field) const {
    if (samples_.empty()) return std::nullopt;
    const auto after = std::lower_bound(samples_.begin(), samples_.end(), t,
                                        [](const VehicleSample& sample, TimeNs at) { return sample.t_ns < at; });
    if (after != samples_.end() && after->t_ns == t) return (*after).*field;
    // Before the first sample or after the last, truth does not say where the
    // nozzle line was: no position, never the nearest one held.
    if (after == samples_.begin() || after == samples_.end()) return std::nullopt;
    const VehicleSample& before = *std::prev(after);
    // Across a headland turn the two neighbours are on different passes: the
    // vehicle was on `before`'s pass until the reposition, which the truth
    // stream dates to its first sample of the new pass at the latest.
    if (before.pass_index != after->pass_index) return before.*field;
    const double fraction =
        static_cast<double>(t - before.t_ns) / static_cast<double>(after->t_ns - before.t_ns);
    return before.*field + fraction * ((*after).*field - before.*field);
}

std::string VehicleTrack::describe_span() const {
    if (samples_.empty()) return "no vehicle truth was recorded";
    return "the vehicle truth recorded spans " + seconds_text(samples_.front().t_ns) + " to " +
           seconds_text(samples_.back().t_ns);
}

std::optional<TimeNs> VehicleTrack::pass_start_ns(int pass_index) const {
    for (const VehicleSample& sample : samples_) {
        if (sample.pass_index == pass_index) return sample.t_ns;
    }
    return std::nullopt;
}

// ---------------------------------------------------------------- breakpoint identification

MetricSet breakpoint_metrics(const std::vector<BreakpointEventSample>& events, const VehicleTrack& track,
                             const emulators::FieldFrame& field, double breakpoint_along_m) {
    MetricSet metrics;
    int reached = 0;
    for (const BreakpointEventSample& event : events) {
        // A board on Modbus or HID reports only that it stored one, not where (no position).
        if (event.kind == "stored" && !metrics.values.count("breakpoint_store_error_m") && event.lat_deg &&
            event.lon_deg && std::isfinite(*event.lat_deg) && std::isfinite(*event.lon_deg)) {
            const auto [along_m, cross_m] = field.to_line(emulators::GeoPoint{*event.lat_deg, *event.lon_deg, 0.0});
            // Across the line, the true place is where the vehicle stood when it
            // stored (its antenna's offset: 0 on the exact route). On autosteer the
            // body stops some cm off the line; the controller storing where it
            // really was is right, and that offset is the autosteer's, not its error.
            // A controller's event always has truth at its instant (the recorder
            // writes a truth sample at every instant the controller publishes);
            // without one (a hand-made trace) the line is the reference, as before.
            const double true_cross_m = track.antenna_cross_m(event.t_ns).value_or(0.0);
            metrics.values["breakpoint_store_error_m"] = std::hypot(along_m - breakpoint_along_m, cross_m - true_cross_m);
        }
        if (event.kind == "reached" && ++reached == 1) {
            // Truth at the instant the controller decided (the trace holds the plant's state then).
            if (const auto nozzle_along_m = track.nozzle_line_along_m(event.t_ns)) {
                metrics.values["breakpoint_error_signed_m"] = *nozzle_along_m - breakpoint_along_m;
                metrics.values["breakpoint_error_m"] = std::abs(*nozzle_along_m - breakpoint_along_m);
                metrics.values["breakpoint_reached_at_s"] = ns_to_seconds(event.t_ns);
            } else {
                const std::string why = "declared at " + seconds_text(event.t_ns) +
                                        ", where truth has no position of the nozzle line: " + track.describe_span();
                metrics.not_measured["breakpoint_error_m"] = why;
                metrics.not_measured["breakpoint_error_signed_m"] = why;
            }
        }
    }
    metrics.values["breakpoint_reached_count"] = reached;
    if (reached == 0) {
        metrics.not_measured["breakpoint_error_m"] = "never declared: the controller did not report the breakpoint reached";
    }
    if (!metrics.values.count("breakpoint_store_error_m")) {
        const bool stored = std::any_of(events.begin(), events.end(), [](const auto& e) { return e.kind == "stored"; });
        metrics.not_measured["breakpoint_store_error_m"] =
            stored ? "the controller reported a stored breakpoint without its position (e.g. over Modbus)"
                   : "never stored: the controller reported no stored breakpoint";
    }
    return metrics;
}

// ---------------------------------------------------------------- flow control

std::vector<FlowReading> kf11_readings(const std::vector<FlowMeterCountSample>& samples, double pulses_per_l,
                                       double window_s) {
    std::vector<FlowReading> readings;
    // Edges seen so far, as (count, capture time) of the samples where the count changed.
    struct Edge {
        std::uint32_t count;
        std::uint32_t capture_us;
    };
    std::vector<Edge> edges;
    TimeNs last_edge_seen_ns = 0;
    const auto window_us = static_cast<std::uint32_t>(std::llround(window_s * 1e6));
    for (const FlowMeterCountSample& sample : samples) {
        if (edges.empty() || sample.count_pulses != edges.back().count) {
            edges.push_back(Edge{sample.count_pulses, sample.last_edge_capture_us});
            last_edge_seen_ns = sample.t_ns;
        }
        // No pulse for twice the window: the flow has stopped (the count alone cannot say so).
        if (sample.t_ns - last_edge_seen_ns > seconds_to_ns(2.0 * window_s)) {
            readings.push_back(FlowReading{sample.t_ns, 0.0});
            continue;
        }
        const Edge& last = edges.back();
        // The latest earlier edge at least window_s before the last one.
        const Edge* base = nullptr;
        for (auto it = edges.rbegin() + 1; it != edges.rend(); ++it) {
            if (static_cast<std::uint32_t>(last.capture_us - it->capture_us) >= window_us) {
                base = &*it;
                break;
            }
        }
        if (base == nullptr) {
            readings.push_back(FlowReading{sample.t_ns, 0.0});
            continue;
        }
        const double pulses = static_cast<std::uint32_t>(last.count - base->count);
        const double t2_s = static_cast<std::uint32_t>(last.capture_us - base->capture_us) * 1e-6;
        readings.push_back(FlowReading{sample.t_ns, 60.0 * pulses / (pulses_per_l * t2_s)});  // Eq. 3
        // Keep the edge list short: nothing older than the base is needed again.
        const auto keep_from = static_cast<std::size_t>(base - edges.data());
        if (keep_from > 64) edges.erase(edges.begin(), edges.begin() + static_cast<std::ptrdiff_t>(keep_from));
    }
    return readings;
}

FlowResult flow_metrics(const std::vector<HydraulicsSample>& hydraulics, const std::vector<SectionCommand>& commands,
                        const std::vector<FlowReading>& kf11, const FlowWindow& window, const FlowJudging& judging) {
    FlowResult result;
    MetricSet& metrics = result.metrics;
    const char* adjust_names[] = {"flow_adjust_time_s", "flow_adjust_time_from_command_s"};

    // Openings: the section command going from all closed to any open.
    std::vector<TimeNs> openings;
    std::uint16_t previous = 0;
    for (const SectionCommand& command : commands) {
        if (command.t_ns >= window.to_ns) break;
        if (previous == 0 && command.open_mask != 0 && command.t_ns >= window.from_ns) openings.push_back(command.t_ns);
        previous = command.open_mask;
    }
    if (openings.empty()) {
        const std::string reason = "never settled: the sections never opened between " + seconds_text(window.from_ns) +
                                   " and " + seconds_text(window.to_ns);
        for (const char* name : adjust_names) metrics.not_measured[name] = reason;
        metrics.not_measured["flow_error_pct"] = reason;
        metrics.values["flow_settled"] = 0.0;
        return result;
    }
    const TimeNs first_open_ns = openings.front();
    result.first_open_ns = first_open_ns;

    // The settle instant: the first in-band sample after the last out-of-band one,
    // provided the flow is still in the band at the window's end.
    const double band_l_min = judging.band_pct / 100.0 * judging.target_l_min;
    auto in_band = [&](const HydraulicsSample& sample) {
        return std::abs(sample.main_flow_l_min - judging.target_l_min) <= band_l_min;
    };
    // The start of the current in-band stretch (kNever while out of the band).
    TimeNs settled_ns = kNever;
    std::optional<TimeNs> first_spraying_ns;  // the nozzles starting after the first opening
    // The nozzles starting (truth): the section valves going from all shut to any
    // open. A command that drops and restores the sections too briefly for the
    // valves to act is no restart; one that empties the boom line is.
    std::vector<TimeNs> nozzle_starts;
    std::uint16_t spraying_before = 0;
    bool any = false;
    for (const HydraulicsSample& sample : hydraulics) {
        if (sample.t_ns < first_open_ns) {
            spraying_before = sample.sections_spraying_mask;
            continue;
        }
        if (sample.t_ns >= window.to_ns) break;
        any = true;
        if (spraying_before == 0 && sample.sections_spraying_mask != 0) nozzle_starts.push_back(sample.t_ns);
        spraying_before = sample.sections_spraying_mask;
        if (!in_band(sample)) {
            settled_ns = kNever;
        } else if (settled_ns == kNever) {
            settled_ns = sample.t_ns;
        }
    }
    if (!nozzle_starts.empty()) first_spraying_ns = nozzle_starts.front();
    if (nozzle_starts.size() > 1) metrics.values["flow_nozzle_starts_count"] = static_cast<double>(nozzle_starts.size());
    // Where the error counts from: the settling, or the moment the flow was due to
    // be steady (settle_by_s after the nozzles first started in the window) if
    // that came first. Restarts in the window are the controller's own doing
    // (it drives on through it): they do not move that moment.
    std::optional<TimeNs> error_from_ns;
    if (!any || settled_ns == kNever) {
        std::string reason = "never settled: the main flow was outside " + fixed_text(judging.target_l_min, 1) +
                             " L/min +-" + fixed_text(judging.band_pct, 1) + " % at the end of the judged window (" +
                             seconds_text(window.to_ns) + ")";
        if (!any) reason = "never settled: no flow sample between the opening and the window's end";
        if (nozzle_starts.size() > 1) reason += ", after the nozzles started " + std::to_string(nozzle_starts.size()) + " times";
        for (const char* name : adjust_names) metrics.not_measured[name] = reason;
        metrics.values["flow_settled"] = 0.0;
        if (!nozzle_starts.empty()) {
            error_from_ns = nozzle_starts.front() + seconds_to_ns(judging.settle_by_s);
        } else {
            metrics.not_measured["flow_error_pct"] = "the nozzles never started in the judged window";
        }
    } else {
        // Each restart of the nozzles starts the adjustment again: it is timed from
        // the last start before the flow settled for good (sec. 3.1.2: "from nozzle
        // start"), and from the open command that started it.
        const TimeNs settle_ns = settled_ns;
        TimeNs nozzles_ns = first_open_ns;
        for (TimeNs start_ns : nozzle_starts) {
            if (start_ns <= settle_ns) nozzles_ns = start_ns;
        }
        const TimeNs open_ns = *std::prev(std::upper_bound(openings.begin(), openings.end(), nozzles_ns));
        metrics.values["flow_settled"] = 1.0;
        metrics.values["flow_adjust_time_from_command_s"] = ns_to_seconds(settle_ns - open_ns);
        metrics.values["flow_adjust_time_s"] = ns_to_seconds(settle_ns - nozzles_ns);
        error_from_ns = std::min(settle_ns, first_spraying_ns.value_or(nozzles_ns) + seconds_to_ns(judging.settle_by_s));
    }
    if (error_from_ns) {
        double error_sum = 0.0;
        double flow_sum = 0.0;
        int count = 0;
        for (const HydraulicsSample& sample : hydraulics) {
            if (sample.t_ns < *error_from_ns || sample.t_ns >= window.to_ns) continue;
            error_sum += std::abs(sample.main_flow_l_min - judging.target_l_min) / judging.target_l_min;
            flow_sum += sample.main_flow_l_min;
            ++count;
        }
        if (count > 0) {
            metrics.values["flow_error_pct"] = 100.0 * error_sum / count;
            metrics.values["flow_mean_l_min"] = flow_sum / count;
        } else {
            metrics.not_measured["flow_error_pct"] = "the judged window ended before the flow was due to be steady";
        }
    }

    // Fig. 12: how often the flow left the band once it had been in it, and how
    // far it still swings at the window's end.
    {
        int exits = 0;
        bool entered = false;
        bool inside = false;
        const TimeNs tail_from_ns = window.to_ns - seconds_to_ns(judging.oscillation_window_s);
        double tail_min = 0.0;
        double tail_max = 0.0;
        bool tail_any = false;
        bool tail_spraying = first_spraying_ns && *first_spraying_ns <= tail_from_ns;
        for (const HydraulicsSample& sample : hydraulics) {
            if (sample.t_ns < first_open_ns) continue;
            if (sample.t_ns >= window.to_ns) break;
            const bool now_inside = in_band(sample);
            if (now_inside) entered = true;
            if (entered && inside && !now_inside) ++exits;
            inside = now_inside;
            if (sample.t_ns >= tail_from_ns) {
                if (sample.sections_spraying_mask == 0) tail_spraying = false;
                tail_min = tail_any ? std::min(tail_min, sample.main_flow_l_min) : sample.main_flow_l_min;
                tail_max = tail_any ? std::max(tail_max, sample.main_flow_l_min) : sample.main_flow_l_min;
                tail_any = true;
            }
        }
        metrics.values["flow_band_exits_count"] = static_cast<double>(exits);
        if (tail_any && tail_spraying) {
            metrics.values["flow_oscillation_pct"] = 100.0 * (tail_max - tail_min) / judging.target_l_min;
        } else {
            metrics.not_measured["flow_oscillation_pct"] =
                "the nozzles did not spray through the last " + fixed_text(judging.oscillation_window_s, 1) +
                " s of the judged window";
        }
    }

    // The paper's way (Table 5): the controller's own meter readings, signed.
    auto kf11_signed_error = [&](TimeNs from_ns) -> std::optional<double> {
        double sum = 0.0;
        int count = 0;
        for (const FlowReading& reading : kf11) {
            if (reading.t_ns < from_ns || reading.t_ns >= window.to_ns) continue;
            sum += reading.flow_l_min;
            ++count;
        }
        if (count == 0) return std::nullopt;
        return 100.0 * (sum / count - judging.target_l_min) / judging.target_l_min;
    };
    if (first_spraying_ns) {
        if (const auto error = kf11_signed_error(*first_spraying_ns)) {
            metrics.values["flow_error_kf11_signed_pct"] = *error;
        }
    }
    if (settled_ns != kNever) {
        if (const auto error = kf11_signed_error(settled_ns)) {
            metrics.values["flow_error_kf11_settled_signed_pct"] = *error;
        }
    }
    return result;
}

Fig11Result fig11_metrics(const std::vector<HydraulicsSample>& hydraulics, const FlowWindow& window,
                          const Fig11Judging& judging) {
    struct Point {
        double pump_l_min;
        double main_l_min;
    };
    std::map<long, std::vector<Point>> points_by_opening;  // key: opening in 0.1 %
    // One hold: samples [begin, end) of the window with the sections open and the valve still.
    std::vector<const HydraulicsSample*> hold;
    auto close_hold = [&] {
        if (hold.size() < 2) {
            hold.clear();
            return;
        }
        const TimeNs end_ns = hold.back()->t_ns;
        if (end_ns - hold.front()->t_ns >= seconds_to_ns(judging.hold_min_s)) {
            const TimeNs from_ns = end_ns - seconds_to_ns(judging.measure_s);
            const TimeNs middle_ns = from_ns + (end_ns - from_ns) / 2;
            double pump_sum = 0.0, main_sum = 0.0, first_sum = 0.0, second_sum = 0.0;
            int count = 0, first_count = 0, second_count = 0;
            for (const HydraulicsSample* sample : hold) {
                if (sample->t_ns < from_ns) continue;
                pump_sum += sample->pump_flow_l_min;
                main_sum += sample->main_flow_l_min;
                ++count;
                if (sample->t_ns < middle_ns) {
                    first_sum += sample->pump_flow_l_min;
                    ++first_count;
                } else {
                    second_sum += sample->pump_flow_l_min;
                    ++second_count;
                }
            }
            if (count > 0 && first_count > 0 && second_count > 0) {
                const double pump = pump_sum / count;
                const double drift = std::abs(first_sum / first_count - second_sum / second_count);
                if (pump > 0.0 && drift <= judging.steady_pump_pct / 100.0 * pump) {
                    const long key = std::lround(hold.front()->valve_opening_pct * 10.0);
                    points_by_opening[key].push_back(Point{pump, main_sum / count});
                }
            }
        }
        hold.clear();
    };
    for (const HydraulicsSample& sample : hydraulics) {
        if (sample.t_ns < window.from_ns) continue;
        if (sample.t_ns >= window.to_ns) break;
        const bool open = sample.sections_spraying_mask != 0;
        if (!open || (!hold.empty() && std::abs(sample.valve_opening_pct - hold.front()->valve_opening_pct) >
                                           judging.opening_tolerance_pct)) {
            close_hold();
        }
        if (open) hold.push_back(&sample);
    }
    close_hold();

    Fig11Result result;
    MetricSet& metrics = result.metrics;
    double main_min = 0.0, main_max = 0.0, pump_min = 0.0, pump_max = 0.0;
    bool any_point = false;
    for (const auto& [key, points] : points_by_opening) {
        Fig11Line line;
        line.opening_pct = static_cast<double>(key) / 10.0;
        line.points = static_cast<int>(points.size());
        double sx = 0.0, sy = 0.0;
        line.pump_min_l_min = points.front().pump_l_min;
        line.pump_max_l_min = points.front().pump_l_min;
        for (const Point& point : points) {
            sx += point.pump_l_min;
            sy += point.main_l_min;
            line.pump_min_l_min = std::min(line.pump_min_l_min, point.pump_l_min);
            line.pump_max_l_min = std::max(line.pump_max_l_min, point.pump_l_min);
            main_min = any_point ? std::min(main_min, point.main_l_min) : point.main_l_min;
            main_max = any_point ? std::max(main_max, point.main_l_min) : point.main_l_min;
            pump_min = any_point ? std::min(pump_min, point.pump_l_min) : point.pump_l_min;
            pump_max = any_point ? std::max(pump_max, point.pump_l_min) : point.pump_l_min;
            any_point = true;
        }
        if (line.points < judging.min_points || line.pump_max_l_min - line.pump_min_l_min < judging.min_span_l_min) {
            continue;
        }
        const double n = static_cast<double>(points.size());
        const double mean_x = sx / n;
        const double mean_y = sy / n;
        double sxx = 0.0, sxy = 0.0, syy = 0.0;
        for (const Point& point : points) {
            sxx += (point.pump_l_min - mean_x) * (point.pump_l_min - mean_x);
            sxy += (point.pump_l_min - mean_x) * (point.main_l_min - mean_y);
            syy += (point.main_l_min - mean_y) * (point.main_l_min - mean_y);
        }
        // Every point at one pump flow: no slope to fit.
        if (!(line.pump_max_l_min > line.pump_min_l_min) || !(sxx > 0.0)) continue;
        line.slope = sxy / sxx;
        line.intercept_l_min = mean_y - line.slope * mean_x;
        double residual = 0.0;
        for (const Point& point : points) {
            const double error = point.main_l_min - (line.slope * point.pump_l_min + line.intercept_l_min);
            residual += error * error;
        }
        // A flat line through flat points explains everything there is.
        line.r2 = syy > 0.0 ? 1.0 - residual / syy : 1.0;
        result.lines.push_back(line);
    }
    metrics.values["fig11_lines_count"] = static_cast<double>(result.lines.size());
    metrics.values["fig11_lines_missing_count"] =
        static_cast<double>(std::max(0, judging.required_lines - static_cast<int>(result.lines.size())));
    if (result.lines.empty()) {
        metrics.not_measured["fig11_unexplained_pct"] =
            "no valve opening was held at " + std::to_string(judging.min_points) + " steady pump flows spanning " +
            fixed_text(judging.min_span_l_min, 1) + " L/min with the sections open";
    } else {
        double worst_r2 = 1.0;
        for (const Fig11Line& line : result.lines) worst_r2 = std::min(worst_r2, line.r2);
        metrics.values["fig11_unexplained_pct"] = 100.0 * (1.0 - worst_r2);
    }
    if (any_point) {
        metrics.values["fig11_main_flow_min_l_min"] = main_min;
        metrics.values["fig11_main_flow_max_l_min"] = main_max;
        metrics.values["fig11_pump_span_l_min"] = pump_max - pump_min;
    }
    return result;
}

MetricSet spray_timing_metrics(const std::vector<SectionCommand>& commands,
                               const std::vector<HydraulicsSample>& hydraulics,
                               const std::vector<LandingEdgeSample>& landing_edges) {
    MetricSet metrics;
    const auto first_open = std::find_if(commands.begin(), commands.end(), [](const auto& c) { return c.open_mask != 0; });
    if (first_open == commands.end()) return metrics;
    for (const HydraulicsSample& sample : hydraulics) {
        if (sample.t_ns >= first_open->t_ns && sample.sections_spraying_mask != 0) {
            metrics.values["section_valve_open_delay_s"] = ns_to_seconds(sample.t_ns - first_open->t_ns);
            break;
        }
    }
    for (const LandingEdgeSample& edge : landing_edges) {
        if (edge.landing && edge.t_ns >= first_open->t_ns) {
            metrics.values["spray_landing_delay_s"] = ns_to_seconds(edge.t_ns - first_open->t_ns);
            break;
        }
    }
    return metrics;
}

// ---------------------------------------------------------------- deposition

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
    MetricSet& metrics = result.metrics;
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
    // Missed: rows of the strip the case says must be sprayed that neither pass
    // sprayed, whatever the controller did (a row belongs to the strip when its
    // centre does). A strip row the recorded ground has no row for is unknown
    // ground, neither sprayed nor missed: then missed_m is not measured.
    double missed_m = 0.0;
    std::optional<double> gap_from_m;
    long off_ground_rows = 0;
    const std::size_t ground_rows = std::max(rows, profile.ground_rows);
    const auto strip_rows = static_cast<long>(
        std::floor((judging.strip_to_m - judging.strip_from_m) / profile.row_m + 1e-9));
    const long first_strip_row =
        static_cast<long>(std::ceil((judging.strip_from_m - profile.first_row_centre_m) / profile.row_m - 1e-9));
    for (long k = 0; k <= strip_rows; ++k) {
        const long row = first_strip_row + k;
        const double centre_m = profile.first_row_centre_m + static_cast<double>(row) * profile.row_m;
        if (centre_m > judging.strip_to_m + 1e-9) break;
        if (row < 0 || static_cast<std::size_t>(row) >= ground_rows) {
            ++off_ground_rows;
            continue;
        }
        const bool covered = sprayed(profile.first_pass, static_cast<std::size_t>(row)) ||
                             sprayed(profile.continuation, static_cast<std::size_t>(row));
        if (!covered) {
            missed_m += profile.row_m;
            if (!gap_from_m) gap_from_m = centre_m - 0.5 * profile.row_m;
        } else if (gap_from_m) {
            result.areas.push_back({"missed", *gap_from_m, centre_m - 0.5 * profile.row_m});
            gap_from_m.reset();
        }
    }
    if (gap_from_m) result.areas.push_back({"missed", *gap_from_m, judging.strip_to_m});
    metrics.values["overlap_m"] = overlap_m;
    if (off_ground_rows == 0) {
        metrics.values["missed_m"] = missed_m;
    } else {
        const std::string ground =
            ground_rows == 0 ? std::string("the trace holds no ground")
                             : "the recorded ground spans " + fixed_text(profile.row_centre_m(0) - 0.5 * profile.row_m, 2) +
                                   " to " + fixed_text(profile.row_centre_m(ground_rows - 1) + 0.5 * profile.row_m, 2) + " m";
        metrics.not_measured["missed_m"] = std::to_string(off_ground_rows) + " rows of the strip that must be sprayed (" +
                                           fixed_text(judging.strip_from_m, 2) + " to " +
                                           fixed_text(judging.strip_to_m, 2) + " m along) lie off the ground: " + ground;
    }
    metrics.values["strip_length_m"] = judging.strip_to_m - judging.strip_from_m;

    // Areas for the CV: the repeated one where both passes sprayed; if there is
    // none, the boundary between the passes stands in for it.
    double repeated_from_m = breakpoint_along_m;
    double repeated_to_m = breakpoint_along_m;
    if (first_both) {
        repeated_from_m = profile.row_centre_m(*first_both) - 0.5 * profile.row_m;
        repeated_to_m = profile.row_centre_m(*last_both) + 0.5 * profile.row_m;
        result.areas.push_back({"repeated", repeated_from_m, repeated_to_m});
        metrics.values["repeated_from_m"] = repeated_from_m - breakpoint_along_m;
        metrics.values["repeated_to_m"] = repeated_to_m - breakpoint_along_m;
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
        metrics.values["cv_operational_pct"] = value;
    }
    if (first_both) {
        if (const double value = cv(repeated_from_m, repeated_to_m); std::isfinite(value)) {
            metrics.values["cv_repeated_pct"] = value;
        }
    }
    if (const double value = cv(repeated_to_m, continuation_to_m); std::isfinite(value)) {
        metrics.values["cv_continuation_pct"] = value;
    }
    return result;
}

}  // namespace rig::harness
