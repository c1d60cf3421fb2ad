#include "rig/wire/modbus_protocol.h"

#include <arpa/inet.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <stdexcept>

namespace rig::modbus {
namespace {

constexpr std::array<int, 11> kSupportedBauds{1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600};

std::uint16_t word_at(std::span<const std::uint8_t> bytes, std::size_t offset) {
    return static_cast<std::uint16_t>((bytes[offset] << 8) | bytes[offset + 1]);
}

void append_word(std::vector<std::uint8_t>& out, std::uint16_t value) {
    out.push_back(static_cast<std::uint8_t>(value >> 8));
    out.push_back(static_cast<std::uint8_t>(value & 0xFFu));
}

std::string hex_byte(std::uint8_t value) {
    static constexpr char kHexDigits[] = "0123456789ABCDEF";
    return std::string("0x") + kHexDigits[value >> 4] + kHexDigits[value & 0xFu];
}

std::string hex_word(std::uint16_t value) {
    return hex_byte(static_cast<std::uint8_t>(value >> 8)) + hex_byte(static_cast<std::uint8_t>(value & 0xFFu)).substr(2);
}

std::string function_label(std::uint8_t function) {
    const std::string number = function < 10 ? "0" + std::to_string(function) : std::to_string(function);
    return "FC " + number;
}

// One request being served: collects the outcome.
class RequestServer {
public:
    RequestServer(std::span<const std::uint8_t> pdu, RegisterImage& image) : pdu_(pdu), image_(image) {}

    ServedRequest serve() {
        function_ = pdu_[0];
        switch (function_) {
            case static_cast<std::uint8_t>(FunctionCode::read_coils):
                return read_bits(image_.coils.data(), image_.coils.size(), "coils");
            case static_cast<std::uint8_t>(FunctionCode::read_discrete_inputs):
                return read_bits(image_.discrete_inputs.data(), image_.discrete_inputs.size(), "discrete inputs");
            case static_cast<std::uint8_t>(FunctionCode::read_holding_registers):
                return read_registers(image_.holding_registers.data(), image_.holding_registers.size(),
                                      "holding registers");
            case static_cast<std::uint8_t>(FunctionCode::read_input_registers):
                return read_registers(image_.input_registers.data(), image_.input_registers.size(), "input registers");
            case static_cast<std::uint8_t>(FunctionCode::write_single_coil): return write_single_coil();
            case static_cast<std::uint8_t>(FunctionCode::write_single_register): return write_single_register();
            case static_cast<std::uint8_t>(FunctionCode::write_multiple_coils): return write_multiple_coils();
            case static_cast<std::uint8_t>(FunctionCode::write_multiple_registers): return write_multiple_registers();
            default:
                return refuse(ExceptionCode::illegal_function,
                              "function code " + hex_byte(function_) + " is not served (only 01-06, 15, 16)");
        }
    }

private:
    ServedRequest refuse(ExceptionCode code, std::string why) {
        ServedRequest served;
        served.response_pdu = {static_cast<std::uint8_t>(function_ | 0x80u), static_cast<std::uint8_t>(code)};
        served.exception = code;
        served.problem = function_label(function_) + ": " + why;
        return served;
    }

    ServedRequest answer(std::vector<std::uint8_t> response, bool wrote_outputs = false) {
        ServedRequest served;
        served.response_pdu = std::move(response);
        served.wrote_outputs = wrote_outputs;
        return served;
    }

    // Spec: a request whose implied length is wrong is ILLEGAL DATA VALUE.
    std::optional<ServedRequest> require_size(std::size_t expected) {
        if (pdu_.size() == expected) return std::nullopt;
        return refuse(ExceptionCode::illegal_data_value, "request PDU is " + std::to_string(pdu_.size()) +
                                                             " bytes, this function needs " + std::to_string(expected));
    }

    static std::string range_text(std::uint32_t address, std::uint32_t quantity) {
        return std::to_string(address) + ".." + std::to_string(address + quantity - 1);
    }

    std::optional<ServedRequest> require_in_table(std::uint32_t address, std::uint32_t quantity, std::size_t table_size,
                                                  const char* table) {
        if (address + quantity <= table_size) return std::nullopt;
        return refuse(ExceptionCode::illegal_data_address, std::string(table) + " " + range_text(address, quantity) +
                                                               " outside 0.." + std::to_string(table_size - 1));
    }

