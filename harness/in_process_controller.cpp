#include "harness/in_process_controller.h"

#include <map>
#include <mutex>
#include <stdexcept>

#include "harness/case_runner.h"

namespace rig::harness {

std::filesystem::path controller_plugin_of(const CaseSpec& spec, const RunOptions& options) {
    if (!spec.controller.plugin.empty()) {
        if (spec.controller.plugin.is_absolute()) return spec.controller.plugin;
        // Beside the case file, as a relative `command` is.
        return (std::filesystem::absolute(spec.source_path).parent_path() / spec.controller.plugin).lexically_normal();
    }
    if (spec.controller.command.empty()) return options.controller_plugin;
    return {};
}

ControllerPlacement place_controller(const CaseSpec& spec, const RunOptions& options) {
    ControllerPlacement placement;
    const bool wanted = spec.controller.in_process.value_or(options.in_process);
    if (!wanted || spec.wiring.external_controller) return placement;
    // The case file's own `in_process: true` was checked when it was read; these
    // are cases `--in-process` asks of that cannot comply.
    if (spec.mode != RunMode::lockstep) {
        placement.refused = "a real-time case: its controller runs as a process on the wall clock";
        return placement;
    }
    // In the rig's process a controller would hold the rig's identity (one per
    // process), which may write every device and truth topic: what the
    // permissions exist to keep from it.
    if (options.dds_security_dir) {
        placement.refused = "rig run --dds-security: the controller's identity is given to a process of its own";
        return placement;
    }
    const std::filesystem::path plugin = controller_plugin_of(spec, options);
    if (plugin.empty()) {
        placement.refused = "controller.command names a program and no controller.plugin";
        return placement;
    }
    placement.plugin = plugin;
    return placement;
}

std::shared_ptr<NodePluginLibrary> load_controller_plugin(const std::filesystem::path& file) {
    static std::mutex mutex;
    static std::map<std::filesystem::path, std::shared_ptr<NodePluginLibrary>> loaded;
    std::lock_guard lock(mutex);
    const std::filesystem::path key = std::filesystem::absolute(file).lexically_normal();
    if (auto it = loaded.find(key); it != loaded.end()) return it->second;
    auto library = NodePluginLibrary::open(key);
    loaded.emplace(key, library);
    return library;
}

std::unique_ptr<InProcessController> InProcessController::make(const std::shared_ptr<NodePluginLibrary>& library,
                                                               const std::filesystem::path& config_file,
                                                               const std::filesystem::path& state_dir,
                                                               const std::filesystem::path& log_file,
                                                               DdsContext& harness_dds, std::string& refusal) {
    std::unique_ptr<InProcessController> controller(new InProcessController());
    controller->library_ = library;
    controller->log_.open(log_file, std::ios::out | std::ios::trunc);
    if (!controller->log_) throw std::runtime_error("cannot write the controller's log " + log_file.string());
    NodePluginArgs args;
    args.node_name = "controller";
    args.config_file = config_file.string();
    args.state_dir = state_dir.string();
    args.log = &controller->log_;
    NodePluginResult made = library->create(args);
    if (!made.refusal.empty()) {
        refusal = made.refusal;
        return nullptr;
    }
    if (!made.node) {
        throw std::runtime_error("controller plugin " + library->file().string() + ": " + made.error);
    }
    // Its own participant, on the run's domain and the loopback profile, as a
    // follower process would have; a guest of the harness's.
    controller->dds_ = std::make_unique<DdsContext>(harness_dds.domain_id(), "controller");
    harness_dds.add_guest_participant(controller->dds_->guid_prefix());
    controller->node_ = std::move(made.node);
    return controller;
}

InProcessController::~InProcessController() {
    node_.reset();
    dds_.reset();
}

}  // namespace rig::harness
