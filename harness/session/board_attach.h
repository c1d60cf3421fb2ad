#pragma once
// A board on real wires (`wiring: { controller: external }`), before and during
// the case (docs/modbus-register-map.md "External boards"):
//
//   1. announce_attach(): one line on stdout saying where the board must attach,
//      and the same as attach.json in the case's output directory, before case
//      time starts;
//   2. wait_for_board(): until the board has opened the NMEA (and laser) pty and sent its
//      first valid Modbus request, bounded by board.attach_timeout_s, else
//      NodeFailure(board_not_attached);
//   3. BoardSilenceWatch: during the case, a Modbus master quiet for longer than
//      board.silence_timeout_s fails the case at once (board_silent);
//   4. board_io_report(): the Modbus slave's answered, refused and dropped
//      frames per kind and the fail-safe trips, for results.json.
//
// What the rig can observe of a board: on a pty, that a process other than the
// rig holds the slave side open (/proc/PID/fd; the rig keeps its own end open,
// so the pty's hang-up state tells nothing); on any Modbus wire, each valid
// request addressed to the rig. That the board reads the NMEA line shows only
// once sentences flow, i.e. after time starts: a line whose bytes wait unread
// fails the case as wire_unread (harness/session/case_session.h wire_problem). Of a
// real serial device's TX line the rig sees nothing.
#include <chrono>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/spec/board_spec.h"
#include "harness/session/case_session.h"
#include "rig/runtime/clock.h"

namespace rig::harness {

// One wire end the board attaches to.
struct AttachPort {
    std::string role;  // gnss_nmea, modbus_rtu, modbus_tcp, hid
    std::string path;  // /dev/pts/5, /dev/ttyUSB0, 127.0.0.1:40123, the HID device
    std::string settings;  // "115200 8N1", "slave 1 115200 8N1"
    std::string attached_when;  // what the rig waits for on it, or "not observable"
};
std::vector<AttachPort> attach_ports(const WiringSpec& wiring, const BenchWires& wires);
// "attach: gnss_nmea=/dev/pts/5 modbus_rtu=/dev/pts/7 (case NAME; waiting up to 60 s)"
std::string attach_line(const std::vector<AttachPort>& ports, const std::string& run_name, const BoardSpec& board);
nlohmann::json attach_json(const std::vector<AttachPort>& ports, const std::string& run_name, const BoardSpec& board);

// Prints attach_line() on `out` (flushed) and writes attach.json into case_dir,
// with `system`'s keys besides the ports (what the case's system tells a
// board: seed 000's register scalings, seed 001's DDS domain and job file).
void announce_attach(const WiringSpec& wiring, const BoardSpec& board, const BenchWires& wires, const std::string& run_name,
                     const std::filesystem::path& case_dir, std::ostream& out, const nlohmann::json& system);

// Other processes holding `path` open, found in /proc/*/fd (this process left
// out): their pids. Empty when none, or when /proc cannot be read.
std::vector<int> processes_holding(const std::filesystem::path& path);

struct BoardAttachment {
    double waited_s = 0.0;
    std::vector<std::string> seen;  // "gnss_nmea opened by pid 1234 after 0.41 s", ...
};
// Blocks until every observable wire end is attached; calls `watchdog` between
// looks (it may throw, e.g. on SIGINT). Throws NodeFailure(board_not_attached)
// naming each port still waited for after board.attach_timeout_s.
BoardAttachment wait_for_board(const BoardSpec& board, BenchWires& wires, const std::function<void()>& watchdog);

// The rig's Modbus slave on this case's wires, if it has one.
modbus::ModbusSlave* modbus_slave_of(BenchWires& wires);

// During the case: throws NodeFailure(board_silent) once the Modbus master has
// been quiet for longer than board.silence_timeout_s (counted from the case
// start until its first request). Does nothing on cases without a Modbus wire.
class BoardSilenceWatch {
public:
    BoardSilenceWatch(const BoardSpec& board, BenchWires& wires);
    // `case_now_ns`: the case clock, for the message.
    void check(TimeNs case_now_ns);

private:
    modbus::ModbusSlave* slave_;
    std::chrono::nanoseconds timeout_;
    std::optional<WallStopwatch> since_start_;
};

// The slave's frame counts per kind, the fail-safe and the attachment: results.json `realtime.board_io`.
nlohmann::json board_io_report(const BoardSpec& board, BenchWires& wires, const std::optional<BoardAttachment>& attachment);

}  // namespace rig::harness
