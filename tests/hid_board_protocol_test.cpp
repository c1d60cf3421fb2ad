// USB-HID I/O board protocol: byte layout worked by hand, seeded round trips, a
// table of malformed reports (each with its one-line legend) refused with the
// right problem and a reason naming the byte, and arbitrary bytes never
// crashing the decoders.
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "rig/wire/hid_board_protocol.h"

namespace rig::hid {
namespace {

using Bytes = std::vector<std::uint8_t>;

BoardCommand sample_command() {
    BoardCommand command;
    command.sequence = 0x1234;
    command.signals.wheel_encoder_count = 0xA1B2C3D4;
    command.signals.main_flow_pulses = 90 * 20;  // 20 L at 90 pulses/L
    command.signals.pump_flow_adc = 0x0ABC;
    command.signals.boom_height_adc = 4095;
    command.signals.breakpoint_button = false;
    command.signals.spray_switch = true;
    command.spread_interval_us = 200'000;  // one 5 Hz epoch
    command.rebase_counters = true;
    return command;
}

BoardStatus sample_status() {
    BoardStatus status;
    status.sequence = 0xFFFF;
    status.last_command_sequence = 0x1234;
    status.actuators.ball_valve_forward = true;
    status.actuators.ball_valve_reverse = false;
    status.actuators.unloading_valve_open = true;
    status.actuators.section_valves_open = 0b1010'0101;
    status.indicators.breakpoints_stored = 3;
    status.indicators.breakpoints_reached = 2;
    status.indicators.breakpoint_pending = true;
    status.indicators.odometer_active = true;
    status.wheel_encoder_emitted = 0xFFFFFFF0;
    status.main_flow_emitted = 1799;
    status.board_time_us = 123'456'789;
    status.pulses_pending = true;
    status.rate_limited = false;
    status.target_behind = true;
    status.last_command_problem = ReportProblem::reserved_bits_set;
    return status;
}

void expect_same(const BoardCommand& a, const BoardCommand& b) {
    EXPECT_EQ(a.sequence, b.sequence);
    EXPECT_EQ(a.signals.wheel_encoder_count, b.signals.wheel_encoder_count);
    EXPECT_EQ(a.signals.main_flow_pulses, b.signals.main_flow_pulses);
    EXPECT_EQ(a.signals.pump_flow_adc, b.signals.pump_flow_adc);
    EXPECT_EQ(a.signals.boom_height_adc, b.signals.boom_height_adc);
    EXPECT_EQ(a.signals.breakpoint_button, b.signals.breakpoint_button);
    EXPECT_EQ(a.signals.spray_switch, b.signals.spray_switch);
    EXPECT_EQ(a.spread_interval_us, b.spread_interval_us);
    EXPECT_EQ(a.rebase_counters, b.rebase_counters);
}

void expect_same(const BoardStatus& a, const BoardStatus& b) {
    EXPECT_EQ(a.sequence, b.sequence);
    EXPECT_EQ(a.last_command_sequence, b.last_command_sequence);
    EXPECT_EQ(a.actuators.ball_valve_forward, b.actuators.ball_valve_forward);
    EXPECT_EQ(a.actuators.ball_valve_reverse, b.actuators.ball_valve_reverse);
    EXPECT_EQ(a.actuators.unloading_valve_open, b.actuators.unloading_valve_open);
    EXPECT_EQ(a.actuators.section_valves_open, b.actuators.section_valves_open);
    EXPECT_EQ(a.indicators.breakpoints_stored, b.indicators.breakpoints_stored);
    EXPECT_EQ(a.indicators.breakpoints_reached, b.indicators.breakpoints_reached);
    EXPECT_EQ(a.indicators.breakpoint_pending, b.indicators.breakpoint_pending);
    EXPECT_EQ(a.indicators.odometer_active, b.indicators.odometer_active);
    EXPECT_EQ(a.wheel_encoder_emitted, b.wheel_encoder_emitted);
    EXPECT_EQ(a.main_flow_emitted, b.main_flow_emitted);
    EXPECT_EQ(a.board_time_us, b.board_time_us);
    EXPECT_EQ(a.pulses_pending, b.pulses_pending);
    EXPECT_EQ(a.rate_limited, b.rate_limited);
    EXPECT_EQ(a.target_behind, b.target_behind);
    EXPECT_EQ(a.last_command_problem, b.last_command_problem);
}

TEST(HidBoardProtocol, CommandBytesByHand) {
    const Report report = encode_command(sample_command());
    const Bytes expected_head{
        0x01, 0x01,              // report id, version
        0x34, 0x12,              // sequence 0x1234
        0xD4, 0xC3, 0xB2, 0xA1,  // wheel target 0xA1B2C3D4
        0x08, 0x07, 0x00, 0x00,  // flow target 1800 = 0x708
        0x40, 0x0D, 0x03, 0x00,  // spread 200000 us = 0x30D40
        0xBC, 0x0A,              // pump code 0xABC
        0xFF, 0x0F,              // boom code 4095
        0x02,                    // digital outputs: spray switch only
        0x01,                    // flags: re-base
    };
    ASSERT_EQ(report.size(), 64u);
    EXPECT_EQ(Bytes(report.begin(), report.begin() + 22), expected_head);
    EXPECT_EQ(Bytes(report.begin() + 22, report.end()), Bytes(42, 0));
}

TEST(HidBoardProtocol, StatusBytesByHand) {
    const Report report = encode_status(sample_status());
    const Bytes expected_head{
        0x02, 0x01,              // report id, version
        0xFF, 0xFF,              // status sequence
        0x34, 0x12,              // last command applied
        0x05,                    // relays: forward + unloading
        0xA5,                    // sections 0, 2, 5, 7
        0xF0, 0xFF, 0xFF, 0xFF,  // wheel emitted
        0x07, 0x07, 0x00, 0x00,  // flow emitted 1799
        0x15, 0xCD, 0x5B, 0x07,  // board time 123456789
        0x03,                    // indicators: pending + odometer
        0x05,                    // flags: pending + target behind
        0x04,                    // last command problem: reserved bits set
        0x00,                    // reserved
        0x03, 0x00,              // breakpoints stored
        0x02, 0x00,              // breakpoints reached
    };
    EXPECT_EQ(Bytes(report.begin(), report.begin() + 28), expected_head);
    EXPECT_EQ(Bytes(report.begin() + 28, report.end()), Bytes(36, 0));
}

TEST(HidBoardProtocol, SeededRoundTrips) {
    std::mt19937 random(2023);
    const auto u32 = [&] { return static_cast<std::uint32_t>(random()); };
    const auto flag = [&] { return (random() & 1) != 0; };
    for (int i = 0; i < 2000; ++i) {
        BoardCommand command;
        command.sequence = static_cast<std::uint16_t>(u32());
        command.signals.wheel_encoder_count = u32();
        command.signals.main_flow_pulses = u32();
        command.signals.pump_flow_adc = static_cast<std::uint16_t>(u32() % 4096);
        command.signals.boom_height_adc = static_cast<std::uint16_t>(u32() % 4096);
        command.signals.breakpoint_button = flag();
        command.signals.spray_switch = flag();
        command.spread_interval_us = u32();
        command.rebase_counters = flag();
        const Report bytes = encode_command(command);
        const auto decoded = decode_command(bytes);
        ASSERT_TRUE(decoded.ok()) << decoded.error.reason;
        expect_same(*decoded.value, command);

        BoardStatus status;
        status.sequence = static_cast<std::uint16_t>(u32());
        status.last_command_sequence = static_cast<std::uint16_t>(u32());
        status.actuators.ball_valve_forward = flag();
        status.actuators.ball_valve_reverse = flag();
        status.actuators.unloading_valve_open = flag();
        status.actuators.section_valves_open = static_cast<std::uint8_t>(u32());
        status.indicators.breakpoints_stored = static_cast<std::uint16_t>(u32());
        status.indicators.breakpoints_reached = static_cast<std::uint16_t>(u32());
        status.indicators.breakpoint_pending = flag();
        status.indicators.odometer_active = flag();
        status.wheel_encoder_emitted = u32();
        status.main_flow_emitted = u32();
        status.board_time_us = u32();
        status.pulses_pending = flag();
        status.rate_limited = flag();
        status.target_behind = flag();
        status.last_command_problem = static_cast<ReportProblem>(u32() % 6);
        const auto decoded_status = decode_status(encode_status(status));
        ASSERT_TRUE(decoded_status.ok()) << decoded_status.error.reason;
        expect_same(*decoded_status.value, status);
    }
}

struct Malformed {
    const char* legend;                  // what a real sender would have done wrong
    std::function<void(Bytes&)> damage;  // applied to a valid report
    ReportProblem problem;
    const char* reason;  // expected within the error text
};

void check_table(const std::vector<Malformed>& table, const Report& valid, bool command) {
    for (const auto& row : table) {
        Bytes bytes(valid.begin(), valid.end());
        row.damage(bytes);
        const ReportError error = command ? decode_command(bytes).error : decode_status(bytes).error;
        const bool ok = command ? decode_command(bytes).ok() : decode_status(bytes).ok();
        EXPECT_FALSE(ok) << row.legend;
        EXPECT_EQ(error.problem, row.problem) << row.legend << ": " << error.reason;
        EXPECT_NE(error.reason.find(row.reason), std::string::npos)
            << row.legend << ": got '" << error.reason << "', expected it to contain '" << row.reason << "'";
    }
}

TEST(HidBoardProtocol, MalformedCommandReportsAreRefusedWithReason) {
    BoardCommand command = sample_command();
    command.rebase_counters = false;
    const std::vector<Malformed> table{
        {"63 bytes: the report id was left out of a numbered report",
         [](Bytes& b) { b.erase(b.begin()); }, ReportProblem::wrong_length,
         "command report is 63 bytes, expected 64"},
        {"65 bytes: an extra report-id byte in front",
         [](Bytes& b) { b.insert(b.begin(), 0x01); }, ReportProblem::wrong_length, "65 bytes"},
        {"empty: a zero-length write", [](Bytes& b) { b.clear(); }, ReportProblem::wrong_length, "0 bytes"},
        {"a status report sent the wrong way", [](Bytes& b) { b[0] = kStatusReportId; },
         ReportProblem::wrong_report_id, "report id 0x02, expected 0x01 (command)"},
        {"report id 0: an unnumbered report", [](Bytes& b) { b[0] = 0x00; }, ReportProblem::wrong_report_id,
         "report id 0x00"},
        {"version 3: a newer rig than this firmware", [](Bytes& b) { b[1] = 3; },
         ReportProblem::unsupported_version, "protocol version 3, this rig speaks versions 1..2"},
        {"version 0: uninitialised memory", [](Bytes& b) { b[1] = 0; }, ReportProblem::unsupported_version,
         "protocol version 0"},
        {"digital output bit 2: a third output this protocol does not have", [](Bytes& b) { b[20] |= 0x04; },
         ReportProblem::reserved_bits_set, "byte 20 (digital outputs): reserved bits 0x04 set"},
        {"command flag bit 7: a flag from a future version", [](Bytes& b) { b[21] |= 0x80; },
         ReportProblem::reserved_bits_set, "byte 21 (command flags): reserved bits 0x80 set"},
        {"byte 22 set: a field this version does not define", [](Bytes& b) { b[22] = 0x01; },
         ReportProblem::reserved_bits_set, "reserved byte 22 is 0x01, must be 0"},
        {"last byte set: garbage at the end", [](Bytes& b) { b[63] = 0xEE; }, ReportProblem::reserved_bits_set,
         "reserved byte 63 is 0xEE"},
        {"pump code 4096: a 16-bit value where 12 bits are allowed",
         [](Bytes& b) {
             b[16] = 0x00;
             b[17] = 0x10;
         },
         ReportProblem::value_out_of_range, "bytes 16-17 (pump-flow sensor code): 4096 exceeds the 12-bit range"},
        {"boom code 0xFFFF: a -1 sent as unsigned",
         [](Bytes& b) {
             b[18] = 0xFF;
             b[19] = 0xFF;
         },
         ReportProblem::value_out_of_range, "bytes 18-19 (boom-height sensor code): 65535"},
    };
    check_table(table, encode_command(command), true);
}

TEST(HidBoardProtocol, MalformedStatusReportsAreRefusedWithReason) {
    BoardStatus status = sample_status();
    status.last_command_problem = ReportProblem::none;
    const std::vector<Malformed> table{
        {"64 bytes read into a 32-byte buffer", [](Bytes& b) { b.resize(32); }, ReportProblem::wrong_length,
         "status report is 32 bytes"},
        {"a command report echoed back", [](Bytes& b) { b[0] = kCommandReportId; },
         ReportProblem::wrong_report_id, "report id 0x01, expected 0x02 (status)"},
        {"another gadget on the shared test PID (report id 0x05)", [](Bytes& b) { b[0] = 0x05; },
         ReportProblem::wrong_report_id, "report id 0x05"},
        {"firmware of protocol version 3", [](Bytes& b) { b[1] = 3; }, ReportProblem::unsupported_version,
         "status report has protocol version 3"},
        {"relay input bit 3: a fourth relay", [](Bytes& b) { b[6] |= 0x08; }, ReportProblem::reserved_bits_set,
         "byte 6 (relay inputs): reserved bits 0x08 set"},
        {"indicator bit 2", [](Bytes& b) { b[20] |= 0x04; }, ReportProblem::reserved_bits_set,
         "byte 20 (indicator inputs)"},
        {"status flag bit 3", [](Bytes& b) { b[21] |= 0x08; }, ReportProblem::reserved_bits_set,
         "byte 21 (status flags): reserved bits 0x08 set"},
        {"problem code 6: not a defined problem", [](Bytes& b) { b[22] = 6; }, ReportProblem::value_out_of_range,
         "byte 22 (last command problem): code 6 is not defined"},
        {"byte 23 set", [](Bytes& b) { b[23] = 0x10; }, ReportProblem::reserved_bits_set,
         "reserved byte 23 is 0x10"},
        {"byte 40 set", [](Bytes& b) { b[40] = 0x01; }, ReportProblem::reserved_bits_set,
         "reserved byte 40 is 0x01"},
    };
    check_table(table, encode_status(status), false);
}

TEST(HidBoardProtocol, EncoderRefusesWhatTheReportCannotCarry) {
    BoardCommand command = sample_command();
    command.signals.pump_flow_adc = 4096;
    try {
        encode_command(command);
        FAIL();
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("pump_flow_adc 4096 exceeds the 12-bit range 0..4095"),
                  std::string::npos)
            << error.what();
    }
    command.signals.pump_flow_adc = 0;
    command.signals.boom_height_adc = 5000;
    EXPECT_THROW(encode_command(command), std::invalid_argument);
    BoardStatus status;
    status.last_command_problem = static_cast<ReportProblem>(9);
    EXPECT_THROW(encode_status(status), std::invalid_argument);
}

TEST(HidBoardProtocol, CounterDistanceWraps) {
    EXPECT_EQ(counter_ahead(0, 10), 10);
    EXPECT_EQ(counter_ahead(10, 0), -10);
    EXPECT_EQ(counter_ahead(0xFFFFFFF0u, 0x10u), 32);
    EXPECT_EQ(counter_ahead(0x10u, 0xFFFFFFF0u), -32);
    EXPECT_EQ(counter_ahead(7, 7), 0);
}

TEST(HidBoardProtocol, ArbitraryBytesNeverCrashTheDecoders) {
    std::mt19937 random(99);
    for (int i = 0; i < 20000; ++i) {
        Bytes bytes(random() % 80);
        for (auto& byte : bytes) byte = static_cast<std::uint8_t>(random());
        if (!bytes.empty() && (i % 3) == 0) bytes[0] = (i % 2) ? kCommandReportId : kStatusReportId;
        if (bytes.size() > 1 && (i % 5) == 0) bytes[1] = kProtocolVersion;
        const auto command = decode_command(bytes);
        const auto status = decode_status(bytes);
        EXPECT_TRUE(command.ok() || !command.error.reason.empty());
        EXPECT_TRUE(status.ok() || !status.error.reason.empty());
    }
}

}  // namespace
}  // namespace rig::hid
