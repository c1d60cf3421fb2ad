#pragma once
// The processes and wires of one case run: its own DDS domain, the bench wires
// it asks for (ptys, serial ports, Modbus, the HID board) and the controller
// process started with the far ends of those wires. The session owns them and
// ends them in order (the controller, then the wires), whatever way the run ends.
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <functional>

#include "emulators/wire_faults.h"
#include "harness/spec/case_spec.h"
#include "harness/trace/trace_file.h"
#include "harness/session/in_process_controller.h"
#include "rig/host/child_process.h"
#include "rig/runtime/clock.h"
#include "rig/host/domain_lease.h"
#include "rig/wire/pty_pair.h"
#include "rig/wire/serial_port.h"
#include "rig/wire/wire_adapters.h"

namespace rig::harness {

// The controller's configuration as it is given to the controller
// (controller.yaml): the case's `controller:` section without the rig's own
// keys (command, plugin, in_process), "{}" when the case has none.
std::string controller_config_text(const CaseSpec& spec);

// The rig's ends of the bench wires a case asks for, and what the controller
// process must be told to use the far ends.
struct BenchWires {
    std::unique_ptr<PtyPair> gnss_pty;
    std::unique_ptr<SerialPort> gnss_device;
    SerialPort* gnss_port = nullptr;  // the rig writes NMEA here
    std::string gnss_far_end;         // what the controller opens
    // Seed 001's L4 laser line (`laser: serial`), like the GNSS's.
    std::unique_ptr<PtyPair> laser_pty;
    std::unique_ptr<SerialPort> laser_device;
    SerialPort* laser_port = nullptr;  // the rig writes the laser's lines here
    std::string laser_far_end;
    std::unique_ptr<PtyLink> modbus_link;
    std::unique_ptr<BoardIoWire> board_io;
    std::string board_io_far_end;     // what the controller opens: a tty path or ADDRESS:PORT
    std::vector<std::string> controller_args;
    std::string description = "dds";
    // The Modbus RTU line's noise when the case has some (harness/systems/breakpoint/gnss_wire_faults.h).
    std::shared_ptr<emulators::RtuLineNoise> line_noise;
};
// Opens what spec.wiring asks for; throws std::runtime_error naming the port.
// `open_hid`: how a HID board is opened (empty: hidapi, rig/wire/hid_board.h).
BenchWires open_bench_wires(const CaseSpec& spec, const HidTransportOpener& open_hid = {});

class CaseSession {
public:
    // Opens the wires and takes a DDS domain. Throws std::runtime_error naming
    // what could not be opened.
    CaseSession(const CaseSpec& spec, const std::filesystem::path& case_dir,
                std::optional<std::uint32_t> domain = std::nullopt, const HidTransportOpener& open_hid = {});
    // Writes the controller's configuration into case_dir and starts the
    // controller with the wires' far ends (unless the case wires an external
    // board). Called once the harness's participant exists on the domain, so
    // discovery sees the controller's from its first moment.
    // `environment`: set for the controller process over the rig's ("NAME=value");
    // `inputs`: arguments naming what the controller is given besides its
    // configuration (the case's system's, harness/systems/system.h).
    void start_controller(const CaseSpec& spec, const std::filesystem::path& controller_executable,
                          const std::filesystem::path& case_dir, const std::vector<std::string>& environment = {},
                          const std::vector<std::string>& inputs = {});
    // Software-in-the-loop: makes the controller from its plugin, to be stepped
    // by the lockstep master in this process. Returns the plugin's refusal (this
    // configuration runs as a process: start_controller then) or "" when made.
    // Throws std::runtime_error when the plugin cannot make it.
    std::string start_in_process_controller(const CaseSpec& spec, const std::filesystem::path& plugin,
                                            const std::filesystem::path& case_dir, DdsContext& harness_dds);
    InProcessController* in_process_controller() { return in_process_.get(); }
    // "process", "in_process" or "external": where the controller ran (results.json).
    std::string controller_mode() const;
    ~CaseSession();
    CaseSession(const CaseSession&) = delete;
    CaseSession& operator=(const CaseSession&) = delete;

    std::uint32_t domain_id() const { return lease_.domain_id(); }
    BenchWires& wires() { return wires_; }
    bool has_controller_process() const { return controller_.has_value(); }
    std::string controller_command_line() const;
    // How the controller process ended, if it has (the lockstep master's liveness check).
    std::optional<std::string> controller_gone();
    // Waits up to `grace` for it to end by itself, then stops it; how it ended.
    std::string stop_controller(std::chrono::milliseconds grace);
    // Runs the case (`run`: the time mode's runner) and ends the controller, and
    // says how the run ended for the trace: completed at `end_ns` when the
    // controller also ended cleanly; else the node that failed and why (with the
    // tail of the controller's log), or the rig's own failure, at `now_ns`.
    TraceOutcome run_to_outcome(const std::function<void()>& run, TimeNs end_ns, const TimeNs& now_ns);
    // The last lines of the controller's log, for error messages.
    std::string controller_log_tail(std::size_t max_lines = 6) const;
    // A bench wire whose far end does not take what the rig writes: the GNSS
    // (or laser) pty holding bytes nobody read for longer than `unread_for`.
    // Empty when fine.
    std::string wire_problem(std::chrono::milliseconds unread_for);

private:
    BenchWires wires_;
    DomainLease lease_;
    std::filesystem::path controller_log_;
    std::optional<ChildProcess> controller_;
    std::unique_ptr<InProcessController> in_process_;
    // A pty's watch: the unread byte count, and since when it has not gone down.
    struct UnreadWatch {
        std::size_t unread = 0;
        std::optional<WallStopwatch> since;
    };
    static std::string unread_problem(PtyPair* pty, const std::string& line, const std::string& far_end,
                                      const std::string& what, UnreadWatch& watch, std::chrono::milliseconds unread_for);
    UnreadWatch gnss_watch_;
    UnreadWatch laser_watch_;
};

}  // namespace rig::harness
