#pragma once
// Files the rig replaces whole (results.json, junit.xml, the reports,
// attach.json, bench.json): written to a temporary beside the target and
// renamed into place, so a reader never sees a half-written file.
#include <filesystem>
#include <string>

namespace rig::harness {

// Throws std::runtime_error / std::filesystem::filesystem_error naming the file.
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

}  // namespace rig::harness
