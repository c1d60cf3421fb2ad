#pragma once
// Which way each metric gets worse, and the smallest change of it that is news
// (docs/metrics.md "Worse is"). `rig compare` and `rig history` read this one
// table: a metric's direction is declared once, beside the others, never
// guessed from its name at the place that compares it.
//
// A limit is an upper bound, so every limited metric is worse upwards; a signed
// error (a wet edge past the boundary is +, one short of it -) is worse away
// from zero; a plant property or an input the case sets (a pump's span, the
// number of NMEA sentences the case damaged) is neither better nor worse, and
// a change of it is reported, never called a regression.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rig::harness {

enum class WorseDirection {
    up,              // higher is worse (errors, times, overlap, missed)
    down,            // lower is worse (a fit's R^2, lines calibrated, flow settled)
    away_from_zero,  // a signed error: |value| higher is worse
    none,            // a property or an input: changes are reported, never judged
};

std::string_view worse_direction_name(WorseDirection direction);  // "up", "down", "away_from_zero", "none"

struct MetricDeclaration {
    // The metric's name; '*' stands for a number (nozzle, camera, duty, paper
    // row): "drive_out_excess_nozzle*_mean_m".
    std::string_view pattern;
    WorseDirection worse = WorseDirection::none;
    // The smallest shift (in the metric's own unit) a comparison calls a
    // regression or an improvement: a 0.1 % change of overlap is not news.
    double min_effect = 0.0;
    std::string_view why;
};

// Every declaration, in the table's order (docs/metrics.md prints the same).
const std::vector<MetricDeclaration>& metric_declarations();

// The declaration of `metric` (first pattern that matches), or none: a metric
// nothing declares is compared as `none` and reported as undeclared.
std::optional<MetricDeclaration> declared_metric(std::string_view metric);

// `value` moved from `base` the worse way for this direction (false for none).
bool is_worse(WorseDirection direction, double base, double value);

}  // namespace rig::harness
