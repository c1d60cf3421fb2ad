#pragma once
// The rig's end of the Modbus bench wire: a Modbus TCP or RTU slave (server)
// serving the register map (rig/wire/modbus_register_map.h) to a real controller
// board, the master. The rig sets the board's inputs (set_device_signals) and
// learns what the board drives (actuator_commands, indicators, a callback and
// a write counter).
//
// Robustness is the point of this class: whatever a master or the line sends,
// the slave answers with the right Modbus exception or drops the frame, counts
// it, and keeps serving. Nothing a peer does can crash it, block it, or block
// another peer: one server thread polls every socket non-blocking, each TCP
// connection has its own receive buffer, and stop() returns in bounded time.
//
// Why the slave frames requests itself instead of libmodbus's modbus_receive()
// + modbus_reply() (libmodbus 3.1.6; the master side, rig/wire/modbus_master.h, does
// use libmodbus): modbus_receive() reads one connection at a time and works
// out a frame's length from its function code, ignoring the MBAP length
// field, so a client that lies about the length desynchronises the stream,
// and one that stalls mid-frame holds the server for a byte timeout. In RTU
// it treats the frame after a request for another slave as that slave's
// reply and skips it, which loses the next real request on a point-to-point
// bench line. Framing is the small part of Modbus; doing it here lets every
// malformed case be handled and counted (rig/wire/modbus_protocol.h).
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "rig/runtime/io_image.h"
#include "rig/wire/modbus_protocol.h"

namespace rig::modbus {


struct TcpSlaveOptions {
    // Loopback only unless allow_non_loopback: these machines never talk to
    // anything but 127.0.0.1 (docs/design.md). A bench with a board on Ethernet
    // sets it explicitly.
    std::string bind_address = "127.0.0.1";
    std::uint16_t port = kDefaultBenchTcpPort;  // 0 = any free port; ModbusSlave::tcp_port() tells which
    bool allow_non_loopback = false;
    // One more connection than this evicts the least recently active one (Modbus
    // TCP implementation guide), so a board that reconnects after a reset is
    // never locked out by its own dead connection.
    int max_connections = 8;
    // A frame that has started must be complete within this, else the
    // connection is closed (the stream cannot be trusted any more).
    std::chrono::milliseconds partial_frame_timeout{3000};
    // Any TCP unit id is served (the slave is the end device, not a gateway).
    CommsFailsafe failsafe;
};

struct RtuSlaveOptions {
    SerialLineSettings line;
    std::uint8_t slave_id = 1;  // 1..247
    // Silence that ends a frame whose length the function code does not tell,
    // or abandons an incomplete one. Generous: USB-serial adapters deliver a
    // frame in chunks up to ~16 ms apart. Frames of FC 01-06/15/16 complete by
    // length and never wait for it.
    std::chrono::milliseconds frame_end_silence{50};
    // A response the line does not take within this is dropped (and counted).
    std::chrono::milliseconds write_timeout{1000};
    CommsFailsafe failsafe;
};

// What the master wrote: reported after every write request carried out
// (FC 05, 06, 15, 16), even one that changed nothing.
struct MasterWrite {
    io::ActuatorCommands commands;        // coils after the write
    io::ControllerIndicators indicators;  // holding registers after the write
    bool commands_changed = false;
    bool indicators_changed = false;
    std::uint64_t sequence = 0;           // 1 for the first write; == master_write_count() then
};

struct ModbusSlaveCallbacks {
    // From the server thread, in order, outside any lock: may call the
    // ModbusSlave getters, must not call stop(), should be quick (the slave
    // serves nobody while it runs). An exception it throws is caught and counted.
    std::function<void(const MasterWrite&)> on_master_write;
    // From the server thread: a request refused with an exception or a frame
    // dropped, one line saying why ("tcp 127.0.0.1:40512: FC 05: coil value 0x1234 ...").
    std::function<void(const std::string&)> on_problem;
};

struct ModbusSlaveStatistics {
    // Valid requests addressed to this slave (or broadcast), answered or
    // refused with an exception: what shows the master is alive.
    std::uint64_t valid_requests = 0;
    // Requests served.
    std::uint64_t requests_answered = 0;       // normal response made (responses_not_sent: lost on the way)
    std::uint64_t broadcast_requests = 0;      // RTU address 0: carried out, never answered
    std::uint64_t master_writes = 0;           // writes to coils / holding registers carried out
    std::uint64_t illegal_function = 0;        // exception 01 sent
    std::uint64_t illegal_data_address = 0;    // exception 02 sent
    std::uint64_t illegal_data_value = 0;      // exception 03 sent
    // Frames dropped without an answer.
    std::uint64_t malformed_frames = 0;        // TCP: bad MBAP header (connection closed); RTU: truncated, oversized
    std::uint64_t bad_crc_frames = 0;          // RTU
    std::uint64_t other_slave_frames = 0;      // RTU: for another slave id
    std::uint64_t responses_not_sent = 0;      // the peer or line did not take the response
    // TCP connections.
    std::uint64_t connections_accepted = 0;
    std::uint64_t connections_closed_by_peer = 0;
    std::uint64_t connections_closed_mid_frame = 0;  // peer went away with part of a frame sent
    std::uint64_t connections_timed_out = 0;         // a started frame not completed in time
    std::uint64_t connections_evicted = 0;           // least recently active, to admit a new one
    std::uint64_t callback_errors = 0;               // exceptions thrown by a callback
    std::uint64_t failsafe_trips = 0;                // comms-loss watchdog expiries (CommsFailsafe)
    std::string last_problem;                        // the latest on_problem line
};

class ModbusSlave {
public:
    // Open the port and start serving at once. Throw std::invalid_argument for
    // bad options and std::runtime_error when the port cannot be had, naming
    // what and where: "cannot listen for Modbus TCP on 127.0.0.1:1502: Address
    // already in use", "cannot open serial device /dev/ttyUSB0: No such file or directory".
    explicit ModbusSlave(const TcpSlaveOptions& options, ModbusSlaveCallbacks callbacks = {});
    explicit ModbusSlave(const RtuSlaveOptions& options, ModbusSlaveCallbacks callbacks = {});
    ~ModbusSlave();  // stop()
    ModbusSlave(const ModbusSlave&) = delete;
    ModbusSlave& operator=(const ModbusSlave&) = delete;

