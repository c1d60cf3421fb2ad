#pragma once
// The reference controller on real wires, as a board runs it (issue: plug in a
// real controller): NMEA from the G970II on a serial port, every other signal
// through the rig's Modbus register map (docs/modbus-register-map.md), with the
// board as the Modbus master. The firmware logic is the same class the DDS node
// uses (controller/spray_controller.h); only the wire differs.
//
// It is a rig::Node only so the real-time follower can start and stop it with
// the harness; it has no DDS endpoints of its own. Each step reads what the
// serial port holds, runs the firmware, writes the coils / holding registers
// that changed, and then polls the board inputs (one FC 04 + one FC 02) for the
// next step.
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "controller/controller_config.h"
#include "controller/spray_controller.h"
#include "rig/wire/modbus_master.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/node.h"
#include "rig/wire/serial_port.h"

namespace rig::controller {

struct WiredBoardOptions {
    std::string nmea_port;                       // e.g. /dev/ttyS1 (the G970II's RS232 line)
    SerialSettings nmea_line{};                  // 115200 8N1 unless told
    // Exactly one of these: Modbus RTU on a serial line, or Modbus TCP.
    std::optional<modbus::RtuMasterOptions> modbus_rtu;
    std::optional<modbus::TcpMasterOptions> modbus_tcp;
    std::chrono::milliseconds poll_period{10};   // board inputs read at 100 Hz, like the DDS devices
    int modbus_retries = 2;                      // a lost frame is retried before it counts as a failure
    // A board that answers nothing for this long is lost (the run ends); until
    // then an exchange that failed its retries is a lost poll. 1 s: the rig's
    // default comms-loss fail-safe (board.failsafe_timeout_s), by which the
    // outputs are already de-energised.
    std::chrono::milliseconds modbus_lost_after{1000};
};

// Complete lines taken from the front of what the NMEA UART received (the
// rest, a line still arriving, stays in `buffer`). A '$' or '!' inside a line
// starts a new one: the fragment before it is a line of its own.
std::vector<std::string> take_nmea_lines(std::string& buffer);

// The Modbus RTU master's waits (the reasons are in the .cpp).
modbus::MasterTimeouts rtu_master_timeouts();

class WiredBoardController final : public Node {
public:
    WiredBoardController(std::string node_name, ControllerConfig config, const std::filesystem::path& state_dir,
                         WiredBoardOptions options);
    const std::string& name() const override { return name_; }
    // Opens the serial port and connects the Modbus master; throws naming the wire.
    void configure(DdsContext& dds) override;
    void activate(TimeNs now_ns) override;
    // Throws (a fatal error naming the wire) when the serial port closed or the
    // Modbus slave stopped answering.
    TimeNs step(TimeNs now_ns) override;
    void shutdown() override;

    std::uint64_t modbus_retries_used() const { return retries_used_; }

private:
    void read_nmea(TimeNs now_ns);
    void poll_board(TimeNs now_ns);
    void write_outputs(TimeNs now_ns);
    template <class Call>
    auto with_retries(Call call);

    std::string name_;
    WiredBoardOptions options_;
    SprayController firmware_;
    std::unique_ptr<SerialPort> nmea_port_;
    std::unique_ptr<modbus::ModbusMaster> board_;
    std::string nmea_buffer_;
    std::optional<io::DeviceSignals> last_inputs_;
    std::optional<io::ActuatorCommands> written_actuators_;
    // When the coils were last written, and the retry count then: they are
    // written again after a retry and at least every kOutputRefreshNs, since an
    // I/O module whose comms-loss watchdog tripped (the rig's: board.failsafe)
    // keeps its outputs de-energised until the master writes them again.
    TimeNs actuators_written_ns_ = 0;
    std::uint64_t retries_at_write_ = 0;
    std::optional<io::ControllerIndicators> written_indicators_;
    TimeNs poll_period_ns_;
    TimeNs next_poll_ns_ = 0;
    std::uint64_t retries_used_ = 0;
    // What the retries were for, and the longest wall time one failed attempt
    // held the loop (a timeout waits for the master's timeouts), for the
    // summary at shutdown.
    std::uint64_t timeouts_retried_ = 0;
    std::uint64_t bad_responses_retried_ = 0;
    TimeNs longest_failed_attempt_ns_ = 0;
    std::uint64_t exchanges_lost_ = 0;   // steps whose Modbus exchange failed after its retries
    TimeNs last_exchange_ns_ = 0;        // the last step whose exchanges all succeeded
    RealtimeClock attempt_clock_;
};

}  // namespace rig::controller
