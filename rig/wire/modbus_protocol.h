#pragma once
// The Modbus protocol as pure functions, no I/O: serving one request PDU
// against the register map (rig/wire/modbus_register_map.h), Modbus TCP (MBAP) and
// RTU framing, and the wire settings master and slave share. ModbusSlave
// (rig/wire/modbus_slave.h) puts sockets and a serial port around it; keeping it
// pure lets the tests throw every hostile request at it without a socket.
//
// Facts from the Modbus Application Protocol Specification V1.1b3 and the
// Modbus over Serial Line guide V1.02: function codes, quantity limits, the
// order of checks (function, quantity/structure -> 03, address -> 02), the
// MBAP header, the RTU CRC and the 3.5-character inter-frame silence.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rig/runtime/clock.h"
#include "rig/wire/modbus_register_map.h"

namespace rig::modbus {

// ---------------------------------------------------------------- wire settings

inline constexpr std::uint16_t kDefaultBenchTcpPort = 1502;  // 502 needs root

enum class Parity { none, even, odd };
// 'N'/'E'/'O' (either case) or none/even/odd. Throws std::invalid_argument.
Parity parse_parity(std::string_view text);
char parity_letter(Parity parity);  // 'N', 'E', 'O'

struct SerialLineSettings {
    std::string device;          // e.g. /dev/ttyUSB0
    int baud = 115200;           // a standard rate 1200..921600
    Parity parity = Parity::none;
    int data_bits = 8;           // 7 or 8 (RTU proper is 8)
    int stop_bits = 1;           // 1 or 2
};
// Empty string = valid; otherwise what is wrong, naming the field and value.
std::string serial_settings_problem(const SerialLineSettings& line);
// "/dev/ttyUSB0 115200 8N1"
std::string describe(const SerialLineSettings& line);
// Modbus over Serial Line 2.5.1.1: 3.5 character times of silence end a frame
// (11 bits per character); above 19200 baud a fixed 1.75 ms.
TimeNs rtu_inter_frame_gap_ns(int baud);

struct TcpEndpoint {
    std::string address = "127.0.0.1";  // IPv4 dotted quad
    std::uint16_t port = kDefaultBenchTcpPort;
};
// "127.0.0.1:1502" -> endpoint. Throws std::invalid_argument naming the text.
TcpEndpoint parse_tcp_endpoint(std::string_view text);
// True for IPv4 literals in 127.0.0.0/8 (the only destinations these machines use).
bool is_loopback_ipv4(std::string_view address);

// The comms-loss watchdog of the rig's board I/O, as a real Modbus I/O module
// has one: `timeout` after the last valid request addressed to this slave, the
// outputs (coils) go to `mode`. A later valid request re-arms it; the coils then
// stay as the fail-safe left them until the master writes them again (as on a
// module whose watchdog tripped: the master must restore its outputs).
enum class FailsafeMode {
    safe,  // every coil 0, i.e. de-energised: ball-valve motor stopped, unloading valve and sections closed
    hold,  // coils keep their last written state (the trip is only counted)
};
struct CommsFailsafe {
    std::chrono::milliseconds timeout{0};  // 0 = no watchdog (the `rig modbus serve` default)
    FailsafeMode mode = FailsafeMode::safe;
};
std::string_view to_string(FailsafeMode mode);

// ---------------------------------------------------------------- application protocol (PDU)

enum class FunctionCode : std::uint8_t {
    read_coils = 0x01,
    read_discrete_inputs = 0x02,
    read_holding_registers = 0x03,
    read_input_registers = 0x04,
    write_single_coil = 0x05,
    write_single_register = 0x06,
    write_multiple_coils = 0x0F,
    write_multiple_registers = 0x10,
};

enum class ExceptionCode : std::uint8_t {
    illegal_function = 0x01,
    illegal_data_address = 0x02,
    illegal_data_value = 0x03,
    server_device_failure = 0x04,
};
// "ILLEGAL DATA ADDRESS" etc.; unknown codes as "exception 0x0B".
std::string exception_name(std::uint8_t code);

// Quantity limits per request (spec 6.1-6.12).
inline constexpr std::uint16_t kMaxReadBits = 2000;
inline constexpr std::uint16_t kMaxReadRegisters = 125;
inline constexpr std::uint16_t kMaxWriteBits = 1968;
inline constexpr std::uint16_t kMaxWriteRegisters = 123;
inline constexpr std::size_t kMaxPduSize = 253;
inline constexpr std::uint16_t kCoilOn = 0xFF00;
inline constexpr std::uint16_t kCoilOff = 0x0000;

struct ServedRequest {
    // Function code first. An exception response is {function | 0x80, code}.
    // Empty only for an empty request (nothing to answer to).
    std::vector<std::uint8_t> response_pdu;
    std::optional<ExceptionCode> exception;
    // Why, for logs: "quantity 0 outside 1..125" (empty when answered normally).
    std::string problem;
    // A write to coils or holding registers was carried out (values may be unchanged).
    bool wrote_outputs = false;
};

// Serves one request PDU (function code + data) against `image`. Supports FC
// 01, 02, 03, 04, 05, 06, 15, 16; everything else is ILLEGAL FUNCTION. A write
// is checked completely before anything is stored: a refused request changes
// nothing. Never throws for any input.
ServedRequest serve_request(std::span<const std::uint8_t> request_pdu, RegisterImage& image);

// ---------------------------------------------------------------- Modbus TCP (MBAP)

inline constexpr std::size_t kMbapHeaderSize = 7;  // transaction, protocol, length (2 each), unit id
// Largest length field: unit id + largest PDU.
inline constexpr std::uint16_t kMaxMbapLength = 1 + kMaxPduSize;

struct MbapHeader {
    std::uint16_t transaction_id = 0;
    std::uint16_t protocol_id = 0;
    std::uint16_t length = 0;   // bytes after the length field: unit id + PDU
    std::uint8_t unit_id = 0;
};
MbapHeader parse_mbap_header(std::span<const std::uint8_t, kMbapHeaderSize> bytes);
// Empty = usable; otherwise why the stream cannot be trusted any more
// ("MBAP protocol id 0x0001 is not 0 (Modbus)", "MBAP length 1 outside 2..254").
std::string mbap_header_problem(const MbapHeader& header);
// The response ADU: the request's transaction and unit id, protocol 0.
std::vector<std::uint8_t> frame_tcp_response(const MbapHeader& request, std::span<const std::uint8_t> response_pdu);

// ---------------------------------------------------------------- Modbus RTU

inline constexpr std::size_t kMaxRtuFrameSize = 256;  // address + PDU + CRC
inline constexpr std::size_t kMinRtuFrameSize = 4;    // address + function + CRC
inline constexpr std::uint8_t kBroadcastAddress = 0;

// CRC-16/MODBUS (poly 0xA001 reflected, init 0xFFFF); sent low byte first.
std::uint16_t crc16_modbus(std::span<const std::uint8_t> bytes);
// address + PDU + CRC.
std::vector<std::uint8_t> frame_rtu(std::uint8_t address, std::span<const std::uint8_t> pdu);

// Splits the bytes a slave receives on a serial line into request frames.
//
// A frame for this slave whose length the function code tells (FC 01-06, 15,
// 16) is complete as soon as that many bytes are in, and its CRC decides; no
// waiting for silence, so USB-serial adapters that deliver a frame in chunks
// several milliseconds apart still work. Any other frame ends at
// `frame_end_silence_ns` of silence and is then judged by its CRC (an unknown
// function with a good CRC gets ILLEGAL FUNCTION from serve_request()).
// After a bad CRC, an oversized frame or a frame for another slave, every byte
// is dropped until `discard_silence_ns` of silence (the spec's 3.5 characters):
// the garbage, or the other slave's exchange, cannot be mistaken for a request.
// A request that follows with less silence than that is dropped with it; the
// master's retry after its response timeout is served.
//
// Time only matters through silence(): the caller calls it when it saw no byte
// for a while (it must not infer silence when bytes were waiting to be read).
class RtuRequestAssembler {
public:
    struct Timing {
        TimeNs discard_silence_ns = 1'750'000;
        TimeNs frame_end_silence_ns = 50'000'000;
    };
    struct Event {
        enum class Kind {
            request,      // CRC good, for this slave or broadcast: address + pdu
            bad_crc,      // dropped
            other_slave,  // addressed to another slave: dropped
            malformed,    // too short or too long to be a frame: dropped
        };
        Kind kind = Kind::request;
        std::uint8_t address = 0;
        std::vector<std::uint8_t> pdu;
    };

    RtuRequestAssembler(std::uint8_t own_address, Timing timing);

    // Bytes that arrived at `now_ns`. Complete frames go to `events`.
    void receive(std::span<const std::uint8_t> bytes, TimeNs now_ns, std::vector<Event>& events);
    // No byte arrived between the last receive() and `now_ns`: ends what the
    // silence ends (if long enough).
    void silence(TimeNs now_ns, std::vector<Event>& events);
    // When silence() next has something to do; kNever when idle.
    TimeNs next_deadline_ns() const;

private:
    void extract_frames(std::vector<Event>& events);
    void start_discarding();

    std::uint8_t own_address_;
    Timing timing_;
    std::vector<std::uint8_t> buffer_;
    bool discarding_ = false;
    TimeNs last_byte_ns_ = 0;
};

}  // namespace rig::modbus
