#pragma once
// A case's `guidance:` section, the same for both systems (docs/guidance.md):
// with it the plant's vehicle is steered along its route by autosteer over a
// rough ground (emulators/guidance/guided_path.h); without it the route is
// driven exactly, as every case did before. Its keys are the fields of
// emulators::guidance::GuidanceParams, by the same names; `guidance: {}` takes
// every default.
#include <optional>

#include "emulators/guidance/guidance_params.h"
#include "rig/config/yaml_fields.h"

namespace rig::harness {

// nullopt without a `guidance:` key. Throws rig::ConfigError naming the file,
// the line and the key for a value outside its bounds (guidance_params.h).
std::optional<emulators::guidance::GuidanceParams> read_guidance_section(const YamlSection& root);

}  // namespace rig::harness
