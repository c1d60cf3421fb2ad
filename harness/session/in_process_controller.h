#pragma once
// Software-in-the-loop: the controller as a plugin, stepped inside the
// harness's process (rig/runtime/node_plugin.h). Process mode stays the
// default and the only mode for outside programs without a plugin, for
// real-time cases and for the bench.
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "rig/host/node_plugin_loader.h"
#include "rig/runtime/dds_context.h"

namespace rig::harness {

// dlopen'ed once per file for the whole run (plugins are never unloaded).
std::shared_ptr<NodePluginLibrary> load_controller_plugin(const std::filesystem::path& file);

// One run's in-process controller: its node, on a DDS participant of its own,
// registered with the harness's as a guest (its endpoints and samples are
// judged like a process's), its log in the case directory. Both participants
// join one LocalBus (rig/runtime/dds_context.h): the case's samples are
// handed over in the process, not sent through DDS.
class InProcessController {
public:
    // Throws std::runtime_error when the plugin fails to make the node; a
    // refusal (this configuration must run as a process) is returned by make().
    static std::unique_ptr<InProcessController> make(const std::shared_ptr<NodePluginLibrary>& library,
                                                     const std::filesystem::path& config_file,
                                                     const std::filesystem::path& state_dir,
                                                     const std::filesystem::path& log_file, DdsContext& harness_dds,
                                                     std::string& refusal);
    ~InProcessController();
    Node& node() { return *node_; }
    DdsContext& dds() { return *dds_; }
    const std::filesystem::path& plugin_file() const { return library_->file(); }

private:
    InProcessController() = default;
    std::shared_ptr<NodePluginLibrary> library_;
    std::ofstream log_;
    std::unique_ptr<DdsContext> dds_;
    std::unique_ptr<Node> node_;  // destroyed before its DDS context
};

}  // namespace rig::harness
