#pragma once
// The controller board's end of the Modbus bench wire: a Modbus TCP or RTU
// master (client) on libmodbus, speaking the register map of
// rig/wire/modbus_register_map.h to a ModbusSlave (or any slave serving that map).
// The reference controller's wired mode uses it in place of DDS topics; tests
// use it to drive a ModbusSlave the way a board would.
//
// Every failure is a ModbusMasterError naming the endpoint, the operation and
// what went wrong (the slave's exception, a timeout, a refused connection), and
// every call returns within the response timeout (plus the byte timeout per
// chunk of a response that is trickling in). Not thread-safe: one per thread.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "rig/runtime/io_image.h"
#include "rig/wire/modbus_protocol.h"
#include "rig/wire/modbus_register_map.h"

namespace rig::modbus {

struct TcpMasterOptions {
    TcpEndpoint slave;                // 127.0.0.1:1502 by default
    std::uint8_t unit_id = 1;
    bool allow_non_loopback = false;  // see TcpSlaveOptions::allow_non_loopback
};

struct RtuMasterOptions {
    SerialLineSettings line;
    std::uint8_t slave_id = 1;  // 1..247
};

struct MasterTimeouts {
    // From sending a request to the first byte of the response (TCP: also the connect timeout).
    std::chrono::milliseconds response_timeout{1000};
    // Between bytes of one response.
    std::chrono::milliseconds byte_timeout{500};
};

class ModbusMasterError : public std::runtime_error {
public:
    enum class Kind {
        connect_failed,      // no connection / serial port could not be opened
        timeout,             // no (complete) response in time
        exception_response,  // the slave answered with a Modbus exception
        bad_response,        // a response that does not fit the request (CRC, length, ids)
        io_error,            // the connection broke
        map_mismatch,        // the slave serves another register map version
    };
    ModbusMasterError(Kind kind, std::string endpoint, const std::string& message,
                      std::optional<std::uint8_t> exception_code = std::nullopt)
        : std::runtime_error(message), kind_(kind), endpoint_(std::move(endpoint)), exception_code_(exception_code) {}

    Kind kind() const { return kind_; }
    const std::string& endpoint() const { return endpoint_; }
    // The Modbus exception code, for exception_response.
    std::optional<std::uint8_t> exception_code() const { return exception_code_; }

private:
    Kind kind_;
    std::string endpoint_;
    std::optional<std::uint8_t> exception_code_;
};

class ModbusMaster {
public:
    // Connect at once; throws ModbusMasterError(connect_failed) naming the
    // endpoint, std::invalid_argument for bad options (a non-loopback address
    // without allow_non_loopback, bad serial settings).
    explicit ModbusMaster(const TcpMasterOptions& options, MasterTimeouts timeouts = {});
    explicit ModbusMaster(const RtuMasterOptions& options, MasterTimeouts timeouts = {});
    ~ModbusMaster();
    ModbusMaster(const ModbusMaster&) = delete;
    ModbusMaster& operator=(const ModbusMaster&) = delete;

    // "tcp 127.0.0.1:1502 unit 1" or "rtu /dev/ttyUSB0 115200 8N1 slave 1".
    const std::string& endpoint() const { return endpoint_; }

    // Input registers 0-6 in one request (so the 32-bit counters are one
    // snapshot) and discrete inputs 0-1. Throws map_mismatch when the map
    // version register is not kRegisterMapVersion.
    io::DeviceSignals read_device_signals();
    std::uint16_t read_map_version();
    // Coils 0-15 in one FC 15 (reserved coils written 0).
    void write_actuator_commands(const io::ActuatorCommands& commands);
    // Holding registers 0-2 in one FC 16.
    void write_indicators(const io::ControllerIndicators& indicators);
    // Read back what the slave holds (FC 01 / FC 03).
    io::ActuatorCommands read_actuator_commands();
    io::ControllerIndicators read_indicators();

private:
    void connect();
    [[noreturn]] void fail(const std::string& operation, int error);
    // RTU, after a bad or late response: waits for the line to fall quiet, then flushes.
    void drain_serial_line();
    template <typename Call>
    int transact(const std::string& operation, int expected, Call call);

    struct Context;  // owns libmodbus's modbus_t, kept out of this header
    std::unique_ptr<Context> context_;
    std::string endpoint_;
    MasterTimeouts timeouts_;
    bool connected_ = false;
};

}  // namespace rig::modbus
