#pragma once
// A termios serial port: the RS232 wire between the rig and a controller board
// (the G970II's NMEA stream, Modbus RTU), or one side of a pseudo-terminal.
//
// The descriptor is non-blocking underneath; every call that waits takes a
// timeout and polls, so no call can hang. Errors are SerialError, whose text
// names the port and the cause ("serial port /dev/ttyUSB0: no such device").
//
// The port is raw: no echo, no line editing, no CR/LF translation, no software
// flow control, no modem-control lines (CLOCAL): bytes go on the wire exactly as
// written and come back exactly as received. On a pseudo-terminal the baud and
// frame are nominal: Linux ptys move 8-bit bytes at memory speed whatever is set.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "rig/runtime/clock.h"

namespace rig {

enum class Parity { none, even, odd };

struct SerialSettings {
    int baud = 115200;
    int data_bits = 8;  // 5..8
    Parity parity = Parity::none;
    int stop_bits = 1;  // 1 or 2
};

// The baud rates a port can be set to (the POSIX/Linux B-constants), ascending.
std::span<const int> supported_bauds();

// "115200 8N1".
std::string describe(const SerialSettings& settings);

// Parses a frame format such as "8N1", "7E1", "8O2" into data bits, parity and
// stop bits of `settings`. Throws std::invalid_argument naming the text.
void apply_frame_format(std::string_view frame_format, SerialSettings& settings);

// Throws std::invalid_argument naming the bad value (baud not supported, data
// bits outside 5..8, stop bits not 1 or 2).
void validate(const SerialSettings& settings);

// Bits one character takes on the wire: start bit, data bits, parity bit, stop
// bits. 8N1 -> 10.
int bits_per_character(const SerialSettings& settings);

// Time `bytes` take on the wire at the settings' baud, back to back, rounded to
// the nearest ns. 82 bytes at 9600 8N1 -> 85'416'667 ns.
TimeNs wire_time_ns(std::size_t bytes, const SerialSettings& settings);

class SerialError : public std::runtime_error {
public:
    enum class Kind {
        not_found,          // no such file, or no device behind the node
        permission_denied,  // the user may not open it (group dialout?)
        not_a_tty,          // a file or device that is not a terminal
        unsupported,        // the settings are invalid or the driver refused them
        closed,             // the other side hung up (pty peer closed, USB adapter unplugged)
        timeout,            // a write could not finish within its timeout
        io,                 // anything else the kernel reported
    };
    SerialError(Kind kind, const std::string& port, const std::string& cause)
        : std::runtime_error("serial port " + port + ": " + cause), kind_(kind) {}
    Kind kind() const { return kind_; }

private:
    Kind kind_;
};

class SerialPort {
public:
    // Opens `path` (O_NOCTTY, non-blocking) and configures it raw with `settings`.
    // Throws SerialError: not_found, permission_denied, not_a_tty, unsupported, io.
    explicit SerialPort(const std::string& path, const SerialSettings& settings = {});

    // Takes ownership of an open terminal descriptor (e.g. a pty master) and
    // configures it raw with `settings`; `name` is what errors call it.
    static SerialPort adopt(int fd, std::string name, const SerialSettings& settings = {});

    ~SerialPort();
    SerialPort(SerialPort&& other) noexcept;
    SerialPort& operator=(SerialPort&& other) noexcept;
    SerialPort(const SerialPort&) = delete;
    SerialPort& operator=(const SerialPort&) = delete;

    const std::string& path() const { return path_; }
    const SerialSettings& settings() const { return settings_; }
    bool is_open() const { return fd_ >= 0; }
    int native_handle() const { return fd_; }
    void close();

    // Writes every byte or throws: SerialError::timeout (saying how many bytes
    // went out) when the kernel's output buffer stays full for `timeout`, closed
    // when the other side hung up. Returns when the bytes are in the kernel's
    // buffer, not when they have left the wire (see wire_time_ns).
    void write_all(std::string_view bytes, std::chrono::milliseconds timeout);
    void write_all(std::span<const std::uint8_t> bytes, std::chrono::milliseconds timeout);

    // What has arrived, at most `max_bytes`, waiting up to `timeout` for the
    // first byte; empty when nothing arrived. Throws SerialError::closed when the
    // other side hung up and everything it sent has been read.
    std::string read_some(std::chrono::milliseconds timeout, std::size_t max_bytes = 4096);

    // One line without its "\n" (and without a "\r" just before it), waiting up
    // to `timeout` for it to be complete; nullopt when it is not. Bytes of an
    // incomplete line stay buffered for the next call, so nothing is lost. A line
    // longer than kMaxLineBytes is returned in kMaxLineBytes pieces (bounded
    // memory on a stream that never sends "\n"). At hang-up, a last incomplete
    // line is returned before SerialError::closed is thrown.
    std::optional<std::string> read_line(std::chrono::milliseconds timeout);
    static constexpr std::size_t kMaxLineBytes = 4096;

private:
    SerialPort(int fd, std::string name, const SerialSettings& settings);
    void configure(const SerialSettings& settings);
    // Reads what is available into pending_, waiting up to `timeout_ms` for it.
    // Returns false on timeout; sets hung_up_ when the peer closed.
    bool fill_pending(std::int64_t timeout_ms);
    [[noreturn]] void throw_errno(const std::string& what, int error) const;

    int fd_ = -1;
    std::string path_;
    SerialSettings settings_;
    std::string pending_;  // received, not yet handed out
    bool hung_up_ = false;
};

}  // namespace rig
