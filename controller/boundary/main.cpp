// rig-boundary-controller: seed 001's reference controller (positioning and
// boundary half) as its own executable, started and driven by the harness like
// rig-controller (docs/controller-contract.md): the same arguments, the same
// clock protocol, its own topics (device/gnss/nmea, device/laser_height/serial
// in; actuator/nozzle_pwm/duty out).
//   --domain N  --node-name NAME  --config FILE  --state-dir DIR  --clock lockstep
#include <CLI/CLI.hpp>

#include <iostream>

#include "controller/boundary/boundary_controller_node.h"
#include "controller/boundary/boundary_node_config.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/lockstep.h"

int main(int argc, char** argv) {
    CLI::App app{"Reference boundary shut-off controller (seed 001) as a rig node"};
    std::uint32_t domain_id = 0;
    std::string node_name = "controller";
    std::string config_file;
    std::string state_dir = ".";
    std::string clock_mode = "lockstep";
    app.add_option("--domain", domain_id, "DDS domain id of the run")->required();
    app.add_option("--node-name", node_name, "node name used in clock acknowledgements");
    app.add_option("--config", config_file, "YAML file with the controller section")->required();
    app.add_option("--state-dir", state_dir, "directory for persistent state (unused: it keeps none)");
    app.add_option("--clock", clock_mode, "lockstep (virtual time)")->check(CLI::IsMember({"lockstep"}));
    CLI11_PARSE(app, argc, argv);
    try {
        // The context first: the node's readers and writers unregister from it
        // when the node is destroyed, so it must outlive the node.
        rig::DdsContext dds(domain_id, node_name);
        rig::controller::boundary::BoundaryControllerNode controller(
            node_name, rig::controller::boundary::load_boundary_node_config(config_file));
        rig::FollowerOptions options;
        options.node_name = node_name;
        rig::ManualClock clock;
        return rig::run_lockstep_follower(controller, dds, clock, options);
    } catch (const std::exception& error) {
        std::cerr << node_name << ": " << error.what() << "\n";
        return 2;
    }
}
