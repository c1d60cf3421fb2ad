#pragma once
// What this build of the rig is: the project's version (CMakeLists.txt
// project()) and the git commit its sources were at when it was built,
// "unknown" for a tree without git (a release tarball), with "-dirty" when the
// work tree had uncommitted changes (cmake/RigBuildInfo.cmake writes them).
// `rig --version` prints them; results.json records them.
#include <string_view>

namespace rig::harness {

std::string_view rig_version();
std::string_view rig_commit();

}  // namespace rig::harness