    // "tcp 127.0.0.1:1502" or "rtu /dev/ttyUSB0 115200 8N1 slave 1".
    const std::string& endpoint() const;
    // The TCP port actually bound (the chosen one for port 0); 0 for RTU.
    std::uint16_t tcp_port() const;

    // Board inputs the master reads. Throws std::invalid_argument (ADC over
    // full scale) without changing what is served.
    void set_device_signals(const io::DeviceSignals& signals);
    io::DeviceSignals device_signals() const;
    // Board outputs as the master last wrote them (all off / 0 before any write).
    io::ActuatorCommands actuator_commands() const;
    io::ControllerIndicators indicators() const;

    // Writes carried out so far. To wait for the next one:
    //   auto seen = slave.master_write_count(); ...; slave.wait_for_master_write(seen, 1s);
    std::uint64_t master_write_count() const;
    // Blocks until master_write_count() > seen or the timeout; returns the count.
    std::uint64_t wait_for_master_write(std::uint64_t seen, std::chrono::milliseconds timeout) const;

    ModbusSlaveStatistics statistics() const;
    // How long since the last valid request addressed to this slave (statistics()
    // valid_requests), on the slave's monotonic clock; nullopt before the first.
    std::optional<std::chrono::nanoseconds> since_last_request() const;
    // Whether the comms-loss watchdog has tripped and no valid request came since.
    bool failsafe_active() const;
    // Set when the server thread ended on an unexpected error (it then serves
    // no more); the message says what. Never set in normal operation.
    std::optional<std::string> server_failure() const;

    // SCHED_FIFO at `priority` for the serving thread (real-time runs: the
    // master's answers must not wait for the machine's other work). "" when
    // granted, else why not.
    std::string raise_to_realtime(int priority);

    // Stops serving and closes the port; bounded time, idempotent. Must not be
    // called from a callback.
    void stop();

private:
    class Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace rig::modbus