    std::optional<ServedRequest> require_quantity(std::uint16_t quantity, std::uint16_t max) {
        if (quantity >= 1 && quantity <= max) return std::nullopt;
        return refuse(ExceptionCode::illegal_data_value,
                      "quantity " + std::to_string(quantity) + " outside 1.." + std::to_string(max));
    }

    ServedRequest read_bits(const bool* table, std::size_t table_size, const char* table_name) {
        if (auto refused = require_size(5)) return *refused;
        const std::uint16_t address = word_at(pdu_, 1);
        const std::uint16_t quantity = word_at(pdu_, 3);
        if (auto refused = require_quantity(quantity, kMaxReadBits)) return *refused;
        if (auto refused = require_in_table(address, quantity, table_size, table_name)) return *refused;
        const std::size_t byte_count = (quantity + 7u) / 8u;
        std::vector<std::uint8_t> response{function_, static_cast<std::uint8_t>(byte_count)};
        response.resize(2 + byte_count, 0);
        for (std::size_t i = 0; i < quantity; ++i) {
            if (table[address + i]) response[2 + i / 8] = static_cast<std::uint8_t>(response[2 + i / 8] | (1u << (i % 8)));
        }
        return answer(std::move(response));
    }

    ServedRequest read_registers(const std::uint16_t* table, std::size_t table_size, const char* table_name) {
        if (auto refused = require_size(5)) return *refused;
        const std::uint16_t address = word_at(pdu_, 1);
        const std::uint16_t quantity = word_at(pdu_, 3);
        if (auto refused = require_quantity(quantity, kMaxReadRegisters)) return *refused;
        if (auto refused = require_in_table(address, quantity, table_size, table_name)) return *refused;
        std::vector<std::uint8_t> response{function_, static_cast<std::uint8_t>(2 * quantity)};
        for (std::size_t i = 0; i < quantity; ++i) append_word(response, table[address + i]);
        return answer(std::move(response));
    }

    ServedRequest write_single_coil() {
        if (auto refused = require_size(5)) return *refused;
        const std::uint16_t address = word_at(pdu_, 1);
        const std::uint16_t value = word_at(pdu_, 3);
        if (value != kCoilOn && value != kCoilOff) {
            return refuse(ExceptionCode::illegal_data_value,
                          "coil value " + hex_word(value) + " is neither 0x0000 (off) nor 0xFF00 (on)");
        }
        if (auto refused = require_in_table(address, 1, image_.coils.size(), "coils")) return *refused;
        if (auto problem = coil_write_problem(address, value == kCoilOn); !problem.empty()) {
            return refuse(ExceptionCode::illegal_data_value, problem);
        }
        image_.coils[address] = value == kCoilOn;
        return answer(std::vector<std::uint8_t>(pdu_.begin(), pdu_.end()), true);
    }

    ServedRequest write_single_register() {
        if (auto refused = require_size(5)) return *refused;
        const std::uint16_t address = word_at(pdu_, 1);
        const std::uint16_t value = word_at(pdu_, 3);
        if (auto refused = require_in_table(address, 1, image_.holding_registers.size(), "holding registers")) {
            return *refused;
        }
        if (auto problem = holding_register_write_problem(address, value); !problem.empty()) {
            return refuse(ExceptionCode::illegal_data_value, problem);
        }
        image_.holding_registers[address] = value;
        return answer(std::vector<std::uint8_t>(pdu_.begin(), pdu_.end()), true);
    }

    // FC 15 and 16 after the quantity check: the byte count is the one the
    // quantity implies, and the PDU is exactly header + byte count.
    std::optional<ServedRequest> check_byte_count(std::size_t expected_byte_count) {
        const std::size_t byte_count = pdu_[5];
        if (byte_count != expected_byte_count) {
            return refuse(ExceptionCode::illegal_data_value, "byte count " + std::to_string(byte_count) + " but quantity " +
                                                                 std::to_string(word_at(pdu_, 3)) + " needs " +
                                                                 std::to_string(expected_byte_count));
        }
        return require_size(6 + byte_count);
    }

