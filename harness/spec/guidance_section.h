#pragma once
// A case's `guidance:` section, the same for both systems (docs/guidance.md).
// Both papers' sprayers are autosteered, so the plant's vehicle is steered
// along its route by autosteer over a rough ground
// (emulators/guidance/guided_path.h) unless the case says `guidance: off`:
// then the route is driven exactly (the cases that must stay exact, such as
// the faulty-controller catalogues and the golden traces, say so). Its keys
// are the fields of emulators::guidance::GuidanceParams, by the same names;
// no section, or `guidance: {}`, takes every default.
#include <optional>

#include "emulators/guidance/guidance_params.h"
#include "rig/config/yaml_fields.h"

namespace rig::harness {

// nullopt for `guidance: off`. Throws rig::ConfigError naming the file, the
// line and the key for any other scalar or a sequence, and for a value outside
// its bounds (guidance_params.h).
std::optional<emulators::guidance::GuidanceParams> read_guidance_section(const YamlSection& root);

}  // namespace rig::harness
