// rig-boundary-controller: seed 001's reference controller (positioning and
// boundary half) as its own executable, started and driven by the harness like
// rig-controller (docs/controller-contract.md): the same arguments, the same
// clock protocol, its own topics (device/gnss/nmea, device/laser_height/serial
// in; actuator/nozzle_pwm/duty out).
//   --domain N  --node-name NAME  --config FILE  --state-dir DIR  --clock lockstep|realtime
// Wired mode (real time only, the bench path of docs/seed001-boundary.md): the
// inputs from serial lines, as the Pi's UARTs have them; the PWM duty stays on DDS.
//   --nmea-serial PATH [--nmea-baud N]     the AD300's RMC line
//   --laser-serial PATH [--laser-baud N]   the L4 laser's line
#include <CLI/CLI.hpp>

#include <iostream>

#include "controller/boundary/boundary_controller_node.h"
#include "controller/boundary/boundary_node_config.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/lockstep.h"
#include "rig/runtime/realtime.h"

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
    app.add_option("--clock", clock_mode, "lockstep (virtual time) or realtime (wall clock)")
        ->check(CLI::IsMember({"lockstep", "realtime"}));
    rig::controller::boundary::BoundarySerialLines serial;
    app.add_option("--nmea-serial", serial.nmea_port, "wired mode: serial port with the AD300's RMC");
    app.add_option("--nmea-baud", serial.nmea_line.baud, "wired mode: RMC line baud rate");
    app.add_option("--laser-serial", serial.laser_port, "wired mode: serial port with the L4 laser's lines");
    app.add_option("--laser-baud", serial.laser_line.baud, "wired mode: laser line baud rate");
    CLI11_PARSE(app, argc, argv);
    try {
        const bool wired = !serial.nmea_port.empty() || !serial.laser_port.empty();
        if (wired && clock_mode != "realtime") throw std::runtime_error("wired mode runs on the wall clock: add --clock realtime");
        // The context first: the node's readers and writers unregister from it
        // when the node is destroyed, so it must outlive the node.
        rig::DdsContext dds(domain_id, node_name, /*watch_discovery=*/false,
                            clock_mode == "realtime" ? rig::ReliabilityTimers::prompt_repair
                                                     : rig::ReliabilityTimers::few_wakeups);
        rig::controller::boundary::BoundaryControllerNode controller(
            node_name, rig::controller::boundary::load_boundary_node_config(config_file), serial);
        rig::FollowerOptions options;
        options.node_name = node_name;
        if (clock_mode == "realtime") {
            std::cerr << node_name << ": " << rig::request_realtime_scheduling(40).detail << "\n";
            return rig::run_realtime_follower(controller, dds, options);
        }
        rig::ManualClock clock;
        return rig::run_lockstep_follower(controller, dds, clock, options);
    } catch (const std::exception& error) {
        std::cerr << node_name << ": " << error.what() << "\n";
        return 2;
    }
}
