#include "harness/run/run_identity.h"

#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <tuple>

#include <yaml-cpp/yaml.h>

#include "harness/trace/sha256.h"

namespace rig::harness {

std::string case_content_sha256(const CaseSpec& spec) {
    Sha256 digest;
    try {
        YAML::Node root = YAML::Load(spec.source_text);
        if (root.IsMap()) root.remove("controller");
        YAML::Emitter emitter;
        emitter << root;
        digest.add(std::string(emitter.c_str()));
    } catch (const YAML::Exception&) {
        // The loader read this text already; were yaml-cpp to refuse it now,
        // the text itself still identifies the case.
        digest.add(spec.source_text);
    }
    return digest.hex();
}

std::string file_sha256(const std::filesystem::path& file) {
    std::error_code error;
    const auto size = std::filesystem::file_size(file, error);
    if (error) return "";
    const auto modified = std::filesystem::last_write_time(file, error);
    if (error) return "";
    using Key = std::tuple<std::string, std::uintmax_t, std::filesystem::file_time_type::rep>;
    static std::mutex mutex;
    static std::map<Key, std::string> known;
    const Key key{file.string(), size, modified.time_since_epoch().count()};
    {
        std::lock_guard lock(mutex);
        if (const auto found = known.find(key); found != known.end()) return found->second;
    }
    std::ifstream in(file, std::ios::binary);
    if (!in) return "";
    Sha256 digest;
    char buffer[1 << 16];
    while (in) {
        in.read(buffer, sizeof buffer);
        digest.add(buffer, static_cast<std::size_t>(in.gcount()));
    }
    if (in.bad()) return "";
    std::string hex = digest.hex();
    std::lock_guard lock(mutex);
    known[key] = hex;
    return hex;
}

namespace {

std::filesystem::path in_path(const std::string& name) {
    const char* path = std::getenv("PATH");
    std::stringstream folders(path != nullptr ? path : "");
    std::string folder;
    while (std::getline(folders, folder, ':')) {
        if (folder.empty()) continue;
        const std::filesystem::path candidate = std::filesystem::path(folder) / name;
        std::error_code error;
        if (std::filesystem::is_regular_file(candidate, error)) return candidate;
    }
    return {};
}

}  // namespace

std::filesystem::path controller_file_of(const CaseSpec& spec, const std::filesystem::path& plugin,
                                         const std::filesystem::path& reference_executable) {
    if (spec.wiring.external_controller) return {};
    if (!plugin.empty()) return plugin;
    if (spec.controller.command.empty()) return reference_executable;
    const std::string& program = spec.controller.command.front();
    if (program.find('/') == std::string::npos) return in_path(program);
    const std::filesystem::path path(program);
    if (path.is_absolute()) return path;
    return (std::filesystem::absolute(spec.source_path).parent_path() / path).lexically_normal();
}

}  // namespace rig::harness
