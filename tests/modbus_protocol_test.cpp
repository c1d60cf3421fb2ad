// Modbus protocol engine without sockets: good requests with hand-worked
// responses, a table of hostile request PDUs (each row says what is wrong with
// it and which exception it must get, and that the image is left as it was),
// a seeded mutation run that shows serve_request() never throws and only ever
// answers with a well-formed response, MBAP and endpoint parsing, the RTU CRC
// against the spec's worked example, and the RTU frame assembler.
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include "rig/wire/modbus_protocol.h"

namespace rig::modbus {
namespace {

using Bytes = std::vector<std::uint8_t>;

std::uint8_t hi(std::uint16_t word) { return static_cast<std::uint8_t>(word >> 8); }
std::uint8_t lo(std::uint16_t word) { return static_cast<std::uint8_t>(word & 0xFF); }

// function, address, quantity-or-value
Bytes request(std::uint8_t function, std::uint16_t address, std::uint16_t word) {
    return {function, hi(address), lo(address), hi(word), lo(word)};
}

Bytes write_registers(std::uint16_t address, const std::vector<std::uint16_t>& values,
                      std::optional<std::uint16_t> quantity = std::nullopt,
                      std::optional<std::uint8_t> byte_count = std::nullopt) {
    const auto q = quantity.value_or(static_cast<std::uint16_t>(values.size()));
    Bytes pdu{0x10, hi(address), lo(address), hi(q), lo(q),
              byte_count.value_or(static_cast<std::uint8_t>(2 * values.size()))};
    for (std::uint16_t value : values) {
        pdu.push_back(hi(value));
        pdu.push_back(lo(value));
    }
    return pdu;
}

Bytes write_coils(std::uint16_t address, std::uint16_t quantity, const Bytes& data,
                  std::optional<std::uint8_t> byte_count = std::nullopt) {
    Bytes pdu{0x0F, hi(address), lo(address), hi(quantity), lo(quantity),
              byte_count.value_or(static_cast<std::uint8_t>(data.size()))};
    pdu.insert(pdu.end(), data.begin(), data.end());
    return pdu;
}

RegisterImage sample_image() {
    RegisterImage image;
    io::DeviceSignals signals;
    signals.wheel_encoder_count = 0x00012345;
    signals.main_flow_pulses = 0xABCD0001;
    signals.pump_flow_adc = 1234;
    signals.boom_height_adc = 4095;
    signals.spray_switch = true;
    encode_device_signals(signals, image);
    image.coils[kCoilUnloadingValve] = true;
    image.coils[kCoilFirstSectionValve + 2] = true;
    image.holding_registers = {5, 6, kFlagOdometerActive};
    return image;
}

bool same_image(const RegisterImage& a, const RegisterImage& b) {
    return a.input_registers == b.input_registers && a.discrete_inputs == b.discrete_inputs && a.coils == b.coils &&
           a.holding_registers == b.holding_registers;
}

// --------------------------------------------------------------- good requests

TEST(ModbusServe, ReadInputRegistersAllInOne) {
    RegisterImage image = sample_image();
    const ServedRequest served = serve_request(request(0x04, 0, 11), image);
    EXPECT_FALSE(served.exception);
    // ..., map version 3, then the flow meter's and the encoder's capture times
    // (registers 7-8 and 9-10, zero in the sample).
    EXPECT_EQ(served.response_pdu, (Bytes{0x04, 22, 0x00, 0x01, 0x23, 0x45, 0xAB, 0xCD, 0x00, 0x01, 0x04, 0xD2, 0x0F,
                                          0xFF, 0x00, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}));
    EXPECT_FALSE(served.wrote_outputs);
}

TEST(ModbusServe, ReadDiscreteInputsAndCoilsPackLsbFirst) {
    RegisterImage image = sample_image();
    EXPECT_EQ(serve_request(request(0x02, 0, 2), image).response_pdu, (Bytes{0x02, 1, 0b10}));
    EXPECT_EQ(serve_request(request(0x02, 1, 1), image).response_pdu, (Bytes{0x02, 1, 0b1}));
    // coils 2 (unloading) and 10 (section 3): 0b0000'0100, 0b0000'0100
    EXPECT_EQ(serve_request(request(0x01, 0, 16), image).response_pdu, (Bytes{0x01, 2, 0x04, 0x04}));
    EXPECT_EQ(serve_request(request(0x01, 2, 9), image).response_pdu, (Bytes{0x01, 2, 0x01, 0x01}));
}

TEST(ModbusServe, ReadHoldingRegisters) {
    RegisterImage image = sample_image();
    EXPECT_EQ(serve_request(request(0x03, 1, 2), image).response_pdu, (Bytes{0x03, 4, 0x00, 0x06, 0x00, 0x02}));
}

TEST(ModbusServe, WriteSingleCoilEchoesAndStores) {
    RegisterImage image = sample_image();
    const Bytes on = request(0x05, 0, 0xFF00);
    const ServedRequest served = serve_request(on, image);
    EXPECT_EQ(served.response_pdu, on);
    EXPECT_TRUE(served.wrote_outputs);
    EXPECT_TRUE(image.coils[0]);
    EXPECT_TRUE(serve_request(request(0x05, 2, 0x0000), image).wrote_outputs);
    EXPECT_FALSE(image.coils[2]);
}

TEST(ModbusServe, WriteSingleRegisterEchoesAndStores) {
    RegisterImage image = sample_image();
    const Bytes pdu = request(0x06, 2, kFlagBreakpointPending | kFlagOdometerActive);
    EXPECT_EQ(serve_request(pdu, image).response_pdu, pdu);
    EXPECT_EQ(image.holding_registers[2], 3);
}

TEST(ModbusServe, WriteMultipleCoilsAllSixteen) {
    RegisterImage image = sample_image();
    // Relays: forward on; sections 1, 2 and 8.
    const ServedRequest served = serve_request(write_coils(0, 16, {0b0000'0001, 0b1000'0011}), image);
    EXPECT_EQ(served.response_pdu, (Bytes{0x0F, 0x00, 0x00, 0x00, 0x10}));
    EXPECT_TRUE(served.wrote_outputs);
    const io::ActuatorCommands commands = decode_coils(image.coils);
    EXPECT_TRUE(commands.ball_valve_forward);
    EXPECT_FALSE(commands.unloading_valve_open);
    EXPECT_EQ(commands.section_valves_open, 0b1000'0011);
}

TEST(ModbusServe, WriteMultipleRegisters) {
    RegisterImage image = sample_image();
    const ServedRequest served = serve_request(write_registers(0, {300, 299, 1}), image);
    EXPECT_EQ(served.response_pdu, (Bytes{0x10, 0x00, 0x00, 0x00, 0x03}));
    EXPECT_EQ(image.holding_registers, (HoldingRegisters{300, 299, 1}));
}

// --------------------------------------------------------------- hostile requests

struct HostileRow {
    Bytes pdu;
    ExceptionCode exception;
    std::string legend;
};

void PrintTo(const HostileRow& row, std::ostream* out) { *out << row.legend; }

std::vector<HostileRow> hostile_rows() {
    using E = ExceptionCode;
    return {
        // --- function codes
        {{0x07}, E::illegal_function, "FC 07 read exception status (serial-line only, not served)"},
        {{0x08, 0x00, 0x00, 0x12, 0x34}, E::illegal_function, "FC 08 diagnostics echo"},
        {{0x11}, E::illegal_function, "FC 17 report server id"},
        {{0x16, 0x00, 0x02, 0xFF, 0xFF, 0x00, 0x04}, E::illegal_function, "FC 22 mask write register (not served)"},
        {{0x17, 0, 0, 0, 1, 0, 2, 0, 1, 2, 0, 4}, E::illegal_function,
         "FC 23 read/write registers (not served; libmodbus 3.1.6 had an overflow here)"},
        {{0x2B, 0x0E, 0x01, 0x00}, E::illegal_function, "FC 43 read device identification"},
        {{0x00, 0x00, 0x00, 0x00, 0x01}, E::illegal_function, "function code 0"},
        {{0x83, 0x02}, E::illegal_function, "an exception response sent as a request"},
        {{0xFF, 0xFF, 0xFF, 0xFF, 0xFF}, E::illegal_function, "all ones"},
        // --- request structure (03: implied length incorrect)
        {{0x03}, E::illegal_data_value, "FC 03 with no address or quantity"},
        {{0x03, 0x00, 0x00, 0x00}, E::illegal_data_value, "FC 03 one byte short"},
        {{0x03, 0x00, 0x00, 0x00, 0x01, 0x00}, E::illegal_data_value, "FC 03 one byte too many"},
        {{0x05, 0x00, 0x00, 0xFF}, E::illegal_data_value, "FC 05 one byte short"},
        {{0x0F, 0x00, 0x00, 0x00}, E::illegal_data_value, "FC 15 cut inside its header"},
        {{0x10, 0x00, 0x00, 0x00, 0x01}, E::illegal_data_value, "FC 16 without a byte count"},
        // --- quantities
        {request(0x01, 0, 0), E::illegal_data_value, "read coils, quantity 0"},
        {request(0x01, 0, 2001), E::illegal_data_value, "read coils, quantity 2001 > 2000"},
        {request(0x02, 0, 0), E::illegal_data_value, "read discrete inputs, quantity 0"},
        {request(0x03, 0, 0), E::illegal_data_value, "read holding registers, quantity 0"},
        {request(0x03, 0, 126), E::illegal_data_value, "read holding registers, quantity 126 > 125"},
        {request(0x04, 0, 0), E::illegal_data_value, "read input registers, quantity 0"},
        {request(0x04, 0, 0xFFFF), E::illegal_data_value, "read input registers, quantity 65535"},
        {write_coils(0, 0, {}), E::illegal_data_value, "write coils, quantity 0"},
        {write_coils(0, 1969, Bytes(247, 0)), E::illegal_data_value, "write coils, quantity 1969 > 1968"},
        {write_registers(0, {}), E::illegal_data_value, "write registers, quantity 0"},
        {write_registers(0, std::vector<std::uint16_t>(124, 0)), E::illegal_data_value,
         "write registers, quantity 124 > 123"},
        // --- byte counts that lie
        {write_coils(8, 8, {0xFF}, 2), E::illegal_data_value, "write 8 coils, byte count 2 (quantity needs 1)"},
        {write_coils(8, 9, {0xFF}), E::illegal_data_value, "write 9 coils with 1 data byte"},
        {write_coils(8, 8, {0xFF, 0x00}, 1), E::illegal_data_value, "write coils, a data byte beyond the byte count"},
        {write_registers(0, {1, 2}, 3), E::illegal_data_value, "write 3 registers, byte count 4"},
        {write_registers(0, {1, 2}, 2, 6), E::illegal_data_value, "write registers, byte count 6 but 4 bytes follow"},
        {write_registers(0, {1, 2}, 2, 3), E::illegal_data_value, "write registers, odd byte count"},
        // --- addresses
        {request(0x01, 16, 1), E::illegal_data_address, "read coil 16 (table is 0..15)"},
        {request(0x01, 15, 2), E::illegal_data_address, "read coils 15..16 (runs off the end)"},
        {request(0x01, 0xFFFF, 2000), E::illegal_data_address, "read coils 65535.. (address + quantity overflows 16 bits)"},
        {request(0x02, 2, 1), E::illegal_data_address, "read discrete input 2"},
        {request(0x02, 0, 3), E::illegal_data_address, "read discrete inputs 0..2"},
        {request(0x03, 3, 1), E::illegal_data_address, "read holding register 3"},
        {request(0x03, 0xFFFF, 1), E::illegal_data_address, "read holding register 65535"},
        {request(0x04, 11, 1), E::illegal_data_address, "read input register 11"},
        {request(0x04, 0, 12), E::illegal_data_address, "read input registers 0..11"},
        {request(0x04, 100, 125), E::illegal_data_address, "read input registers far out, maximum quantity"},
        {request(0x05, 16, 0xFF00), E::illegal_data_address, "write coil 16"},
        {request(0x05, 0xFFFF, 0x0000), E::illegal_data_address, "write coil 65535"},
        {request(0x06, 3, 0), E::illegal_data_address, "write holding register 3"},
        {write_coils(15, 2, {0x03}), E::illegal_data_address, "write coils 15..16"},
        {write_registers(2, {0, 0}), E::illegal_data_address, "write holding registers 2..3"},
        {write_registers(0xFFFF, {0}), E::illegal_data_address, "write holding register 65535"},
        // --- values
        {request(0x05, 0, 0x1234), E::illegal_data_value, "write coil value 0x1234 (neither 0x0000 nor 0xFF00)"},
        {request(0x05, 0, 0x00FF), E::illegal_data_value, "write coil value 0x00FF (byte-swapped ON)"},
        {request(0x05, 0, 0x0001), E::illegal_data_value, "write coil value 0x0001 (a 'true' from a careless master)"},
        {request(0x05, 0, 0xFFFF), E::illegal_data_value, "write coil value 0xFFFF"},
        {request(0x05, 5, 0xFF00), E::illegal_data_value, "switch on reserved coil 5"},
        {write_coils(0, 16, {0b0000'1001, 0xFF}), E::illegal_data_value,
         "write all coils with reserved coil 3 on (the valid part must not be written either)"},
        {request(0x06, 2, 0x0004), E::illegal_data_value, "indicator flags with reserved bit 2"},
        {write_registers(0, {9, 9, 0x8000}), E::illegal_data_value,
         "write all holding registers with reserved flag bit 15 (counters must not change either)"},
    };
}

class ModbusServeHostile : public ::testing::TestWithParam<HostileRow> {};

TEST_P(ModbusServeHostile, GetsTheRightExceptionAndChangesNothing) {
    const HostileRow& row = GetParam();
    RegisterImage image = sample_image();
    const RegisterImage before = image;
    const ServedRequest served = serve_request(row.pdu, image);
    ASSERT_TRUE(served.exception) << row.legend;
    EXPECT_EQ(*served.exception, row.exception) << row.legend << ": " << served.problem;
    EXPECT_EQ(served.response_pdu,
              (Bytes{static_cast<std::uint8_t>(row.pdu[0] | 0x80), static_cast<std::uint8_t>(row.exception)}));
    EXPECT_FALSE(served.problem.empty());
    EXPECT_FALSE(served.wrote_outputs);
    EXPECT_TRUE(same_image(image, before)) << row.legend << ": a refused request changed the image";
}

INSTANTIATE_TEST_SUITE_P(Table, ModbusServeHostile, ::testing::ValuesIn(hostile_rows()));

TEST(ModbusServe, EmptyPduGetsNoResponse) {
    RegisterImage image = sample_image();
    const ServedRequest served = serve_request({}, image);
    EXPECT_TRUE(served.response_pdu.empty());
    EXPECT_FALSE(served.wrote_outputs);
}

TEST(ModbusServe, ProblemTextsNameWhatAndWhere) {
    RegisterImage image = sample_image();
    EXPECT_EQ(serve_request(request(0x04, 9, 3), image).problem, "FC 04: input registers 9..11 outside 0..10");
    EXPECT_EQ(serve_request(request(0x03, 0, 0), image).problem, "FC 03: quantity 0 outside 1..125");
    EXPECT_EQ(serve_request(request(0x05, 1, 0x1234), image).problem,
              "FC 05: coil value 0x1234 is neither 0x0000 (off) nor 0xFF00 (on)");
    EXPECT_EQ(serve_request(Bytes{0x2B, 0x0E}, image).problem,
              "FC 43: function code 0x2B is not served (only 01-06, 15, 16)");
}

// Random PDUs, many of them near-valid (a valid function code with random
// fields): never a throw, always either a normal response to the same function
// or a two-byte exception with code 1..3; reads never change the image.
TEST(ModbusServe, MutatedRequestsAlwaysGetWellFormedAnswers) {
    std::mt19937 random(20240611);
    const Bytes functions{0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x0F, 0x10};
    for (int round = 0; round < 200000; ++round) {
        Bytes pdu(1 + random() % 12);
        for (auto& byte : pdu) byte = static_cast<std::uint8_t>(random());
        if (random() % 4 != 0) pdu[0] = functions[random() % functions.size()];
        if (pdu.size() > 2 && random() % 2 == 0) pdu[1] = 0;  // small addresses hit the tables
        if (pdu.size() > 4 && random() % 2 == 0) pdu[3] = 0;  // small quantities pass the limit checks
        RegisterImage image = sample_image();
        const RegisterImage before = image;
        const ServedRequest served = serve_request(pdu, image);
        ASSERT_FALSE(served.response_pdu.empty());
        if (served.exception) {
            ASSERT_EQ(served.response_pdu.size(), 2u);
            ASSERT_EQ(served.response_pdu[0], pdu[0] | 0x80);
            ASSERT_GE(served.response_pdu[1], 1);
            ASSERT_LE(served.response_pdu[1], 3);
            ASSERT_TRUE(same_image(image, before));
        } else {
            ASSERT_EQ(served.response_pdu[0], pdu[0]);
            if (!served.wrote_outputs) {
                ASSERT_TRUE(same_image(image, before));
            }
            ASSERT_EQ(image.input_registers, before.input_registers);
            ASSERT_EQ(image.discrete_inputs, before.discrete_inputs);
        }
    }
}

// --------------------------------------------------------------- MBAP, endpoints, settings

TEST(ModbusTcp, MbapHeaderParsingAndChecks) {
    const Bytes bytes{0x12, 0x34, 0x00, 0x00, 0x00, 0x06, 0x11};
    const MbapHeader header = parse_mbap_header(std::span<const std::uint8_t, kMbapHeaderSize>(bytes.data(), 7));
    EXPECT_EQ(header.transaction_id, 0x1234);
    EXPECT_EQ(header.protocol_id, 0);
    EXPECT_EQ(header.length, 6);
    EXPECT_EQ(header.unit_id, 0x11);
    EXPECT_TRUE(mbap_header_problem(header).empty());
    EXPECT_TRUE(mbap_header_problem({1, 0, 2, 1}).empty());
    EXPECT_TRUE(mbap_header_problem({1, 0, 254, 1}).empty());
    EXPECT_EQ(mbap_header_problem({1, 1, 6, 1}), "MBAP protocol id 1 is not 0 (Modbus)");
    EXPECT_EQ(mbap_header_problem({1, 0, 1, 1}), "MBAP length 1 outside 2..254 (unit id + PDU of 1..253 bytes)");
    EXPECT_FALSE(mbap_header_problem({1, 0, 0, 1}).empty());
    EXPECT_FALSE(mbap_header_problem({1, 0, 255, 1}).empty());
    EXPECT_FALSE(mbap_header_problem({1, 0, 0xFFFF, 1}).empty());
}

TEST(ModbusTcp, ResponseFrameEchoesTransactionAndUnit) {
    const MbapHeader request_header{0xBEEF, 0, 6, 0x2A};
    EXPECT_EQ(frame_tcp_response(request_header, Bytes{0x84, 0x02}),
              (Bytes{0xBE, 0xEF, 0x00, 0x00, 0x00, 0x03, 0x2A, 0x84, 0x02}));
}

TEST(ModbusWireSettings, TcpEndpoints) {
    const TcpEndpoint endpoint = parse_tcp_endpoint("127.0.0.1:1502");
    EXPECT_EQ(endpoint.address, "127.0.0.1");
    EXPECT_EQ(endpoint.port, 1502);
    EXPECT_EQ(parse_tcp_endpoint("127.0.0.1:0").port, 0);
    EXPECT_THROW(parse_tcp_endpoint("127.0.0.1"), std::invalid_argument);
    EXPECT_THROW(parse_tcp_endpoint("127.0.0.1:"), std::invalid_argument);
    EXPECT_THROW(parse_tcp_endpoint("127.0.0.1:65536"), std::invalid_argument);
    EXPECT_THROW(parse_tcp_endpoint("127.0.0.1:15x"), std::invalid_argument);
    EXPECT_THROW(parse_tcp_endpoint("localhost:1502"), std::invalid_argument);
    try {
        parse_tcp_endpoint("127.0.0.1:port");
        FAIL();
    } catch (const std::invalid_argument& error) {
        EXPECT_EQ(std::string(error.what()), "TCP endpoint '127.0.0.1:port': port 'port' is not a number 0..65535");
    }
    EXPECT_TRUE(is_loopback_ipv4("127.0.0.1"));
    EXPECT_TRUE(is_loopback_ipv4("127.1.2.3"));
    EXPECT_FALSE(is_loopback_ipv4("0.0.0.0"));
    EXPECT_FALSE(is_loopback_ipv4("192.168.1.10"));
    EXPECT_FALSE(is_loopback_ipv4("128.0.0.1"));
    EXPECT_FALSE(is_loopback_ipv4("not an address"));
}

TEST(ModbusWireSettings, SerialSettings) {
    EXPECT_EQ(parse_parity("N"), Parity::none);
    EXPECT_EQ(parse_parity("e"), Parity::even);
    EXPECT_EQ(parse_parity("odd"), Parity::odd);
    EXPECT_THROW(parse_parity("X"), std::invalid_argument);
    SerialLineSettings line;
    line.device = "/dev/ttyUSB0";
    EXPECT_TRUE(serial_settings_problem(line).empty());
    EXPECT_EQ(describe(line), "/dev/ttyUSB0 115200 8N1");
    line.baud = 12345;
    EXPECT_NE(serial_settings_problem(line).find("baud rate 12345 for /dev/ttyUSB0"), std::string::npos);
    line.baud = 9600;
    line.data_bits = 5;
    EXPECT_FALSE(serial_settings_problem(line).empty());
    line.data_bits = 7;
    line.stop_bits = 3;
    EXPECT_FALSE(serial_settings_problem(line).empty());
    line.device.clear();
    EXPECT_FALSE(serial_settings_problem(line).empty());
    // 3.5 characters of 11 bits: 4.01 ms at 9600; fixed 1.75 ms above 19200.
    EXPECT_EQ(rtu_inter_frame_gap_ns(9600), 4'010'416);
    EXPECT_EQ(rtu_inter_frame_gap_ns(115200), 1'750'000);
}

// --------------------------------------------------------------- RTU

TEST(ModbusRtu, CrcOfTheSpecExample) {
    // Modbus over Serial Line V1.02, 6.2.2: "01 03 00 00 00 0A" is followed by C5 CD (low byte first).
    const Bytes frame{0x01, 0x03, 0x00, 0x00, 0x00, 0x0A};
    EXPECT_EQ(crc16_modbus(frame), 0xCDC5);
    EXPECT_EQ(frame_rtu(0x01, Bytes{0x03, 0x00, 0x00, 0x00, 0x0A}),
              (Bytes{0x01, 0x03, 0x00, 0x00, 0x00, 0x0A, 0xC5, 0xCD}));
}

using Kind = RtuRequestAssembler::Event::Kind;
constexpr TimeNs kMs = 1'000'000;

struct AssemblerFixture {
    RtuRequestAssembler assembler{1, {2 * kMs, 50 * kMs}};
    std::vector<RtuRequestAssembler::Event> events;
    TimeNs now = 1000 * kMs;

    void receive(const Bytes& bytes, TimeNs after_ns = 1 * kMs) {
        now += after_ns;
        assembler.receive(bytes, now, events);
    }
    void quiet(TimeNs for_ns) {
        now += for_ns;
        assembler.silence(now, events);
    }
    std::vector<Kind> kinds() const {
        std::vector<Kind> result;
        for (const auto& event : events) result.push_back(event.kind);
        return result;
    }
};

Bytes good_request() { return frame_rtu(1, request(0x03, 0, 3)); }

TEST(ModbusRtuAssembler, FrameOfKnownLengthCompletesWithoutSilence) {
    AssemblerFixture f;
    f.receive(good_request());
    ASSERT_EQ(f.kinds(), (std::vector<Kind>{Kind::request}));
    EXPECT_EQ(f.events[0].address, 1);
    EXPECT_EQ(f.events[0].pdu, request(0x03, 0, 3));
    EXPECT_EQ(f.assembler.next_deadline_ns(), kNever);
}

TEST(ModbusRtuAssembler, FrameInChunksWithGapsShorterThanFrameEnd) {
    AssemblerFixture f;
    const Bytes frame = frame_rtu(1, write_registers(0, {1, 2, 3}));
    for (std::uint8_t byte : frame) {
        f.receive({byte}, 20 * kMs);  // a USB adapter's latency between bytes
        if (f.events.empty()) f.quiet(0);
    }
    ASSERT_EQ(f.kinds(), (std::vector<Kind>{Kind::request}));
    EXPECT_EQ(f.events[0].pdu, write_registers(0, {1, 2, 3}));
}

TEST(ModbusRtuAssembler, BackToBackFramesInOneChunk) {
    AssemblerFixture f;
    Bytes both = good_request();
    const Bytes second = frame_rtu(1, request(0x05, 0, 0xFF00));
    both.insert(both.end(), second.begin(), second.end());
    f.receive(both);
    EXPECT_EQ(f.kinds(), (std::vector<Kind>{Kind::request, Kind::request}));
}

TEST(ModbusRtuAssembler, BadCrcDropsUntilSilence) {
    AssemblerFixture f;
    Bytes bad = good_request();
    bad.back() ^= 0x01;
    f.receive(bad);
    EXPECT_EQ(f.kinds(), (std::vector<Kind>{Kind::bad_crc}));
    f.receive(good_request(), 1 * kMs);  // no silence in between: still part of the garbage
    EXPECT_EQ(f.events.size(), 1u);
    f.quiet(1 * kMs);  // shorter than the 2 ms discard silence
    f.receive(good_request(), 0);
    EXPECT_EQ(f.events.size(), 1u);
    f.quiet(3 * kMs);
    f.receive(good_request());
    EXPECT_EQ(f.kinds(), (std::vector<Kind>{Kind::bad_crc, Kind::request}));
}

TEST(ModbusRtuAssembler, OtherSlaveIsSkippedWithItsReply) {
    AssemblerFixture f;
    f.receive(frame_rtu(2, request(0x03, 0, 3)));
    f.receive(frame_rtu(2, Bytes{0x03, 0x06, 0, 1, 0, 2, 0, 3}), 1 * kMs);  // slave 2 answers
    EXPECT_EQ(f.kinds(), (std::vector<Kind>{Kind::other_slave}));
    EXPECT_EQ(f.events[0].address, 2);
    f.quiet(5 * kMs);
    f.receive(good_request());
    EXPECT_EQ(f.kinds(), (std::vector<Kind>{Kind::other_slave, Kind::request}));
}

TEST(ModbusRtuAssembler, BroadcastIsDelivered) {
    AssemblerFixture f;
    f.receive(frame_rtu(0, request(0x05, 1, 0xFF00)));
    ASSERT_EQ(f.kinds(), (std::vector<Kind>{Kind::request}));
    EXPECT_EQ(f.events[0].address, 0);
}

TEST(ModbusRtuAssembler, TruncatedFrameIsDroppedAtFrameEndSilence) {
    AssemblerFixture f;
    const Bytes frame = good_request();
    f.receive(Bytes(frame.begin(), frame.begin() + 5));
    EXPECT_EQ(f.assembler.next_deadline_ns(), f.now + 50 * kMs);
    f.quiet(30 * kMs);
    EXPECT_TRUE(f.events.empty()) << "30 ms is a USB adapter's gap, not the end of the frame";
    f.quiet(30 * kMs);
    EXPECT_EQ(f.kinds(), (std::vector<Kind>{Kind::malformed}));
    f.receive(good_request());
    EXPECT_EQ(f.kinds(), (std::vector<Kind>{Kind::malformed, Kind::request}));
}

TEST(ModbusRtuAssembler, UnknownFunctionWaitsForSilenceThenIsJudgedByCrc) {
    AssemblerFixture f;
    f.receive(frame_rtu(1, Bytes{0x2B, 0x0E, 0x01, 0x00}));
    EXPECT_TRUE(f.events.empty());
    f.quiet(60 * kMs);
    ASSERT_EQ(f.kinds(), (std::vector<Kind>{Kind::request}));
    EXPECT_EQ(f.events[0].pdu, (Bytes{0x2B, 0x0E, 0x01, 0x00}));

    Bytes bad = frame_rtu(1, Bytes{0x2B, 0x0E, 0x01, 0x00});
    bad[2] ^= 0xFF;
    f.receive(bad);
    f.quiet(60 * kMs);
    EXPECT_EQ(f.kinds(), (std::vector<Kind>{Kind::request, Kind::bad_crc}));
}

TEST(ModbusRtuAssembler, ShortAndOversizedFramesAreMalformed) {
    AssemblerFixture f;
    f.receive({0x01, 0x2B, 0x00});
    f.quiet(60 * kMs);
    EXPECT_EQ(f.kinds(), (std::vector<Kind>{Kind::malformed}));
    // FC 16 with byte count 250: 259 bytes, more than any RTU frame.
    f.receive({0x01, 0x10, 0x00, 0x00, 0x00, 0x7D, 0xFA});
    EXPECT_EQ(f.kinds(), (std::vector<Kind>{Kind::malformed, Kind::malformed}));
    f.quiet(5 * kMs);
    // Endless bytes of an unknown function.
    Bytes endless(300, 0x2B);
    endless[0] = 0x01;
    f.receive(endless);
    EXPECT_EQ(f.kinds().size(), 3u);
    EXPECT_EQ(f.kinds().back(), Kind::malformed);
}

}  // namespace
}  // namespace rig::modbus
