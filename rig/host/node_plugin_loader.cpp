#include "rig/host/node_plugin_loader.h"

#include <dlfcn.h>

#include <stdexcept>
#include <system_error>

namespace rig {

std::shared_ptr<NodePluginLibrary> NodePluginLibrary::open(const std::filesystem::path& file) {
    std::error_code error;
    if (!std::filesystem::is_regular_file(file, error)) {
        throw std::runtime_error("controller plugin " + file.string() + ": no such file");
    }
    // RTLD_LOCAL: the plugin's copy of the rig runtime stays its own.
    // RTLD_NODELETE: Fast DDS keeps callbacks and thread-local state that point
    // into the plugin's code after its participant is gone; unmapping that code
    // on dlclose made the harness crash at exit now and then.
    void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (handle == nullptr) {
        const char* why = dlerror();
        throw std::runtime_error("controller plugin " + file.string() + ": cannot load: " + (why ? why : "unknown"));
    }
    std::shared_ptr<NodePluginLibrary> library(new NodePluginLibrary(file, handle));
    auto abi = reinterpret_cast<NodePluginAbiFn>(dlsym(handle, kNodePluginAbiSymbol));
    library->create_ = reinterpret_cast<NodePluginCreateFn>(dlsym(handle, kNodePluginCreateSymbol));
    library->check_ = reinterpret_cast<NodePluginCheckFn>(dlsym(handle, kNodePluginCheckSymbol));
    if (abi == nullptr || library->create_ == nullptr) {
        throw std::runtime_error("controller plugin " + file.string() +
                                 ": not a rig node plugin (no RIG_NODE_PLUGIN entry points; rig/runtime/node_plugin.h)");
    }
    if (const std::string theirs = abi(); theirs != kNodePluginAbi) {
        throw std::runtime_error("controller plugin " + file.string() + ": built for \"" + theirs +
                                 "\", this rig is \"" + kNodePluginAbi + "\"; rebuild it against this rig");
    }
    return library;
}

NodePluginLibrary::NodePluginLibrary(std::filesystem::path file, void* handle)
    : file_(std::move(file)), handle_(handle) {}

NodePluginLibrary::~NodePluginLibrary() {
    if (handle_ != nullptr) dlclose(handle_);
}

NodePluginResult NodePluginLibrary::create(const NodePluginArgs& args) const {
    NodePluginResult result;
    create_(&args, &result);
    if (!result.node && result.refusal.empty() && result.error.empty()) {
        result.error = "the plugin's factory returned no node and gave no reason";
    }
    return result;
}

std::string NodePluginLibrary::check_config(const NodePluginCaseText& text) const {
    if (check_ == nullptr) return {};
    std::string error;
    check_(&text, &error);
    return error;
}

}  // namespace rig
