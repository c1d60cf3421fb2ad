// The reference controller as a plugin (software-in-the-loop): the same node as
// rig-controller's, made by the harness in its own process
// (rig/runtime/node_plugin.h, docs/controller-contract.md section 6).
#include <yaml-cpp/yaml.h>

#include "controller/controller_config.h"
#include "controller/reference_controller.h"
#include "rig/config/config_error.h"
#include "rig/config/yaml_fields.h"
#include "rig/runtime/node_plugin.h"

namespace {

rig::NodePluginResult make_reference_controller(const rig::NodePluginArgs& args) {
    rig::NodePluginResult result;
    const rig::controller::ControllerConfig config = rig::controller::load_controller_config(args.config_file);
    // Faults that end or wedge the controller's process would end or wedge the
    // harness's: those cases run as a process, where the rig can name them.
    if (config.faults.crash_at_s >= 0.0) {
        result.refusal = "the fault crash_at_s aborts the controller's process";
        return result;
    }
    if (config.faults.stall_at_s >= 0.0) {
        result.refusal = "the fault stall_at_s stops the controller answering the clock";
        return result;
    }
    result.node = std::make_unique<rig::controller::ReferenceController>(args.node_name, config, args.state_dir, args.log);
    return result;
}

// The case file's controller section, with the case file's lines in the errors.
std::string check_reference_config(const rig::NodePluginCaseText& text) {
    try {
        const YAML::Node root = YAML::Load(text.text);
        const YAML::Node section = root[text.section_key];
        if (!section || section.IsNull()) {
            rig::controller::parse_controller_config(rig::YamlSection(YAML::Node(YAML::NodeType::Map), text.file_name,
                                                                      text.section_key));
        } else {
            rig::controller::parse_controller_config(rig::YamlSection(section, text.file_name, text.section_key));
        }
    } catch (const rig::ConfigError& error) {
        return error.what();
    }
    return {};
}

}  // namespace

RIG_NODE_PLUGIN(make_reference_controller)
RIG_NODE_PLUGIN_CONFIG_CHECK(check_reference_config)