    ServedRequest write_multiple_coils() {
        if (pdu_.size() < 6) return *require_size(6);
        const std::uint16_t address = word_at(pdu_, 1);
        const std::uint16_t quantity = word_at(pdu_, 3);
        if (auto refused = require_quantity(quantity, kMaxWriteBits)) return *refused;
        if (auto refused = check_byte_count((quantity + 7u) / 8u)) return *refused;
        if (auto refused = require_in_table(address, quantity, image_.coils.size(), "coils")) return *refused;
        const auto coil_value = [&](std::size_t i) { return ((pdu_[6 + i / 8] >> (i % 8)) & 1u) != 0; };
        for (std::size_t i = 0; i < quantity; ++i) {
            const auto coil = static_cast<std::uint16_t>(address + i);
            if (auto problem = coil_write_problem(coil, coil_value(i)); !problem.empty()) {
                return refuse(ExceptionCode::illegal_data_value, problem);
            }
        }
        for (std::size_t i = 0; i < quantity; ++i) image_.coils[address + i] = coil_value(i);
        std::vector<std::uint8_t> response(pdu_.begin(), pdu_.begin() + 5);
        return answer(std::move(response), true);
    }

    ServedRequest write_multiple_registers() {
        if (pdu_.size() < 6) return *require_size(6);
        const std::uint16_t address = word_at(pdu_, 1);
        const std::uint16_t quantity = word_at(pdu_, 3);
        if (auto refused = require_quantity(quantity, kMaxWriteRegisters)) return *refused;
        if (auto refused = check_byte_count(2u * quantity)) return *refused;
        if (auto refused = require_in_table(address, quantity, image_.holding_registers.size(), "holding registers")) {
            return *refused;
        }
        for (std::size_t i = 0; i < quantity; ++i) {
            const auto register_address = static_cast<std::uint16_t>(address + i);
            if (auto problem = holding_register_write_problem(register_address, word_at(pdu_, 6 + 2 * i));
                !problem.empty()) {
                return refuse(ExceptionCode::illegal_data_value, problem);
            }
        }
        for (std::size_t i = 0; i < quantity; ++i) image_.holding_registers[address + i] = word_at(pdu_, 6 + 2 * i);
        std::vector<std::uint8_t> response(pdu_.begin(), pdu_.begin() + 5);
        return answer(std::move(response), true);
    }

