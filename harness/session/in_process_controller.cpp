#include "harness/session/in_process_controller.h"

#include <map>
#include <mutex>
#include <stdexcept>


namespace rig::harness {

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
    // With the controller here, every node of the case lives in this process:
    // its samples go from writer to readers by hand-off (rig/runtime/dds_context.h
    // LocalBus), DDS only to readers outside it (an observer on the domain).
    if (!harness_dds.local_bus()) harness_dds.join_local_bus(std::make_shared<LocalBus>());
    controller->dds_->join_local_bus(harness_dds.local_bus());
    controller->node_ = std::move(made.node);
    return controller;
}

InProcessController::~InProcessController() {
    node_.reset();
    dds_.reset();
}

}  // namespace rig::harness
