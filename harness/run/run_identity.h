#pragma once
// What a run was run with, as digests `rig compare` can set side by side
// (docs/regression.md): the case as the rig reads it, and the controller as a
// binary and as its configuration. Two runs whose traces part are then told
// apart as "the controller changed", "the case changed" or "the rig changed".
#include <filesystem>
#include <string>

#include "harness/spec/case_spec.h"

namespace rig::harness {

// SHA-256 of the case file without its `controller:` section, as yaml-cpp
// re-emits it: the world, the route, the limits and the expectations. The
// controller's section (its gains, its command) is the controller's side of a
// comparison, so a team's gain change leaves the case the same; comments and
// layout do not count.
std::string case_content_sha256(const CaseSpec& spec);

// SHA-256 of a file's bytes; empty when it cannot be read (a run is never
// stopped for its digest). Cached per path, size and modification time: a
// sweep hashes its controller once, not once per run.
std::string file_sha256(const std::filesystem::path& file);

// The controller's program or plugin as a file: `plugin` when it ran in
// process, else `command`'s first word (beside the case file when it has a
// '/', looked up in PATH when bare), else the reference executable. Empty for
// an external board.
std::filesystem::path controller_file_of(const CaseSpec& spec, const std::filesystem::path& plugin,
                                         const std::filesystem::path& reference_executable);

}  // namespace rig::harness
