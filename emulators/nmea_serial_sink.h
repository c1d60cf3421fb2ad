#pragma once
// The G970II's RS232 output on a real wire: puts NMEA sentences (already framed
// "$...*HH\r\n" by rig/nmea/nmea_encoder.h) on a SerialPort, byte for byte what
// a receiver transmits, and says how long each one occupies the wire at the
// port's baud and frame format (10 bits per byte for 8N1), so the real-time loop
// that calls it can account for it (a 90-byte GGA at 9600 baud is 94 ms: at
// 5 Hz, GGA + RMC nearly fill the 200 ms epoch).
//
// Like every emulator it neither reads a clock nor sleeps: it writes and
// returns. Pacing (when to write the next epoch) is the caller's business; the
// caller is a real-time loop in rig/ that owns a RealtimeClock.
#include <chrono>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "rig/runtime/clock.h"
#include "rig/wire/serial_port.h"

namespace rig::emulators {

class NmeaSerialSink {
public:
    // `write_timeout` bounds one write when the port's output buffer is full
    // (nobody reading a pty, flow stopped): it fails with SerialError::timeout
    // rather than blocking the caller's loop.
    explicit NmeaSerialSink(SerialPort& port,
                            std::chrono::milliseconds write_timeout = std::chrono::milliseconds(1000));

    // Writes one sentence and returns the time it takes on the wire. The
    // sentence must be framed as a receiver frames it: '$' or '!', body, '*',
    // two hex digits, "\r\n", and no other CR or LF. A malformed one is refused
    // with std::invalid_argument saying what is wrong (nothing is written), so
    // an encoder bug cannot silently merge two sentences on the wire. The
    // checksum value itself is not checked: a case may inject wrong ones.
    // Port failures are rig::SerialError (timeout, closed...).
    TimeNs write_sentence(std::string_view sentence);

    // Several sentences back to back (one epoch: GGA then RMC); all are checked
    // before any is written. Returns their total wire time.
    TimeNs write_epoch(std::span<const std::string> sentences);

    // Arbitrary bytes, unchecked: deliberate wire faults (a truncated sentence,
    // line noise). Returns their wire time.
    TimeNs write_raw(std::string_view bytes);

    // Wire time of `bytes` at the port's settings.
    TimeNs wire_time_ns(std::size_t bytes) const;

    std::uint64_t sentences_written() const { return sentences_written_; }
    std::uint64_t bytes_written() const { return bytes_written_; }

    // Why `sentence` is not a framed NMEA sentence, or empty when it is.
    static std::string framing_error(std::string_view sentence);

private:
    SerialPort& port_;
    std::chrono::milliseconds write_timeout_;
    std::uint64_t sentences_written_ = 0;
    std::uint64_t bytes_written_ = 0;
};

}  // namespace rig::emulators
