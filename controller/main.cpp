// rig-controller: the reference controller as its own executable. The harness
// starts it with the command a case names (this one by default) and drives it
// over DDS. A team's own controller, built against rig::runtime, takes the same
// arguments and drops in unchanged:
//   --domain N        DDS domain of the run
//   --node-name NAME  name it answers the clock with
//   --config FILE     the case's `controller:` section as YAML
//   --state-dir DIR   where it keeps persistent state (the breakpoint store)
//   --clock lockstep|realtime
//                     lockstep: step when the harness's tick says (virtual time);
//                     realtime: run on the wall clock from the harness's start tick
// Wired mode (real time only): instead of DDS device and actuator topics, the
// board's wires, as on the bench:
//   --nmea-serial PATH [--nmea-baud N]        the G970II's RS232 line
//   --modbus-rtu PATH [--modbus-baud N] [--modbus-parity N|E|O] [--modbus-slave-id N]
//   --modbus-tcp ADDRESS:PORT                 the board's I/O through the rig's register map
// Fault injection: --stall-at-s T stops answering the clock at simulated time T
// (the rig must then fail the case by the node's name, in bounded time).
#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>

#include "controller/controller_config.h"
#include "controller/reference_controller.h"
#include "controller/wired_board_controller.h"
#include "rig/runtime/follower.h"
#include "rig/wire/modbus_protocol.h"

int main(int argc, char** argv) {
    CLI::App app{"Reference breakpoint-spraying controller (seed 000) as a rig node"};
    std::uint32_t domain_id = 0;
    std::string node_name = "controller";
    std::string config_file;
    std::string state_dir = ".";
    std::string clock_mode = "lockstep";
    rig::controller::WiredBoardOptions wired;
    std::string modbus_rtu_device;
    int modbus_baud = 115200;
    std::string modbus_parity = "N";
    int modbus_slave_id = 1;
    std::string modbus_tcp;
    app.add_option("--domain", domain_id, "DDS domain id of the run")->required();
    app.add_option("--node-name", node_name, "node name used in clock acknowledgements");
    app.add_option("--config", config_file, "YAML file with the controller section")->required();
    app.add_option("--state-dir", state_dir, "directory for persistent state (breakpoint store)");
    app.add_option("--clock", clock_mode, "lockstep (virtual time) or realtime (wall clock)")
        ->check(CLI::IsMember({"lockstep", "realtime"}));
    app.add_option("--nmea-serial", wired.nmea_port, "wired mode: serial port with the GNSS NMEA stream");
    app.add_option("--nmea-baud", wired.nmea_line.baud, "wired mode: NMEA line baud rate");
    app.add_option("--modbus-rtu", modbus_rtu_device, "wired mode: serial port of the rig's Modbus RTU slave");
    app.add_option("--modbus-baud", modbus_baud, "wired mode: Modbus RTU baud rate");
    app.add_option("--modbus-parity", modbus_parity, "wired mode: Modbus RTU parity")->check(CLI::IsMember({"N", "E", "O"}));
    app.add_option("--modbus-slave-id", modbus_slave_id, "wired mode: Modbus slave id")->check(CLI::Range(1, 247));
    app.add_option("--modbus-tcp", modbus_tcp, "wired mode: ADDRESS:PORT of the rig's Modbus TCP slave");
    double stall_at_s = -1.0;
    app.add_option("--stall-at-s", stall_at_s,
                   "fault injection (lockstep): stop answering the clock from this simulated time on");
    CLI11_PARSE(app, argc, argv);

    const bool wired_mode = !wired.nmea_port.empty() || !modbus_rtu_device.empty() || !modbus_tcp.empty();
    try {
        const auto config = rig::controller::load_controller_config(config_file);
        rig::FollowerStartup startup;
        startup.domain_id = domain_id;
        startup.clock = rig::clock_mode_from(clock_mode);
        startup.options.node_name = node_name;
        if (stall_at_s >= 0.0) startup.options.stall_at_ns = rig::seconds_to_ns(stall_at_s);
        // TEST-ONLY fault (the catalogue of faulty controllers): the same stall from the case file.
        if (config.faults.stall_at_s >= 0.0) startup.options.stall_at_ns = rig::seconds_to_ns(config.faults.stall_at_s);
        // The node is made once the follower's DDS context exists
        // (rig/runtime/follower.h); the wired options are checked as it is made.
        return rig::run_follower(startup, [&]() -> std::unique_ptr<rig::Node> {
            if (wired_mode) {
                if (startup.clock != rig::ClockMode::realtime) {
                    throw std::runtime_error("wired mode runs on the wall clock: add --clock realtime");
                }
                if (modbus_rtu_device.empty() == modbus_tcp.empty()) {
                    throw std::runtime_error("wired mode needs exactly one of --modbus-rtu and --modbus-tcp");
                }
                if (!modbus_rtu_device.empty()) {
                    rig::modbus::RtuMasterOptions rtu;
                    rtu.line.device = modbus_rtu_device;
                    rtu.line.baud = modbus_baud;
                    rtu.line.parity = rig::modbus::parse_parity(modbus_parity);
                    rtu.slave_id = static_cast<std::uint8_t>(modbus_slave_id);
                    wired.modbus_rtu = rtu;
                } else {
                    rig::modbus::TcpMasterOptions tcp;
                    tcp.slave = rig::modbus::parse_tcp_endpoint(modbus_tcp);
                    wired.modbus_tcp = tcp;
                }
                return std::make_unique<rig::controller::WiredBoardController>(node_name, config, state_dir, wired);
            }
            return std::make_unique<rig::controller::ReferenceController>(node_name, config, state_dir);
        });
    } catch (const std::exception& error) {
        std::cerr << node_name << ": " << error.what() << "\n";
        return 2;
    }
}
