#include "harness/session/case_session.h"

#include <cmath>
#include <fstream>

#include <yaml-cpp/yaml.h>

#include "rig/host/shm_cleanup.h"
#include "rig/runtime/lockstep.h"
#include "rig/wire/hid_board.h"
#include "rig/wire/modbus_protocol.h"

namespace rig::harness {

std::string controller_config_text(const CaseSpec& spec) {
    YAML::Node section = spec.controller.params.present ? YAML::Clone(spec.controller.params.node) : YAML::Node();
    if (section.IsMap()) {
        for (std::string_view key : kControllerRigKeys) section.remove(std::string(key));
    }
    if (section.IsNull()) return "{}";
    YAML::Emitter out;
    out << section;
    return out.c_str();
}

namespace {


// The controller's parameters as their own YAML file (the case section minus `command`).
void write_controller_config(const CaseSpec& spec, const std::filesystem::path& file) {
    std::ofstream(file) << "# the `controller:` section of " << spec.source_path.string() << "\n"
                        << controller_config_text(spec) << "\n";
}

std::string log_tail(const std::filesystem::path& log, std::size_t max_lines) {
    std::ifstream in(log);
    std::vector<std::string> lines;
    std::string line;
    while (std::getline(in, line)) {
        lines.push_back(line);
        if (lines.size() > max_lines) lines.erase(lines.begin());
    }
    std::string tail;
    for (const auto& kept : lines) tail += "\n    | " + kept;
    return tail;
}

modbus::CommsFailsafe comms_failsafe(const BoardSpec& board) {
    return {std::chrono::milliseconds(std::lround(board.failsafe_timeout_s * 1000.0)), board.failsafe};
}

// A serial line the rig writes: `port` is "pty" (a pseudo-terminal made here)
// or a device path. Sets `writer` to the rig's end; returns the far end's path.
std::string open_serial_line(const std::string& port, int baud, std::unique_ptr<PtyPair>& pty,
                             std::unique_ptr<SerialPort>& device, SerialPort*& writer) {
    SerialSettings line;
    line.baud = baud;
    if (port == "pty") {
        pty = std::make_unique<PtyPair>(PtyOptions{line, {}});
        writer = &pty->master();
        return pty->slave_path();
    }
    device = std::make_unique<SerialPort>(port, line);
    writer = device.get();
    return port;
}

}  // namespace

BenchWires open_bench_wires(const CaseSpec& spec, const HidTransportOpener& open_hid) {
    BenchWires wires;
    const WiringSpec& wiring = spec.wiring;
    std::vector<std::string> parts;
    if (wiring.gnss == GnssWire::serial) {
        const std::string far_end =
            open_serial_line(wiring.gnss_port, wiring.nmea_baud, wires.gnss_pty, wires.gnss_device, wires.gnss_port);
        wires.gnss_far_end = far_end;
        wires.controller_args.insert(wires.controller_args.end(),
                                     {"--nmea-serial", far_end, "--nmea-baud", std::to_string(wiring.nmea_baud)});
        parts.push_back("gnss serial " + far_end + " " + std::to_string(wiring.nmea_baud) + " baud");
    } else {
        parts.push_back("gnss dds");
    }
    if (wiring.laser == GnssWire::serial) {
        wires.laser_far_end = open_serial_line(wiring.laser_port, wiring.laser_baud, wires.laser_pty,
                                               wires.laser_device, wires.laser_port);
        wires.controller_args.insert(wires.controller_args.end(), {"--laser-serial", wires.laser_far_end,
                                                                   "--laser-baud", std::to_string(wiring.laser_baud)});
        parts.push_back("laser serial " + wires.laser_far_end + " " + std::to_string(wiring.laser_baud) + " baud");
    } else if (spec.system && spec.system->reads_laser_line()) {
        parts.push_back("laser dds");
    }
    switch (wiring.board_io) {
        case BoardIoWireKind::dds: parts.push_back("board_io dds"); break;
        case BoardIoWireKind::modbus_rtu: {
            modbus::RtuSlaveOptions options;
            options.line.baud = wiring.modbus_baud;
            options.failsafe = comms_failsafe(spec.board);
            std::string far_end = wiring.modbus_port;
            if (wiring.modbus_port == "pty") {
                wires.modbus_link = std::make_unique<PtyLink>();
                options.line.device = wires.modbus_link->slave_path_a();
                far_end = wires.modbus_link->slave_path_b();
            } else {
                options.line.device = wiring.modbus_port;
            }
            wires.board_io = std::make_unique<ModbusSlaveWire>(options);
            wires.board_io_far_end = far_end;
            wires.controller_args.insert(wires.controller_args.end(), {"--modbus-rtu", far_end, "--modbus-baud",
                                                                       std::to_string(wiring.modbus_baud)});
            parts.push_back("board_io modbus_rtu " + far_end + " " + std::to_string(wiring.modbus_baud) + " baud");
            break;
        }
        case BoardIoWireKind::modbus_tcp: {
            modbus::TcpSlaveOptions options;
            const modbus::TcpEndpoint endpoint = modbus::parse_tcp_endpoint(wiring.modbus_tcp);
            options.bind_address = endpoint.address;
            options.port = endpoint.port;
            options.failsafe = comms_failsafe(spec.board);
            auto wire = std::make_unique<ModbusSlaveWire>(options);
            const std::string address = endpoint.address + ":" + std::to_string(wire->slave().tcp_port());
            wires.controller_args.insert(wires.controller_args.end(), {"--modbus-tcp", address});
            wires.board_io_far_end = address;
            parts.push_back("board_io modbus_tcp " + address);
            wires.board_io = std::move(wire);
            break;
        }
        case BoardIoWireKind::hid: {
            // A real bench board; the controller is wired to it, not to the rig process.
            std::unique_ptr<HidTransport> transport = open_hid ? open_hid(wiring.hid_vid, wiring.hid_pid)
                                                               : HidapiTransport::open(wiring.hid_vid, wiring.hid_pid);
            const std::string description = transport->description();
            wires.board_io_far_end = description;
            wires.board_io = std::make_unique<HidBoardWire>(std::make_unique<HidBoard>(std::move(transport)), description);
            parts.push_back("board_io hid " + description);
            break;
        }
    }
    wires.description.clear();
    for (const std::string& part : parts) wires.description += (wires.description.empty() ? "" : ", ") + part;
    return wires;
}



CaseSession::CaseSession(const CaseSpec& spec, const std::filesystem::path& case_dir,
                         std::optional<std::uint32_t> domain, const HidTransportOpener& open_hid)
    : wires_(open_bench_wires(spec, open_hid)),
      lease_(domain ? DomainLease::acquire_exact(*domain) : spec.domain ? DomainLease::acquire_exact(*spec.domain)
                                                                         : DomainLease::acquire()),
      controller_log_(case_dir / "controller.log") {}

void CaseSession::start_controller(const CaseSpec& spec, const std::filesystem::path& controller_executable,
                                   const std::filesystem::path& case_dir, const std::vector<std::string>& environment,
                                   const std::vector<std::string>& inputs) {
    // The controller under test, in its own process on this run's own domain
    // (none when a real board is wired up: `wiring: { controller: external }`).
    if (controller_ || in_process_) return;
    // An external board is given the same file beside attach.json (a seed-001
    // Pi takes its mounting from it, and its areas from the job beside it).
    write_controller_config(spec, case_dir / "controller.yaml");
    if (spec.wiring.external_controller) return;
    std::vector<std::string> argv = spec.controller.command;
    if (argv.empty()) {
        argv.push_back(controller_executable.string());
    } else if (argv[0].find('/') != std::string::npos && std::filesystem::path(argv[0]).is_relative()) {
        // A relative path names a program beside the case file (a bare name is
        // looked up in PATH), wherever `rig run` is started from.
        argv[0] = (std::filesystem::absolute(spec.source_path).parent_path() / argv[0]).lexically_normal().string();
    }
    for (const std::string& arg :
         {std::string("--domain"), std::to_string(lease_.domain_id()), std::string("--node-name"),
          std::string("controller"), std::string("--config"), (case_dir / "controller.yaml").string(),
          std::string("--state-dir"), (case_dir / "controller-state").string()}) {
        argv.push_back(arg);
    }
    argv.insert(argv.end(), inputs.begin(), inputs.end());
    if (spec.mode == ClockMode::realtime) {
        argv.insert(argv.end(), {"--clock", "realtime"});
        argv.insert(argv.end(), wires_.controller_args.begin(), wires_.controller_args.end());
    }
    controller_.emplace(argv, controller_log_, environment);
}

std::string CaseSession::start_in_process_controller(const CaseSpec& spec, const std::filesystem::path& plugin,
                                                     const std::filesystem::path& case_dir, DdsContext& harness_dds) {
    write_controller_config(spec, case_dir / "controller.yaml");
    std::string refusal;
    in_process_ = InProcessController::make(load_controller_plugin(plugin), case_dir / "controller.yaml",
                                            case_dir / "controller-state", controller_log_, harness_dds, refusal);
    return refusal;
}

CaseSession::~CaseSession() {
    if (controller_) controller_->stop(std::chrono::milliseconds(500));
    // A controller that had to be killed left its Fast DDS segments in /dev/shm (rig/host/shm_cleanup.h).
    remove_dead_participant_segments();
}

std::string CaseSession::controller_mode() const {
    if (in_process_) return "in_process";
    return controller_ ? "process" : "external";
}

std::string CaseSession::controller_command_line() const {
    if (in_process_) return "in process: " + in_process_->plugin_file().string();
    return controller_ ? controller_->command_line() : "external (a wired board)";
}

std::optional<std::string> CaseSession::controller_gone() {
    return controller_ ? controller_->exit_description() : std::nullopt;
}

std::string CaseSession::stop_controller(std::chrono::milliseconds grace) {
    return controller_ ? controller_->stop(grace) : std::string("process exited with status 0");
}

TraceOutcome CaseSession::run_to_outcome(const std::function<void()>& run, TimeNs end_ns, const TimeNs& now_ns) {
    TraceOutcome outcome;
    try {
        run();
        const std::string ended = stop_controller(std::chrono::milliseconds(3000));
        if (ended != "process exited with status 0") {
            throw NodeFailure(FailureKind::node_exited, "controller", "after shutdown: " + ended);
        }
        outcome.end_ns = end_ns;
    } catch (const NodeFailure& failure) {
        stop_controller(std::chrono::milliseconds(500));
        outcome.status = failure.kind() == FailureKind::interrupted ? "interrupted" : "error";
        outcome.error_kind = std::string(to_string(failure.kind()));
        outcome.error = failure.what() + controller_log_tail();
        outcome.end_ns = now_ns;
    } catch (const std::exception& error) {
        // The rig's own side failed (a DDS write, the trace): the case cannot be judged on the controller.
        stop_controller(std::chrono::milliseconds(500));
        outcome.status = "error";
        outcome.error_kind = std::string(to_string(FailureKind::harness_error));
        outcome.error = std::string("node 'harness': ") + error.what();
        outcome.end_ns = now_ns;
    }
    return outcome;
}

std::string CaseSession::controller_log_tail(std::size_t max_lines) const {
    return controller_ || in_process_ ? log_tail(controller_log_, max_lines) : std::string();
}

std::string CaseSession::unread_problem(PtyPair* pty, const std::string& line, const std::string& far_end,
                                        const std::string& what, UnreadWatch& watch,
                                        std::chrono::milliseconds unread_for) {
    if (pty == nullptr) return {};
    const std::size_t unread = pty->unread_bytes();
    // Bytes waiting is normal between reads; bytes waiting that never go down
    // mean nobody has the line open, or nobody reads it.
    if (unread == 0 || unread < watch.unread) {
        watch.since.reset();
    } else if (!watch.since) {
        watch.since.emplace();
    }
    watch.unread = unread;
    if (watch.since && watch.since->elapsed() > unread_for) {
        return "nobody reads the " + line + " line " + far_end + ": " + std::to_string(unread) + " bytes of " + what +
               " written to it have waited unread for more than " + std::to_string(unread_for.count()) +
               " ms (is the board attached to that port?)";
    }
    return {};
}

std::string CaseSession::wire_problem(std::chrono::milliseconds unread_for) {
    std::string problem =
        unread_problem(wires_.gnss_pty.get(), "GNSS", wires_.gnss_far_end, "NMEA", gnss_watch_, unread_for);
    if (problem.empty()) {
        problem = unread_problem(wires_.laser_pty.get(), "laser", wires_.laser_far_end, "laser lines", laser_watch_,
                                 unread_for);
    }
    return problem;
}

}  // namespace rig::harness