    std::span<const std::uint8_t> pdu_;
    RegisterImage& image_;
    std::uint8_t function_ = 0;
};

bool crc_matches(std::span<const std::uint8_t> frame) {
    if (frame.size() < 3) return false;
    const std::uint16_t crc = crc16_modbus(frame.first(frame.size() - 2));
    return frame[frame.size() - 2] == (crc & 0xFFu) && frame[frame.size() - 1] == (crc >> 8);
}

// Request frame length (address .. CRC) told by the function code, 0 when the
// function code does not tell it, std::nullopt when more bytes are needed first.
std::optional<std::size_t> rtu_request_length(std::span<const std::uint8_t> frame) {
    if (frame.size() < 2) return std::nullopt;
    switch (frame[1]) {
        case 0x01: case 0x02: case 0x03: case 0x04: case 0x05: case 0x06:
            return 8;  // address, function, 2 x 2 bytes, CRC
        case 0x0F: case 0x10:
            if (frame.size() < 7) return std::nullopt;
            return 9 + static_cast<std::size_t>(frame[6]);  // + byte count of data
        default:
            return 0;
    }
}

}  // namespace

// ---------------------------------------------------------------- wire settings

std::string_view to_string(FailsafeMode mode) { return mode == FailsafeMode::safe ? "safe" : "hold"; }

Parity parse_parity(std::string_view text) {
    std::string lower;
    for (char c : text) lower += static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    if (lower == "n" || lower == "none") return Parity::none;
    if (lower == "e" || lower == "even") return Parity::even;
    if (lower == "o" || lower == "odd") return Parity::odd;
    throw std::invalid_argument("parity '" + std::string(text) + "' is not N, E or O (none, even, odd)");
}

char parity_letter(Parity parity) {
    switch (parity) {
        case Parity::none: return 'N';
        case Parity::even: return 'E';
        case Parity::odd: return 'O';
    }
    return '?';
}

std::string serial_settings_problem(const SerialLineSettings& line) {
    if (line.device.empty()) return "serial device path is empty";
    if (std::find(kSupportedBauds.begin(), kSupportedBauds.end(), line.baud) == kSupportedBauds.end()) {
        std::string supported;
        for (int baud : kSupportedBauds) supported += (supported.empty() ? "" : ", ") + std::to_string(baud);
        return "baud rate " + std::to_string(line.baud) + " for " + line.device + " is not one of " + supported;
    }
    if (line.data_bits != 7 && line.data_bits != 8) {
        return "data bits " + std::to_string(line.data_bits) + " for " + line.device + " must be 7 or 8";
    }
    if (line.stop_bits != 1 && line.stop_bits != 2) {
        return "stop bits " + std::to_string(line.stop_bits) + " for " + line.device + " must be 1 or 2";
    }
    return {};
}

std::string describe(const SerialLineSettings& line) {
    return line.device + " " + std::to_string(line.baud) + " " + std::to_string(line.data_bits) +
           parity_letter(line.parity) + std::to_string(line.stop_bits);
}

TimeNs rtu_inter_frame_gap_ns(int baud) {
    if (baud <= 0 || baud > 19200) return 1'750'000;
    return static_cast<TimeNs>(3.5 * 11.0 * 1e9 / baud);
}

TcpEndpoint parse_tcp_endpoint(std::string_view text) {
    const auto colon = text.rfind(':');
    if (colon == std::string_view::npos) {
        throw std::invalid_argument("TCP endpoint '" + std::string(text) + "' is not ADDRESS:PORT (e.g. 127.0.0.1:1502)");
    }
    TcpEndpoint endpoint;
    endpoint.address = std::string(text.substr(0, colon));
    in_addr parsed{};
    if (inet_pton(AF_INET, endpoint.address.c_str(), &parsed) != 1) {
        throw std::invalid_argument("TCP endpoint '" + std::string(text) + "': '" + endpoint.address +
                                    "' is not an IPv4 address (e.g. 127.0.0.1)");
    }
    const std::string_view port_text = text.substr(colon + 1);
    unsigned port = 0;
    const auto [end, error] = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
    if (port_text.empty() || error != std::errc() || end != port_text.data() + port_text.size() || port > 65535) {
        throw std::invalid_argument("TCP endpoint '" + std::string(text) + "': port '" + std::string(port_text) +
                                    "' is not a number 0..65535");
    }
    endpoint.port = static_cast<std::uint16_t>(port);
    return endpoint;
}

bool is_loopback_ipv4(std::string_view address) {
    in_addr parsed{};
    if (inet_pton(AF_INET, std::string(address).c_str(), &parsed) != 1) return false;
    return (ntohl(parsed.s_addr) >> 24) == 127;
}

// ---------------------------------------------------------------- application protocol

std::string exception_name(std::uint8_t code) {
    switch (code) {
        case 0x01: return "ILLEGAL FUNCTION";
        case 0x02: return "ILLEGAL DATA ADDRESS";
        case 0x03: return "ILLEGAL DATA VALUE";
        case 0x04: return "SERVER DEVICE FAILURE";
        case 0x05: return "ACKNOWLEDGE";
        case 0x06: return "SERVER DEVICE BUSY";
        case 0x08: return "MEMORY PARITY ERROR";
        case 0x0A: return "GATEWAY PATH UNAVAILABLE";
        case 0x0B: return "GATEWAY TARGET DEVICE FAILED TO RESPOND";
        default: return "exception " + hex_byte(code);
    }
}

ServedRequest serve_request(std::span<const std::uint8_t> request_pdu, RegisterImage& image) {
    if (request_pdu.empty()) {
        ServedRequest served;
        served.problem = "empty request PDU";
        return served;
    }
    return RequestServer(request_pdu, image).serve();
}

// ---------------------------------------------------------------- TCP

MbapHeader parse_mbap_header(std::span<const std::uint8_t, kMbapHeaderSize> bytes) {
    MbapHeader header;
    header.transaction_id = word_at(bytes, 0);
    header.protocol_id = word_at(bytes, 2);
    header.length = word_at(bytes, 4);
    header.unit_id = bytes[6];
    return header;
}

std::string mbap_header_problem(const MbapHeader& header) {
    if (header.protocol_id != 0) {
        return "MBAP protocol id " + std::to_string(header.protocol_id) + " is not 0 (Modbus)";
    }
    if (header.length < 2 || header.length > kMaxMbapLength) {
        return "MBAP length " + std::to_string(header.length) + " outside 2.." + std::to_string(kMaxMbapLength) +
               " (unit id + PDU of 1..253 bytes)";
    }
    return {};
}

std::vector<std::uint8_t> frame_tcp_response(const MbapHeader& request, std::span<const std::uint8_t> response_pdu) {
    std::vector<std::uint8_t> adu;
    adu.reserve(kMbapHeaderSize + response_pdu.size());
    append_word(adu, request.transaction_id);
    append_word(adu, 0);
    append_word(adu, static_cast<std::uint16_t>(1 + response_pdu.size()));
    adu.push_back(request.unit_id);
    adu.insert(adu.end(), response_pdu.begin(), response_pdu.end());
    return adu;
}

// ---------------------------------------------------------------- RTU

std::uint16_t crc16_modbus(std::span<const std::uint8_t> bytes) {
    std::uint16_t crc = 0xFFFF;
    for (std::uint8_t byte : bytes) {
        crc ^= byte;
        for (int bit = 0; bit < 8; ++bit) {
            crc = (crc & 1u) != 0 ? static_cast<std::uint16_t>((crc >> 1) ^ 0xA001u) : static_cast<std::uint16_t>(crc >> 1);
        }
    }
    return crc;
}

std::vector<std::uint8_t> frame_rtu(std::uint8_t address, std::span<const std::uint8_t> pdu) {
    std::vector<std::uint8_t> frame;
    frame.reserve(pdu.size() + 3);
    frame.push_back(address);
    frame.insert(frame.end(), pdu.begin(), pdu.end());
    const std::uint16_t crc = crc16_modbus(frame);
    frame.push_back(static_cast<std::uint8_t>(crc & 0xFFu));
    frame.push_back(static_cast<std::uint8_t>(crc >> 8));
    return frame;
}

RtuRequestAssembler::RtuRequestAssembler(std::uint8_t own_address, Timing timing)
    : own_address_(own_address), timing_(timing) {}

void RtuRequestAssembler::receive(std::span<const std::uint8_t> bytes, TimeNs now_ns, std::vector<Event>& events) {
    if (bytes.empty()) return;
    last_byte_ns_ = now_ns;
    if (discarding_) return;
    buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
    extract_frames(events);
}

void RtuRequestAssembler::start_discarding() {
    buffer_.clear();
    discarding_ = true;
}

void RtuRequestAssembler::extract_frames(std::vector<Event>& events) {
    while (!buffer_.empty() && !discarding_) {
        const std::uint8_t address = buffer_[0];
        if (address != own_address_ && address != kBroadcastAddress) {
            events.push_back({Event::Kind::other_slave, address, {}});
            start_discarding();
            return;
        }
        const std::optional<std::size_t> length = rtu_request_length(buffer_);
        if (!length) return;  // more bytes first
        if (*length == 0 || *length > kMaxRtuFrameSize) {
            // Unknown length: silence will end it, unless it outgrows any frame.
            if (*length > kMaxRtuFrameSize || buffer_.size() > kMaxRtuFrameSize) {
                events.push_back({Event::Kind::malformed, address, {}});
                start_discarding();
            }
            return;
        }
        if (buffer_.size() < *length) return;
        const std::span<const std::uint8_t> frame(buffer_.data(), *length);
        if (!crc_matches(frame)) {
            events.push_back({Event::Kind::bad_crc, address, {}});
            start_discarding();
            return;
        }
        events.push_back({Event::Kind::request, address, {frame.begin() + 1, frame.end() - 2}});
        buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(*length));
    }
}

