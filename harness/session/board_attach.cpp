#include "harness/session/board_attach.h"

#include <unistd.h>

#include <cmath>
#include <ostream>
#include <system_error>

#include "harness/output/atomic_file.h"
#include "harness/session/line_noise.h"
#include "rig/runtime/lockstep.h"
#include "rig/wire/modbus_slave.h"
#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

// How often the attach wait looks at the wires: well under a person's
// reaction, and /proc is scanned at most this often.
constexpr std::chrono::milliseconds kAttachPoll{50};

constexpr const char* kFirstRequest = "its first valid Modbus request addressed to the rig";
constexpr const char* kPtyOpened = "a process other than the rig opens the pty";
constexpr const char* kNotObservable = "not observable (a serial device's transmit line)";

std::string seconds_text(double seconds, int decimals = 2) { return fixed_text(seconds, decimals); }

std::string line_settings(int baud) { return std::to_string(baud) + " 8N1"; }

}  // namespace

std::vector<AttachPort> attach_ports(const WiringSpec& wiring, const BenchWires& wires) {
    std::vector<AttachPort> ports;
    if (wiring.gnss == GnssWire::serial) {
        ports.push_back(AttachPort{"gnss_nmea", wires.gnss_far_end, line_settings(wiring.nmea_baud),
                                   wires.gnss_pty ? kPtyOpened : kNotObservable});
    }
    if (wiring.laser == GnssWire::serial) {
        ports.push_back(AttachPort{"laser_serial", wires.laser_far_end, line_settings(wiring.laser_baud),
                                   wires.laser_pty ? kPtyOpened : kNotObservable});
    }
    switch (wiring.board_io) {
        case BoardIoWireKind::dds: break;
        case BoardIoWireKind::modbus_rtu:
            ports.push_back(AttachPort{"modbus_rtu", wires.board_io_far_end, "slave 1 " + line_settings(wiring.modbus_baud),
                                       kFirstRequest});
            break;
        case BoardIoWireKind::modbus_tcp:
            ports.push_back(AttachPort{"modbus_tcp", wires.board_io_far_end, "any unit id", kFirstRequest});
            break;
        case BoardIoWireKind::hid:
            ports.push_back(AttachPort{"hid", wires.board_io_far_end, "", "not observable (the board's own wiring)"});
            break;
    }
    return ports;
}

std::string attach_line(const std::vector<AttachPort>& ports, const std::string& run_name, const BoardSpec& board) {
    std::string line = "attach:";
    for (const AttachPort& port : ports) line += " " + port.role + "=" + port.path;
    return line + " (case " + run_name + "; waiting up to " + seconds_text(board.attach_timeout_s, 1) +
           " s; details in attach.json)";
}

nlohmann::json attach_json(const std::vector<AttachPort>& ports, const std::string& run_name, const BoardSpec& board) {
    nlohmann::json listed = nlohmann::json::array();
    for (const AttachPort& port : ports) {
        listed.push_back(
            {{"role", port.role}, {"path", port.path}, {"settings", port.settings}, {"attached_when", port.attached_when}});
    }
    return {{"case", run_name},
            {"ports", std::move(listed)},
            {"register_map", "docs/modbus-register-map.md"},
            {"attach_timeout_s", board.attach_timeout_s},
            {"silence_timeout_s", board.silence_timeout_s},
            {"failsafe_timeout_s", board.failsafe_timeout_s},
            {"failsafe", std::string(modbus::to_string(board.failsafe))}};
}

void announce_attach(const WiringSpec& wiring, const BoardSpec& board, const BenchWires& wires, const std::string& run_name,
                     const std::filesystem::path& case_dir, std::ostream& out, const nlohmann::json& system) {
    const std::vector<AttachPort> ports = attach_ports(wiring, wires);
    // The file first: whoever reacts to the line finds the file already there.
    nlohmann::json attach = attach_json(ports, run_name, board);
    if (system.is_object()) attach.update(system);
    write_file_atomically(case_dir / "attach.json", attach.dump(2) + "\n");
    out << attach_line(ports, run_name, board) << std::endl;
}

std::vector<int> processes_holding(const std::filesystem::path& path) {
    std::vector<int> pids;
    std::error_code error;
    const std::filesystem::path target = std::filesystem::canonical(path, error);
    if (error) return pids;
    const int self = static_cast<int>(::getpid());
    for (const auto& process : std::filesystem::directory_iterator("/proc", error)) {
        const std::string name = process.path().filename().string();
        if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
        const int pid = std::stoi(name);
        if (pid == self) continue;
        std::error_code fd_error;  // processes end and forbid reading: skip those
        for (const auto& fd : std::filesystem::directory_iterator(process.path() / "fd", fd_error)) {
            std::error_code link_error;
            if (std::filesystem::read_symlink(fd.path(), link_error) == target && !link_error) {
                pids.push_back(pid);
                break;
            }
        }
    }
    return pids;
}

modbus::ModbusSlave* modbus_slave_of(BenchWires& wires) {
    auto* wire = dynamic_cast<ModbusSlaveWire*>(wires.board_io.get());
    return wire ? &wire->slave() : nullptr;
}

