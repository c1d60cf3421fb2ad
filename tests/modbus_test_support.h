#pragma once
// Helpers for the Modbus tests: a pty pair through socat (an RTU line without
// hardware), a raw TCP client for hostile frames, running a command (mbpoll)
// with a time bound, and waiting for a condition without tight timing.
// Everything talks to 127.0.0.1 only.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rig/host/child_process.h"

namespace rig::modbus::testing {

using Bytes = std::vector<std::uint8_t>;

// A fresh, empty directory under the test temp dir.
std::filesystem::path fresh_dir(const std::string& name);

// Polls `condition` every few ms until it holds or `timeout` passes (generous
// bounds: these tests run on a loaded 2-core machine). Returns whether it held.
bool eventually(const std::function<bool()>& condition,
                std::chrono::milliseconds timeout = std::chrono::milliseconds(10000));

struct CommandResult {
    int exit_code = -1;
    std::string output;  // stdout and stderr
};
// Runs `command` through the shell under `timeout` (so it cannot hang a test).
CommandResult run_command(const std::string& command, int timeout_s = 60);
// Fails the calling test (ADD_FAILURE) when `tool` is not on PATH.
bool require_tool(const std::string& tool);

// Two pseudo-terminals joined by socat: what is written to one comes out of
// the other, like the two ends of a null-modem cable.
class PtyPair {
public:
    explicit PtyPair(const std::string& name);  // throws if socat does not come up
    ~PtyPair();
    PtyPair(const PtyPair&) = delete;
    PtyPair& operator=(const PtyPair&) = delete;
    std::string slave_end() const { return (dir_ / "A").string(); }   // the rig's ModbusSlave opens this
    std::string master_end() const { return (dir_ / "B").string(); }  // the master (mbpoll, ModbusMaster, raw) opens this

private:
    std::filesystem::path dir_;
    std::unique_ptr<ChildProcess> socat_;
};

// A serial end opened raw, for writing hand-made RTU frames.
class RawSerial {
public:
    explicit RawSerial(const std::string& path);
    ~RawSerial();
    RawSerial(const RawSerial&) = delete;
    RawSerial& operator=(const RawSerial&) = delete;
    void write(const Bytes& bytes);
    // Exactly `count` bytes, or what arrived before the timeout.
    Bytes read(std::size_t count, std::chrono::milliseconds timeout);
    // Whatever is waiting now (after a short look), to show nothing unexpected came.
    Bytes read_pending(std::chrono::milliseconds look = std::chrono::milliseconds(100));

private:
    int fd_ = -1;
};

// A TCP client on 127.0.0.1 that sends whatever bytes it is given.
class RawTcpClient {
public:
    explicit RawTcpClient(std::uint16_t port);
    ~RawTcpClient();
    RawTcpClient(const RawTcpClient&) = delete;
    RawTcpClient& operator=(const RawTcpClient&) = delete;
    void send(const Bytes& bytes);
    // Exactly `count` bytes, or what came before the peer closed / the timeout.
    Bytes receive(std::size_t count, std::chrono::milliseconds timeout);
    // True when the slave closed the connection within `timeout` (bytes before the close are discarded).
    bool closed_by_peer(std::chrono::milliseconds timeout);
    void close();

private:
    int fd_ = -1;
};

// A listening socket on 127.0.0.1 that nobody accepts from or answers: the
// handshake completes (the kernel's backlog) and then silence.
class SilentTcpListener {
public:
    SilentTcpListener();
    ~SilentTcpListener();
    std::uint16_t port() const { return port_; }

private:
    int fd_ = -1;
    std::uint16_t port_ = 0;
};

// A port on 127.0.0.1 nobody listens on (bound, then closed).
std::uint16_t unused_tcp_port();

// MBAP + PDU with the given header fields.
Bytes tcp_frame(std::uint16_t transaction_id, const Bytes& pdu, std::uint8_t unit_id = 1,
                std::optional<std::uint16_t> length_field = std::nullopt, std::uint16_t protocol_id = 0);

}  // namespace rig::modbus::testing
