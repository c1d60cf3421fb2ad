// boundary_board_player: a seed-001 Raspberry Pi on the bench, as a process
// outside the rig (`wiring: { controller: external }`, docs/seed001-boundary.md
// "Bench path"). It does what a Pi wired to the rig does: takes the ports from
// the attach.json the rig writes (gnss_nmea: the AD300's RMC, laser_serial: the
// L4's lines) and its configuration from the controller.yaml beside it, reads
// both lines as its UARTs would, and publishes its six nozzle duties on DDS in
// the run's domain (attach.json `dds_domain`), on its own wall clock: the rig's
// start tick is not addressed to it. The logic is the reference controller's
// (BoundaryControllerNode in wired mode): what is under test here is the rig's
// side of the wires. It ends when the rig closes the lines at the case's end.
//   boundary_board_player --attach OUT/cases/NAME/attach.json [--wait-s 60]
//                         [--leave-laser-unread 1]
// --leave-laser-unread: a miswired Pi that opens the laser line but never
// reads it (its height then comes from DDS): the rig must fail the case at
// once, naming that line.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "controller/boundary/boundary_controller_node.h"
#include "controller/boundary/boundary_node_config.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/realtime.h"

namespace {

std::string port_of(const nlohmann::json& attach, const std::string& role) {
    for (const nlohmann::json& port : attach.at("ports")) {
        if (port.at("role") == role) return port.at("path").get<std::string>();
    }
    throw std::runtime_error("attach.json lists no " + role + " port");
}

}  // namespace

int main(int argc, char** argv) {
    std::filesystem::path attach_file;
    double wait_s = 60.0;
    bool leave_laser_unread = false;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (i + 1 >= argc) {
            std::cerr << "boundary_board_player: " << arg << " needs a value\n";
            return 2;
        }
        const std::string value = argv[++i];
        if (arg == "--attach") attach_file = value;
        else if (arg == "--wait-s") wait_s = std::stod(value);
        else if (arg == "--leave-laser-unread") leave_laser_unread = value == "1";
        else {
            std::cerr << "boundary_board_player: unknown option " << arg << "\n";
            return 2;
        }
    }
    if (attach_file.empty()) {
        std::cerr << "usage: boundary_board_player --attach OUT/cases/NAME/attach.json [--wait-s 60]\n";
        return 2;
    }
    try {
        const rig::RealtimeClock clock;
        // The rig writes attach.json before it waits for the board.
        while (!std::filesystem::exists(attach_file)) {
            if (rig::ns_to_seconds(clock.now_ns()) > wait_s) {
                std::cerr << "boundary_board_player: no " << attach_file << " after " << wait_s << " s\n";
                return 1;
            }
            clock.sleep_until_ns(clock.now_ns() + rig::seconds_to_ns(0.05));
        }
        std::ifstream in(attach_file);
        const nlohmann::json attach = nlohmann::json::parse(in);
        rig::controller::boundary::BoundarySerialLines lines;
        lines.nmea_port = port_of(attach, "gnss_nmea");
        lines.laser_port = port_of(attach, "laser_serial");
        std::optional<rig::SerialPort> unread_laser;
        if (leave_laser_unread) {
            unread_laser.emplace(lines.laser_port);
            lines.laser_port.clear();
        }
        const auto domain = attach.at("dds_domain").get<std::uint32_t>();
        rig::DdsContext dds(domain, "pi_player");
        rig::controller::boundary::BoundaryControllerNode pi(
            "pi_player",
            // Its configuration, and the job the rig named in attach.json (the target areas, the cameras).
            rig::controller::boundary::load_boundary_node_config(
                attach_file.parent_path() / "controller.yaml",
                attach_file.parent_path() / attach.at("job").get<std::string>()),
            lines);
        pi.configure(dds);
        // A Pi's controller loop runs at real-time priority, as the reference controller asks.
        std::cout << "boundary_board_player: " << rig::request_realtime_scheduling(40).detail << std::endl;
        std::cout << "boundary_board_player: RMC on " << lines.nmea_port << ", laser on " << lines.laser_port
                  << ", PWM on DDS domain " << domain << std::endl;
        for (;;) {
            const rig::TimeNs now = clock.now_ns();
            rig::TimeNs next = pi.step(now);
            clock.sleep_until_ns(std::max(next, now));
        }
    } catch (const rig::SerialError& error) {
        // The rig closes its ends when the case is over: the normal way out.
        if (error.kind() == rig::SerialError::Kind::closed) {
            std::cout << "boundary_board_player: " << error.what() << ": done" << std::endl;
            return 0;
        }
        std::cerr << "boundary_board_player: " << error.what() << "\n";
        return 1;
    } catch (const std::exception& error) {
        std::cerr << "boundary_board_player: " << error.what() << "\n";
        return 1;
    }
}