BoardAttachment wait_for_board(const BoardSpec& board, BenchWires& wires, const std::function<void()>& watchdog) {
    const WallStopwatch waited;
    BoardAttachment attachment;
    modbus::ModbusSlave* slave = modbus_slave_of(wires);
    bool nmea_open = !wires.gnss_pty;  // only a pty's peer is observable
    bool laser_open = !wires.laser_pty;
    bool modbus_heard = slave == nullptr;
    const auto look_at_pty = [&](bool& open, const char* role, const std::string& far_end) {
        if (open) return;
        const std::vector<int> holders = processes_holding(far_end);
        if (holders.empty()) return;
        open = true;
        attachment.seen.push_back(std::string(role) + " " + far_end + " opened by pid " + std::to_string(holders.front()) +
                                  " after " + seconds_text(waited.elapsed_s()) + " s");
    };
    for (;;) {
        look_at_pty(nmea_open, "gnss_nmea", wires.gnss_far_end);
        look_at_pty(laser_open, "laser_serial", wires.laser_far_end);
        if (!modbus_heard && slave->statistics().valid_requests > 0) {
            modbus_heard = true;
            attachment.seen.push_back("first valid Modbus request on " + wires.board_io_far_end + " after " +
                                      seconds_text(waited.elapsed_s()) + " s");
        }
        if (nmea_open && laser_open && modbus_heard) break;
        if (waited.elapsed_s() > board.attach_timeout_s) {
            std::string missing;
            if (!nmea_open) missing += "no process opened the GNSS NMEA line " + wires.gnss_far_end;
            if (!laser_open) {
                missing += std::string(missing.empty() ? "" : "; ") + "no process opened the laser line " + wires.laser_far_end;
            }
            if (!modbus_heard) {
                const modbus::ModbusSlaveStatistics stats = slave->statistics();
                missing += std::string(missing.empty() ? "" : "; ") + "no valid Modbus request came on " +
                           wires.board_io_far_end + " (frames dropped: " + std::to_string(stats.bad_crc_frames) +
                           " bad CRC, " + std::to_string(stats.other_slave_frames) + " for other slave ids, " +
                           std::to_string(stats.malformed_frames) + " malformed)";
            }
            throw NodeFailure(FailureKind::board_not_attached, "board",
                              "not attached within board.attach_timeout_s = " + seconds_text(board.attach_timeout_s, 1) +
                                  " s: " + missing);
        }
        watchdog();
        pause_between_polls(kAttachPoll);
    }
    attachment.waited_s = waited.elapsed_s();
    return attachment;
}

BoardSilenceWatch::BoardSilenceWatch(const BoardSpec& board, BenchWires& wires)
    : slave_(modbus_slave_of(wires)),
      timeout_(std::chrono::nanoseconds(seconds_to_ns(board.silence_timeout_s))) {}

void BoardSilenceWatch::check(TimeNs case_now_ns) {
    if (slave_ == nullptr) return;
    if (!since_start_) since_start_.emplace();  // the first check is at the case's start
    const std::optional<std::chrono::nanoseconds> since_request = slave_->since_last_request();
    const std::chrono::nanoseconds silent =
        since_request ? std::min<std::chrono::nanoseconds>(*since_request, since_start_->elapsed())
                      : std::chrono::nanoseconds(since_start_->elapsed());
    if (silent <= timeout_) return;
    const double silent_s = std::chrono::duration<double>(silent).count();
    const double last_at_s = ns_to_seconds(case_now_ns) - silent_s;
    const modbus::ModbusSlaveStatistics stats = slave_->statistics();
    std::string message = "the Modbus master has been silent for " + seconds_text(silent_s) +
                          " s (board.silence_timeout_s = " + seconds_text(std::chrono::duration<double>(timeout_).count()) +
                          " s): ";
    message += since_request && *since_request <= since_start_->elapsed()
                   ? "its last valid request came at case time t=" + seconds_text(last_at_s, 3) + " s"
                   : std::string("no valid request since the case started");
    message += ", " + std::to_string(stats.valid_requests) + " valid requests in all; the case is at t=" +
               seconds_text(ns_to_seconds(case_now_ns), 3) + " s";
    throw NodeFailure(FailureKind::board_silent, "board", message);
}

nlohmann::json board_io_report(const BoardSpec& board, BenchWires& wires, const std::optional<BoardAttachment>& attachment) {
    modbus::ModbusSlave* slave = modbus_slave_of(wires);
    if (slave == nullptr) return nullptr;
    const modbus::ModbusSlaveStatistics stats = slave->statistics();
    nlohmann::json report = {
        {"slave", slave->endpoint()},
        {"valid_requests", stats.valid_requests},
        {"answered", stats.requests_answered},
        {"broadcast", stats.broadcast_requests},
        {"master_writes", stats.master_writes},
        // Valid requests answered with a Modbus exception.
        {"refused",
         {{"illegal_function", stats.illegal_function},
          {"illegal_data_address", stats.illegal_data_address},
          {"illegal_data_value", stats.illegal_data_value}}},
        // Frames never answered.
        {"dropped",
         {{"bad_crc", stats.bad_crc_frames},
          {"wrong_address", stats.other_slave_frames},
          {"malformed", stats.malformed_frames},  // RTU truncated or oversized; TCP bad MBAP header
          {"response_not_sent", stats.responses_not_sent}}},
        {"failsafe",
         {{"mode", std::string(modbus::to_string(board.failsafe))},
          {"timeout_s", board.failsafe_timeout_s},
          {"trips", stats.failsafe_trips}}},
        {"silence_timeout_s", board.silence_timeout_s},
        {"last_problem", stats.last_problem},
    };
    if (wires.line_noise) report["line_noise"] = line_noise_json(*wires.line_noise);
    if (attachment) report["attach"] = {{"waited_s", attachment->waited_s}, {"seen", attachment->seen}};
    return report;
}

}  // namespace rig::harness
