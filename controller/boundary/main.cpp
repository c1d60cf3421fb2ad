// rig-boundary-controller: seed 001's reference controller (positioning and
// boundary half) as its own executable, started and driven by the harness like
// rig-controller (docs/controller-contract.md): the same arguments, the same
// clock protocol, its own topics (device/gnss/nmea, device/laser_height/serial
// in; actuator/nozzle_pwm/duty out).
//   --domain N  --node-name NAME  --config FILE  --state-dir DIR  --clock lockstep|realtime
//   --job FILE  the job (docs/controller-contract.md "The job"): the target areas
//               and the cameras, for what the configuration does not say
// Before a run, the rig asks it to check a case's section, without starting anything:
//   --check-config FILE [--config-section KEY]  exit 0 when valid, else 2 with
//               the error (file:line:col: key: message) on standard error
// Wired mode (real time only, the bench path of docs/seed001-boundary.md): the
// inputs from serial lines, as the Pi's UARTs have them; the PWM duty stays on DDS.
//   --nmea-serial PATH [--nmea-baud N]     the AD300's RMC line
//   --laser-serial PATH [--laser-baud N]   the L4 laser's line
#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>

#include "controller/boundary/boundary_controller_node.h"
#include "controller/boundary/boundary_node_config.h"
#include "rig/runtime/follower.h"

int main(int argc, char** argv) {
    CLI::App app{"Reference boundary shut-off controller (seed 001) as a rig node"};
    std::uint32_t domain_id = 0;
    std::string node_name = "controller";
    std::string config_file;
    std::string job_file;
    std::string check_file;
    std::string check_section;
    std::string state_dir = ".";
    std::string clock_mode = "lockstep";
    auto* check = app.add_option("--check-config", check_file,
                                 "check the controller section in FILE and exit (0: valid; 2: the error on stderr)");
    app.add_option("--config-section", check_section, "with --check-config: the key of FILE that holds the section")
        ->needs(check);
    auto* domain = app.add_option("--domain", domain_id, "DDS domain id of the run")->excludes(check);
    app.add_option("--node-name", node_name, "node name used in clock acknowledgements");
    app.add_option("--config", config_file, "YAML file with the controller section")->excludes(check);
    app.add_option("--job", job_file, "the job: target areas and cameras (docs/controller-contract.md)")->excludes(check);
    app.add_option("--state-dir", state_dir, "directory for persistent state (unused: it keeps none)");
    app.add_option("--clock", clock_mode, "lockstep (virtual time) or realtime (wall clock)")
        ->check(CLI::IsMember({"lockstep", "realtime"}));
    rig::controller::boundary::BoundarySerialLines serial;
    app.add_option("--nmea-serial", serial.nmea_port, "wired mode: serial port with the AD300's RMC");
    app.add_option("--nmea-baud", serial.nmea_line.baud, "wired mode: RMC line baud rate");
    app.add_option("--laser-serial", serial.laser_port, "wired mode: serial port with the L4 laser's lines");
    app.add_option("--laser-baud", serial.laser_line.baud, "wired mode: laser line baud rate");
    CLI11_PARSE(app, argc, argv);
    if (!check_file.empty()) {
        try {
            const rig::YamlSection file = rig::YamlSection::load_file(check_file);
            rig::controller::boundary::check_boundary_node_config(check_section.empty() ? file
                                                                                        : file.section(check_section));
            return 0;
        } catch (const std::exception& error) {
            std::cerr << error.what() << "\n";
            return 2;
        }
    }
    if (config_file.empty() || domain->count() == 0) {
        std::cerr << node_name << ": --domain N and --config FILE are required (or --check-config FILE)\n";
        return 2;
    }
    try {
        const bool wired = !serial.nmea_port.empty() || !serial.laser_port.empty();
        if (wired && clock_mode != "realtime") throw std::runtime_error("wired mode runs on the wall clock: add --clock realtime");
        rig::FollowerStartup startup;
        startup.domain_id = domain_id;
        startup.clock = rig::clock_mode_from(clock_mode);
        startup.options.node_name = node_name;
        return rig::run_follower(startup, [&] {
            return std::make_unique<rig::controller::boundary::BoundaryControllerNode>(
                node_name,
                rig::controller::boundary::load_boundary_node_config(
                    config_file, job_file.empty() ? std::nullopt : std::optional<std::filesystem::path>(job_file)),
                serial);
        });
    } catch (const std::exception& error) {
        std::cerr << node_name << ": " << error.what() << "\n";
        return 2;
    }
}
