#pragma once
// What `rig compare` writes (docs/regression.md "Outputs"): compare.json (the
// contract a CI reads), compare.md (regressions first, short enough for a
// merge-request comment), compare.html (each regressed metric's two
// distributions side by side against its limit) and junit.xml (one failing
// testcase per regression, so Jenkins and GitLab list them).
#include <string>

#include <nlohmann/json.hpp>

#include "harness/regression/compare.h"

namespace rig::harness {

inline constexpr int kCompareSchemaVersion = 1;

nlohmann::json compare_json(const Comparison& comparison);
std::string compare_markdown(const Comparison& comparison);
std::string compare_html(const Comparison& comparison);
std::string compare_junit(const Comparison& comparison);
// The terminal's summary: a line per regression and improvement, then the counts.
std::string compare_table(const Comparison& comparison);

}  // namespace rig::harness
