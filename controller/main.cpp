// rig-controller: the reference controller as its own executable. The harness
// starts it with the command a case names (this one by default) and drives it in
// lockstep over DDS. A team's own controller, built against rig::runtime, takes
// the same arguments and drops in unchanged:
//   --domain N        DDS domain of the run
//   --node-name NAME  name it answers ticks with
//   --config FILE     the case's `controller:` section as YAML
//   --state-dir DIR   where it keeps persistent state (the breakpoint store)
#include <CLI/CLI.hpp>

#include <iostream>

#include "controller/controller_config.h"
#include "controller/reference_controller.h"
#include "rig/dds_context.h"
#include "rig/lockstep.h"

int main(int argc, char** argv) {
    CLI::App app{"Reference breakpoint-spraying controller (seed 000) as a rig node"};
    std::uint32_t domain_id = 0;
    std::string node_name = "controller";
    std::string config_file;
    std::string state_dir = ".";
    app.add_option("--domain", domain_id, "DDS domain id of the run")->required();
    app.add_option("--node-name", node_name, "node name used in lockstep acknowledgements");
    app.add_option("--config", config_file, "YAML file with the controller section")->required();
    app.add_option("--state-dir", state_dir, "directory for persistent state (breakpoint store)");
    CLI11_PARSE(app, argc, argv);

    try {
        const auto config = rig::controller::load_controller_config(config_file);
        rig::DdsContext dds(domain_id, node_name);
        rig::ManualClock clock;
        rig::controller::ReferenceController controller(node_name, config, state_dir);
        rig::FollowerOptions options;
        options.node_name = node_name;
        return rig::run_lockstep_follower(controller, dds, clock, options);
    } catch (const std::exception& error) {
        std::cerr << node_name << ": " << error.what() << "\n";
        return 2;
    }
}