void RtuRequestAssembler::silence(TimeNs now_ns, std::vector<Event>& events) {
    if (discarding_) {
        if (now_ns - last_byte_ns_ >= timing_.discard_silence_ns) discarding_ = false;
        return;
    }
    if (buffer_.empty() || now_ns - last_byte_ns_ < timing_.frame_end_silence_ns) return;
    // The line went quiet: what is buffered is one whole frame, or a broken one.
    const std::uint8_t address = buffer_[0];
    const std::optional<std::size_t> length = rtu_request_length(buffer_);
    if (buffer_.size() >= kMinRtuFrameSize && crc_matches(buffer_)) {
        // Good CRC: an unknown function, or a known one with the wrong length;
        // serve_request() answers both with the right exception.
        events.push_back({Event::Kind::request, address, {buffer_.begin() + 1, buffer_.end() - 2}});
    } else if (buffer_.size() < kMinRtuFrameSize || !length || *length > buffer_.size()) {
        events.push_back({Event::Kind::malformed, address, {}});  // truncated
    } else {
        events.push_back({Event::Kind::bad_crc, address, {}});
    }
    buffer_.clear();
}

TimeNs RtuRequestAssembler::next_deadline_ns() const {
    if (discarding_) return last_byte_ns_ + timing_.discard_silence_ns;
    if (!buffer_.empty()) return last_byte_ns_ + timing_.frame_end_silence_ns;
    return kNever;
}

}  // namespace rig::modbus
