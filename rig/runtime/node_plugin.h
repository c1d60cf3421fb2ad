#pragma once
// A controller built as a shared library (software-in-the-loop): the harness
// loads it with dlopen and steps its Node inside its own process, on a DDS
// participant of the node's own, under the same lockstep rules as a follower
// process (docs/controller-contract.md section 6). Only the process boundary
// goes: the topics, the counted delivery and the order of steps are those of
// process mode, so the same case and seed give the same trace.
//
// A plugin is a MODULE library that links rig::node and defines, once:
//
//   RIG_NODE_PLUGIN(make_my_node)
//       rig::NodePluginResult make_my_node(const rig::NodePluginArgs& args);
//   RIG_NODE_PLUGIN_CONFIG_CHECK(check_my_config)   (optional)
//       std::string check_my_config(const rig::NodePluginCaseText& text);
//
// The factory gets what a follower process gets on its command line (node
// name, configuration file, state directory) and returns the node, or a
// refusal when this configuration cannot run in process (fault injection that
// wedges or kills its process, say): the harness then runs that case as a
// process. The config check validates the case file's `controller:` section
// before anything starts and returns the error text (empty = fine); without
// it a bad key is found only when the node is made.
//
// C++ types cross the boundary, so plugin and harness must be built by the same
// compiler against the same rig: the harness compares kNodePluginAbi and
// refuses a plugin built otherwise, by name.
#include <exception>
#include <iosfwd>
#include <memory>
#include <string>

#include "rig/runtime/node.h"
#include "rig/runtime/version.h"

namespace rig {

// What a follower process gets as --node-name, --config and --state-dir.
struct NodePluginArgs {
    std::string node_name;
    std::string config_file;  // the case's `controller:` section as YAML, rig keys removed
    std::string state_dir;    // persistent state (the breakpoint store)
    std::ostream* log = nullptr;  // the node's diagnostics (a process writes them to stderr)
};

struct NodePluginResult {
    std::unique_ptr<Node> node;  // null when refused or failed
    std::string refusal;         // why this configuration must run as a process
    std::string error;           // the configuration is wrong (the run fails, naming it)
};

// The whole case file, for the config check: errors then name file, line and key.
struct NodePluginCaseText {
    std::string file_name;
    std::string text;
    std::string section_key;  // "controller"
};

// The plugin's and the rig's copies of the runtime's classes must agree on
// layout: the number goes up when one changes within a rig version (2: the
// writers' match listener holds its context, rig/runtime/dds_context.h; 3: a
// Node may report its own emissions, two more virtual functions, rig/runtime/node.h;
// 4: readers and writers carry in-process delivery, rig/runtime/dds_context.h LocalBus).
#define RIG_NODE_PLUGIN_ABI_STRING "rig-node-plugin/4 rig/" RIG_VERSION_STRING " gcc/" __VERSION__
inline constexpr const char* kNodePluginAbi = RIG_NODE_PLUGIN_ABI_STRING;

// Symbol names the harness looks up.
inline constexpr const char* kNodePluginAbiSymbol = "rig_node_plugin_abi";
inline constexpr const char* kNodePluginCreateSymbol = "rig_node_plugin_create";
inline constexpr const char* kNodePluginCheckSymbol = "rig_node_plugin_check_config";

using NodePluginAbiFn = const char* (*)();
using NodePluginCreateFn = void (*)(const NodePluginArgs*, NodePluginResult*);
using NodePluginCheckFn = void (*)(const NodePluginCaseText*, std::string*);

}  // namespace rig

// Exceptions must not cross the boundary: they become the result's error.
#define RIG_NODE_PLUGIN(factory)                                                                          \
    extern "C" __attribute__((visibility("default"))) const char* rig_node_plugin_abi() {                \
        return RIG_NODE_PLUGIN_ABI_STRING;                                                                \
    }                                                                                                     \
    extern "C" __attribute__((visibility("default"))) void rig_node_plugin_create(                        \
        const rig::NodePluginArgs* args, rig::NodePluginResult* result) {                                 \
        try {                                                                                             \
            *result = factory(*args);                                                                     \
        } catch (const std::exception& error) {                                                           \
            result->node.reset();                                                                         \
            result->error = error.what();                                                                 \
        }                                                                                                 \
    }

#define RIG_NODE_PLUGIN_CONFIG_CHECK(check)                                                               \
    extern "C" __attribute__((visibility("default"))) void rig_node_plugin_check_config(                  \
        const rig::NodePluginCaseText* text, std::string* error) {                                        \
        try {                                                                                             \
            *error = check(*text);                                                                        \
        } catch (const std::exception& failure) {                                                         \
            *error = failure.what();                                                                      \
        }                                                                                                 \
    }
