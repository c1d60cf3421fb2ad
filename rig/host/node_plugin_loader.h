#pragma once
// Loads a controller plugin (rig/runtime/node_plugin.h) into the harness.
#include <filesystem>
#include <memory>
#include <string>

#include "rig/runtime/node_plugin.h"

namespace rig {

class NodePluginLibrary {
public:
    // dlopen + the ABI check. Throws std::runtime_error naming the file and what
    // is wrong: missing, not a shared library, not a rig plugin, built against
    // another rig or compiler.
    static std::shared_ptr<NodePluginLibrary> open(const std::filesystem::path& file);
    ~NodePluginLibrary();
    NodePluginLibrary(const NodePluginLibrary&) = delete;
    NodePluginLibrary& operator=(const NodePluginLibrary&) = delete;

    const std::filesystem::path& file() const { return file_; }
    // The node for one run; never throws (a factory's exception is the result's error).
    NodePluginResult create(const NodePluginArgs& args) const;
    bool has_config_check() const { return check_ != nullptr; }
    // The plugin's check of the case's controller section ("" = fine, or no check).
    std::string check_config(const NodePluginCaseText& text) const;

private:
    NodePluginLibrary(std::filesystem::path file, void* handle);
    std::filesystem::path file_;
    void* handle_;
    NodePluginCreateFn create_ = nullptr;
    NodePluginCheckFn check_ = nullptr;
};

}  // namespace rig
