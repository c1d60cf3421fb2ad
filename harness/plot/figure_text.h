#pragma once
// Text on the report page and in gnuplot scripts: numbers for people and for
// gnuplot, HTML escapes, gnuplot string literals. Used by the report page
// (harness/report) and by each system's figures (harness/systems/*/).
#include <cstddef>
#include <limits>
#include <string>
#include <string_view>

namespace rig::harness {

// A figure value that was not measured (drawn as a gap, printed as "–").
inline constexpr double kNotMeasured = std::numeric_limits<double>::quiet_NaN();

// Shortest text that reads back as the same double: for gnuplot scripts and
// data, where the value must be exact and the text locale-independent ("NaN"
// for NaN, which gnuplot reads as a missing point).
std::string exact_number(double value);
// For people: `significant_digits` like %g, "–" when not measured.
std::string shown_number(double value, int significant_digits = 4);
// `decimals` after the point; "–" when not measured.
std::string fixed_number(double value, int decimals);
// `value` with enough digits not to print like a different `limit` (3.3000001
// against 3.3 must not read "3.3 / 3.3" while it fails).
std::string shown_against(double value, double limit);

// HTML (XHTML) element text.
std::string html(std::string_view text);
// A gnuplot string literal. Single quotes because gnuplot interprets no
// backslash escapes in them (a quote is written twice); control characters
// would end the command line, so they become spaces. Enhanced-text markup is
// off for every figure (termoption noenhanced), so '_' or '^' print as is.
std::string gnuplot_string(std::string_view text);
// At most `max_code_points`, with an ellipsis when cut (long case names on a bar chart's axis).
std::string shortened(std::string_view text, std::size_t max_code_points);

}  // namespace rig::harness
