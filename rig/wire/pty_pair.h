#pragma once
// Pseudo-terminals as bench wiring, for programs that only speak to serial ports
// (gpsd, a terminal, libmodbus RTU, a controller build that opens /dev/ttyS*).
//
// PtyPair: one pty. The rig holds the master side (a SerialPort it writes NMEA to
// or reads from) and another program opens the slave path, e.g. /dev/pts/7, or
// a symlink to it at a path of the caller's choosing (/tmp/gnss0).
//
// PtyLink: two ptys whose master sides a thread forwards to each other, so the
// two slave paths behave like the two ends of a null-modem cable (what
// `socat pty,raw,echo=0 pty,raw,echo=0` gives): for Modbus RTU tests and for a
// person at the bench.
//
// Both slaves are configured raw (no echo, no line editing, no CR/LF
// translation) before their paths are handed out. The rig keeps each slave open
// itself, without reading it: on Linux a pty master reports a hang-up (EIO)
// whenever no program has the slave open, and the slave's settings would be
// reset when the last program closes it. Holding it keeps the master writable
// while programs come and go (gpsd reopening its device, a person restarting a
// terminal); bytes written while nobody reads stay queued for the next reader,
// and once the queue is full the writer sees backpressure (a write timeout), not
// loss. A pty moves bytes at memory speed and always carries 8 data bits
// without parity: baud and frame in the settings are nominal (programs can read
// the baud back; NmeaSerialSink accounts wire time with them).
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "rig/wire/serial_port.h"

namespace rig {

struct PtyOptions {
    SerialSettings settings;          // applied to the slave; nominal on a pty
    std::filesystem::path link_path;  // when not empty, a symlink to the slave is made here
};

class PtyPair {
public:
    // Throws std::runtime_error naming the step that failed (posix_openpt,
    // grantpt, ...) or the symlink path and why it cannot be made (the path
    // exists and is not a symlink, its directory does not exist...). An existing
    // symlink at link_path is replaced (a leftover of an earlier run).
    explicit PtyPair(const PtyOptions& options = {});
    ~PtyPair();  // removes the symlink if it still points at this pty
    PtyPair(const PtyPair&) = delete;
    PtyPair& operator=(const PtyPair&) = delete;

    const std::string& slave_path() const { return slave_path_; }
    const std::filesystem::path& link_path() const { return link_path_; }
    // The path to give to another program: the symlink when there is one.
    std::string public_path() const { return link_path_.empty() ? slave_path_ : link_path_.string(); }
    // The rig's side. Reads report SerialError::closed only if the held slave
    // was closed, i.e. never while this object lives.
    SerialPort& master() { return *master_; }
    // Bytes written on the master that no program has read from the slave yet
    // (FIONREAD on the held slave: every program on the slave shares its input
    // queue). A count that never goes down means nobody reads the line.
    std::size_t unread_bytes() const;

private:
    std::string slave_path_;
    std::filesystem::path link_path_;
    std::optional<SerialPort> master_;
    std::optional<SerialPort> held_slave_;
};

class PtyLink {
public:
    // Creates both ptys and starts forwarding. Throws like PtyPair.
    PtyLink(const PtyOptions& a = {}, const PtyOptions& b = {});
    ~PtyLink();  // stop(), then both ptys are closed: programs on the slaves see a hang-up
    PtyLink(const PtyLink&) = delete;
    PtyLink& operator=(const PtyLink&) = delete;

    const PtyPair& a() const { return a_; }
    const PtyPair& b() const { return b_; }
    const std::string& slave_path_a() const { return a_.slave_path(); }
    const std::string& slave_path_b() const { return b_.slave_path(); }

    // SCHED_FIFO at `priority` for the forwarding thread (every byte crosses
    // it). "" when granted, else why not.
    std::string raise_to_realtime(int priority);
    // Stops the forwarding thread (it wakes at once; bounded) and joins it.
    // Bytes still inside the rig are dropped, as on a cable pulled mid-byte.
    void stop();
    // Why forwarding stopped by itself, if it did (it should not while both
    // slaves are held open).
    std::optional<std::string> error() const;
    std::uint64_t bytes_a_to_b() const { return bytes_a_to_b_.load(); }
    std::uint64_t bytes_b_to_a() const { return bytes_b_to_a_.load(); }

private:
    void forward();
    PtyPair a_;
    PtyPair b_;
    int wake_fd_ = -1;  // eventfd: stop() writes it, the thread polls it
    std::atomic<std::uint64_t> bytes_a_to_b_{0};
    std::atomic<std::uint64_t> bytes_b_to_a_{0};
    mutable std::mutex error_mutex_;
    std::optional<std::string> error_;
    std::thread forwarder_;
};

}  // namespace rig
