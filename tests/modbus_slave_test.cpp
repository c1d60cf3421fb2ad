// ModbusSlave with our libmodbus ModbusMaster over TCP on 127.0.0.1 (ephemeral
// ports) and over RTU through a socat pty pair; hostile frames sent raw over a
// TCP socket and a pty (a table, each row with a one-line legend, after each
// of which a good master is still served); the master's errors against absent,
// silent and misbehaving endpoints.
//
// Timing: nothing here asserts how fast something happens, only that it happens
// within bounds far beyond any scheduling delay on a loaded 2-core machine; a
// test that needs "the stalled client does not block the others" makes the
// stall longer than the good master's timeout instead of measuring latency.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "modbus_test_support.h"
#include "rig/runtime/clock.h"
#include "rig/wire/modbus_master.h"
#include "rig/wire/modbus_slave.h"

namespace rig::modbus {
namespace {

using namespace std::chrono_literals;
namespace mt = rig::modbus::testing;
using mt::Bytes;

constexpr auto kGenerous = 10s;

TcpSlaveOptions any_port() {
    TcpSlaveOptions options;
    options.port = 0;
    return options;
}

TcpMasterOptions master_for(const ModbusSlave& slave) {
    TcpMasterOptions options;
    options.slave.port = slave.tcp_port();
    return options;
}

MasterTimeouts patient() { return {5000ms, 2000ms}; }

io::DeviceSignals sample_signals() {
    io::DeviceSignals signals;
    signals.wheel_encoder_count = 0xDEADBEEF;
    signals.main_flow_pulses = 123456;
    signals.pump_flow_adc = 2048;
    signals.boom_height_adc = 310;
    signals.breakpoint_button = true;
    signals.spray_switch = false;
    return signals;
}

io::ActuatorCommands sample_commands() {
    io::ActuatorCommands commands;
    commands.ball_valve_forward = true;
    commands.unloading_valve_open = true;
    commands.section_valves_open = 0b1010'0101;
    return commands;
}

void expect_signals(const io::DeviceSignals& actual, const io::DeviceSignals& expected) {
    EXPECT_EQ(actual.wheel_encoder_count, expected.wheel_encoder_count);
    EXPECT_EQ(actual.main_flow_pulses, expected.main_flow_pulses);
    EXPECT_EQ(actual.pump_flow_adc, expected.pump_flow_adc);
    EXPECT_EQ(actual.boom_height_adc, expected.boom_height_adc);
    EXPECT_EQ(actual.breakpoint_button, expected.breakpoint_button);
    EXPECT_EQ(actual.spray_switch, expected.spray_switch);
}

void expect_commands(const io::ActuatorCommands& actual, const io::ActuatorCommands& expected) {
    EXPECT_EQ(actual.ball_valve_forward, expected.ball_valve_forward);
    EXPECT_EQ(actual.ball_valve_reverse, expected.ball_valve_reverse);
    EXPECT_EQ(actual.unloading_valve_open, expected.unloading_valve_open);
    EXPECT_EQ(actual.section_valves_open, expected.section_valves_open);
}

std::string what_of(const std::function<void()>& action) {
    try {
        action();
    } catch (const std::exception& error) {
        return error.what();
    }
    return "(no exception)";
}

// =============================================================== TCP with our master

TEST(ModbusSlaveTcp, MasterReadsInputsAndWritesOutputs) {
    std::mutex writes_mutex;
    std::vector<MasterWrite> writes;
    ModbusSlaveCallbacks callbacks;
    callbacks.on_master_write = [&](const MasterWrite& write) {
        std::lock_guard lock(writes_mutex);
        writes.push_back(write);
    };
    ModbusSlave slave(any_port(), callbacks);
    ASSERT_NE(slave.tcp_port(), 0);
    EXPECT_EQ(slave.endpoint(), "tcp 127.0.0.1:" + std::to_string(slave.tcp_port()));
    slave.set_device_signals(sample_signals());

    ModbusMaster master(master_for(slave), patient());
    EXPECT_EQ(master.endpoint(), "tcp 127.0.0.1:" + std::to_string(slave.tcp_port()) + " unit 1");
    expect_signals(master.read_device_signals(), sample_signals());
    EXPECT_EQ(master.read_map_version(), kRegisterMapVersion);

    const std::uint64_t before = slave.master_write_count();
    EXPECT_EQ(before, 0u);
    master.write_actuator_commands(sample_commands());
    EXPECT_EQ(slave.wait_for_master_write(before, kGenerous), 1u);
    expect_commands(slave.actuator_commands(), sample_commands());
    expect_commands(master.read_actuator_commands(), sample_commands());

    io::ControllerIndicators indicators;
    indicators.breakpoints_stored = 3;
    indicators.breakpoints_reached = 2;
    indicators.odometer_active = true;
    master.write_indicators(indicators);
    EXPECT_EQ(slave.wait_for_master_write(1, kGenerous), 2u);
    EXPECT_EQ(slave.indicators().breakpoints_stored, 3);
    EXPECT_EQ(slave.indicators().breakpoints_reached, 2);
    EXPECT_FALSE(slave.indicators().breakpoint_pending);
    EXPECT_TRUE(slave.indicators().odometer_active);
    EXPECT_EQ(master.read_indicators().breakpoints_stored, 3);

    master.write_actuator_commands(sample_commands());  // the same again: a write, not a change
    EXPECT_EQ(slave.wait_for_master_write(2, kGenerous), 3u);

    // The callback runs before the response goes out, so it has run for every write by now.
    std::lock_guard lock(writes_mutex);
    ASSERT_EQ(writes.size(), 3u);
    EXPECT_TRUE(writes[0].commands_changed);
    EXPECT_FALSE(writes[0].indicators_changed);
    expect_commands(writes[0].commands, sample_commands());
    EXPECT_FALSE(writes[1].commands_changed);
    EXPECT_TRUE(writes[1].indicators_changed);
    EXPECT_EQ(writes[1].indicators.breakpoints_stored, 3);
    EXPECT_FALSE(writes[2].commands_changed);
    EXPECT_FALSE(writes[2].indicators_changed);
    EXPECT_EQ(writes[0].sequence, 1u);
    EXPECT_EQ(writes[2].sequence, 3u);

    const ModbusSlaveStatistics stats = slave.statistics();
    EXPECT_EQ(stats.master_writes, 3u);
    EXPECT_GE(stats.requests_answered, 8u);
    EXPECT_EQ(stats.illegal_function + stats.illegal_data_address + stats.illegal_data_value, 0u);
    EXPECT_EQ(stats.malformed_frames, 0u);
    EXPECT_FALSE(slave.server_failure());
}

TEST(ModbusSlaveTcp, StalledAndIdleClientsDoNotBlockOthers) {
    TcpSlaveOptions options = any_port();
    options.partial_frame_timeout = 60s;  // far longer than the masters' timeout below
    ModbusSlave slave(options);
    slave.set_device_signals(sample_signals());
    mt::RawTcpClient idle(slave.tcp_port());     // connects, never sends anything
    mt::RawTcpClient stalled(slave.tcp_port());  // sends 3 bytes of a header, then nothing
    stalled.send({0x00, 0x01, 0x00});
    ModbusMaster reader(master_for(slave), patient());
    ModbusMaster writer(master_for(slave), patient());
    for (int round = 0; round < 20; ++round) {
        expect_signals(reader.read_device_signals(), sample_signals());
        io::ActuatorCommands commands;
        commands.section_valves_open = static_cast<std::uint8_t>(round);
        writer.write_actuator_commands(commands);
        EXPECT_EQ(slave.actuator_commands().section_valves_open, round);
    }
    EXPECT_EQ(slave.statistics().connections_accepted, 4u);
    EXPECT_EQ(slave.statistics().connections_timed_out, 0u);
}

TEST(ModbusSlaveTcp, IncompleteFrameTimesOutAndClosesOnlyThatConnection) {
    TcpSlaveOptions options = any_port();
    options.partial_frame_timeout = 300ms;
    ModbusSlave slave(options);
    ModbusMaster master(master_for(slave), patient());
    mt::RawTcpClient stalled(slave.tcp_port());
    stalled.send({0x00, 0x01, 0x00, 0x00, 0x00, 0x06, 0x01, 0x04});  // header + function, then nothing
    EXPECT_TRUE(stalled.closed_by_peer(kGenerous));
    EXPECT_TRUE(mt::eventually([&] { return slave.statistics().connections_timed_out == 1; }));
    EXPECT_NE(slave.statistics().last_problem.find("frame incomplete after 300 ms (8 bytes); connection closed"),
              std::string::npos)
        << slave.statistics().last_problem;
    expect_signals(master.read_device_signals(), io::DeviceSignals{});
}

TEST(ModbusSlaveTcp, ClientVanishingMidFrameIsCounted) {
    ModbusSlave slave(any_port());
    {
        mt::RawTcpClient client(slave.tcp_port());
        client.send({0x00, 0x07, 0x00, 0x00, 0x00});
    }
    EXPECT_TRUE(mt::eventually([&] { return slave.statistics().connections_closed_mid_frame == 1; }));
    EXPECT_EQ(slave.statistics().connections_closed_by_peer, 1u);
    ModbusMaster master(master_for(slave), patient());
    EXPECT_EQ(master.read_map_version(), kRegisterMapVersion);
}

TEST(ModbusSlaveTcp, NewConnectionEvictsTheLeastRecentlyActive) {
    TcpSlaveOptions options = any_port();
    options.max_connections = 2;
    ModbusSlave slave(options);
    mt::RawTcpClient oldest(slave.tcp_port());
    mt::RawTcpClient second(slave.tcp_port());
    ASSERT_TRUE(mt::eventually([&] { return slave.statistics().connections_accepted == 2; }));
    ModbusMaster master(master_for(slave), patient());
    EXPECT_EQ(master.read_map_version(), kRegisterMapVersion);
    EXPECT_TRUE(oldest.closed_by_peer(kGenerous));
    EXPECT_EQ(slave.statistics().connections_evicted, 1u);
}

TEST(ModbusSlaveTcp, PipelinedAndSplitRequests) {
    ModbusSlave slave(any_port());
    slave.set_device_signals(sample_signals());
    mt::RawTcpClient client(slave.tcp_port());
    // Two requests in one segment: two responses, in order.
    Bytes both = mt::tcp_frame(1, {0x04, 0x00, 0x06, 0x00, 0x01});
    const Bytes second = mt::tcp_frame(2, {0x02, 0x00, 0x00, 0x00, 0x02});
    both.insert(both.end(), second.begin(), second.end());
    client.send(both);
    EXPECT_EQ(client.receive(11, kGenerous), (Bytes{0, 1, 0, 0, 0, 5, 1, 0x04, 0x02, 0x00, kRegisterMapVersion}));
    EXPECT_EQ(client.receive(10, kGenerous), (Bytes{0, 2, 0, 0, 0, 4, 1, 0x02, 0x01, 0b01}));
    // One request in three pieces with pauses between them.
    const Bytes frame = mt::tcp_frame(3, {0x03, 0x00, 0x00, 0x00, 0x01}, 0xFF);
    client.send(Bytes(frame.begin(), frame.begin() + 2));
    std::this_thread::sleep_for(50ms);
    client.send(Bytes(frame.begin() + 2, frame.begin() + 9));
    std::this_thread::sleep_for(50ms);
    client.send(Bytes(frame.begin() + 9, frame.end()));
    EXPECT_EQ(client.receive(11, kGenerous), (Bytes{0, 3, 0, 0, 0, 5, 0xFF, 0x03, 0x02, 0x00, 0x00}));
}

// --------------------------------------------------------------- hostile frames

enum class Outcome {
    exception,                  // the exception response, connection stays open
    closed_at_once,             // the slave closes the connection (framing lost)
    closed_after_timeout,       // no answer; the incomplete frame times out and the slave closes
    exception_then_timeout,     // an exception for what was complete, then a time-out for the rest
};

struct TcpHostileRow {
    std::string legend;
    Bytes bytes;
    Outcome outcome;
    std::uint8_t function = 0;   // for the exception outcomes
    ExceptionCode code = ExceptionCode::illegal_function;
};

Bytes frame(const Bytes& pdu) { return mt::tcp_frame(0x4242, pdu); }

std::vector<TcpHostileRow> tcp_hostile_rows() {
    using E = ExceptionCode;
    Bytes too_many_coils{0x0F, 0x00, 0x00, 0x07, 0xB1, 247};  // 1969 coils
    too_many_coils.resize(too_many_coils.size() + 247, 0xFF);
    return {
        // --- framing: the slave cannot tell where the next frame starts
        {"truncated MBAP header (3 bytes), then nothing", {0x00, 0x01, 0x00}, Outcome::closed_after_timeout},
        {"MBAP header alone: its length promises a PDU that never comes", {0x00, 0x01, 0x00, 0x00, 0x00, 0x06, 0x01},
         Outcome::closed_after_timeout},
        {"length field lying long: says 12, a 5-byte PDU follows", mt::tcp_frame(0x4242, {0x03, 0, 0, 0, 1}, 1, 12),
         Outcome::closed_after_timeout},
        {"length field lying short: says 3 (unit + 2 PDU bytes) before a 5-byte PDU",
         mt::tcp_frame(0x4242, {0x03, 0, 0, 0, 1}, 1, 3), Outcome::exception_then_timeout, 0x03, E::illegal_data_value},
        {"protocol id 1 (not Modbus)", mt::tcp_frame(0x4242, {0x03, 0, 0, 0, 1}, 1, std::nullopt, 1), Outcome::closed_at_once},
        {"length field 0", mt::tcp_frame(0x4242, {}, 1, 0), Outcome::closed_at_once},
        {"length field 1: unit id and no PDU", mt::tcp_frame(0x4242, {}, 1, 1), Outcome::closed_at_once},
        {"length field 255: a PDU longer than Modbus allows", mt::tcp_frame(0x4242, Bytes(254, 0x03), 1, 255),
         Outcome::closed_at_once},
        {"length field 0xFFFF", mt::tcp_frame(0x4242, {0x03, 0, 0, 0, 1}, 1, 0xFFFF), Outcome::closed_at_once},
        {"an HTTP request on the Modbus port",
         Bytes{'G', 'E', 'T', ' ', '/', ' ', 'H', 'T', 'T', 'P', '/', '1', '.', '1', '\r', '\n', '\r', '\n'},
         Outcome::closed_at_once},
        // --- function codes
        {"unknown function 0x2B (device identification) with payload", frame({0x2B, 0x0E, 0x01, 0x00}),
         Outcome::exception, 0x2B, E::illegal_function},
        {"FC 08 diagnostics", frame({0x08, 0x00, 0x00, 0xA5, 0x37}), Outcome::exception, 0x08, E::illegal_function},
        {"FC 23 read/write multiple registers", frame({0x17, 0, 0, 0, 1, 0, 2, 0, 1, 2, 0, 3}), Outcome::exception,
         0x17, E::illegal_function},
        {"function code 0x80 (an exception code as a request)", frame({0x80}), Outcome::exception, 0x80,
         E::illegal_function},
        // --- addresses
        {"read input register 11 (table is 0..10)", frame({0x04, 0x00, 0x0B, 0x00, 0x01}), Outcome::exception, 0x04,
         E::illegal_data_address},
        {"read coils 65535.. (address + quantity past 16 bits)", frame({0x01, 0xFF, 0xFF, 0x00, 0x10}),
         Outcome::exception, 0x01, E::illegal_data_address},
        {"write holding register 3", frame({0x06, 0x00, 0x03, 0x00, 0x01}), Outcome::exception, 0x06,
         E::illegal_data_address},
        // --- quantities
        {"read holding registers, quantity 0", frame({0x03, 0x00, 0x00, 0x00, 0x00}), Outcome::exception, 0x03,
         E::illegal_data_value},
        {"read input registers, quantity 126 > 125", frame({0x04, 0x00, 0x00, 0x00, 0x7E}), Outcome::exception, 0x04,
         E::illegal_data_value},
        {"read coils, quantity 2001 > 2000", frame({0x01, 0x00, 0x00, 0x07, 0xD1}), Outcome::exception, 0x01,
         E::illegal_data_value},
        {"write coils, quantity 1969 > 1968", frame(too_many_coils), Outcome::exception, 0x0F, E::illegal_data_value},
        {"write registers, quantity 124 > 123", frame({0x10, 0x00, 0x00, 0x00, 0x7C, 0x00}), Outcome::exception, 0x10,
         E::illegal_data_value},
        // --- values and structure
        {"write coil value 0x1234", frame({0x05, 0x00, 0x00, 0x12, 0x34}), Outcome::exception, 0x05,
         E::illegal_data_value},
        {"write coil value 0x00FF (byte-swapped ON)", frame({0x05, 0x00, 0x01, 0x00, 0xFF}), Outcome::exception, 0x05,
         E::illegal_data_value},
        {"switch on reserved coil 4", frame({0x05, 0x00, 0x04, 0xFF, 0x00}), Outcome::exception, 0x05,
         E::illegal_data_value},
        {"write coils, byte count 2 for 8 coils", frame({0x0F, 0x00, 0x08, 0x00, 0x08, 0x02, 0xFF, 0xFF}),
         Outcome::exception, 0x0F, E::illegal_data_value},
        {"indicator flags with a reserved bit", frame({0x06, 0x00, 0x02, 0x01, 0x00}), Outcome::exception, 0x06,
         E::illegal_data_value},
        {"FC 04 with a PDU one byte short", frame({0x04, 0x00, 0x00, 0x00}), Outcome::exception, 0x04,
         E::illegal_data_value},
    };
}

TEST(ModbusSlaveTcp, HostileFramesGetExceptionsOrCleanDropsAndGoodClientsStayServed) {
    TcpSlaveOptions options = any_port();
    options.partial_frame_timeout = 300ms;
    ModbusSlave slave(options);
    slave.set_device_signals(sample_signals());
    ModbusMaster good(master_for(slave), patient());  // one connection through the whole table

    for (const TcpHostileRow& row : tcp_hostile_rows()) {
        SCOPED_TRACE(row.legend);
        mt::RawTcpClient client(slave.tcp_port());
        client.send(row.bytes);
        if (row.outcome == Outcome::exception || row.outcome == Outcome::exception_then_timeout) {
            const Bytes expected{0x42, 0x42, 0x00, 0x00, 0x00, 0x03, 0x01, static_cast<std::uint8_t>(row.function | 0x80),
                                 static_cast<std::uint8_t>(row.code)};
            EXPECT_EQ(client.receive(expected.size(), kGenerous), expected);
        }
        if (row.outcome == Outcome::exception) {
            // Still open and serving on the same connection.
            client.send(frame({0x04, 0x00, 0x06, 0x00, 0x01}));
            EXPECT_EQ(client.receive(11, kGenerous), (Bytes{0x42, 0x42, 0, 0, 0, 5, 1, 0x04, 0x02, 0x00, kRegisterMapVersion}));
        } else {
            EXPECT_TRUE(client.closed_by_peer(kGenerous)) << "the slave must close a connection whose framing is lost";
        }
        expect_signals(good.read_device_signals(), sample_signals());
    }

    // No hostile write got through, and everything was counted.
    expect_commands(slave.actuator_commands(), io::ActuatorCommands{});
    EXPECT_EQ(slave.indicators().breakpoints_stored, 0);
    const ModbusSlaveStatistics stats = slave.statistics();
    EXPECT_EQ(stats.master_writes, 0u);
    EXPECT_EQ(stats.illegal_function, 4u);
    EXPECT_EQ(stats.illegal_data_address, 3u);
    EXPECT_EQ(stats.illegal_data_value, 12u);
    EXPECT_EQ(stats.malformed_frames, 6u);
    EXPECT_EQ(stats.connections_timed_out, 4u);
    EXPECT_FALSE(slave.server_failure());
}

// --------------------------------------------------------------- lifecycle and errors

TEST(ModbusSlaveTcp, StopReturnsPromptlyWithClientsConnected) {
    TcpSlaveOptions options = any_port();
    options.partial_frame_timeout = 60s;
    auto slave = std::make_unique<ModbusSlave>(options);
    mt::RawTcpClient idle(slave->tcp_port());
    mt::RawTcpClient stalled(slave->tcp_port());
    stalled.send({0x00, 0x01});
    ModbusMaster master(master_for(*slave), patient());
    EXPECT_EQ(master.read_map_version(), kRegisterMapVersion);
    const WallStopwatch clock;
    slave->stop();
    EXPECT_LT(clock.elapsed(), 5s);
    slave->stop();  // idempotent
    EXPECT_TRUE(idle.closed_by_peer(kGenerous));
    // The port is free again at once (a bench restarts `rig modbus serve` on its port).
    TcpSlaveOptions again;
    again.port = slave->tcp_port();
    slave.reset();
    EXPECT_NO_THROW(ModbusSlave restarted(again));
}

TEST(ModbusSlaveTcp, PortInUseIsAClearError) {
    ModbusSlave first(any_port());
    TcpSlaveOptions options;
    options.port = first.tcp_port();
    const std::string message = what_of([&] { ModbusSlave second(options); });
    EXPECT_NE(message.find("cannot listen for Modbus TCP on 127.0.0.1:" + std::to_string(first.tcp_port()) +
                           ": Address already in use"),
              std::string::npos)
        << message;
}

TEST(ModbusSlaveTcp, OnlyLoopbackUnlessAllowed) {
    for (const std::string address : {"0.0.0.0", "192.168.1.20"}) {
        TcpSlaveOptions options = any_port();
        options.bind_address = address;
        const std::string message = what_of([&] { ModbusSlave slave(options); });
        EXPECT_NE(message.find("'" + address + "' is not loopback"), std::string::npos) << message;
    }
    TcpSlaveOptions named = any_port();
    named.bind_address = "localhost";
    EXPECT_THROW(ModbusSlave slave(named), std::invalid_argument);
    TcpSlaveOptions other_loopback = any_port();
    other_loopback.bind_address = "127.0.0.1";
    EXPECT_NO_THROW(ModbusSlave slave(other_loopback));
}

TEST(ModbusSlaveTcp, CallbackErrorsAreCountedAndServingGoesOn) {
    ModbusSlaveCallbacks callbacks;
    callbacks.on_master_write = [](const MasterWrite&) { throw std::runtime_error("rig-side bug"); };
    ModbusSlave slave(any_port(), callbacks);
    ModbusMaster master(master_for(slave), patient());
    master.write_actuator_commands(sample_commands());
    master.write_actuator_commands(sample_commands());
    EXPECT_EQ(slave.statistics().callback_errors, 2u);
    expect_commands(slave.actuator_commands(), sample_commands());
    EXPECT_FALSE(slave.server_failure());
}

TEST(ModbusSlave, DeviceSignalsOverFullScaleAreRefusedAndNothingChanges) {
    ModbusSlave slave(any_port());
    slave.set_device_signals(sample_signals());
    io::DeviceSignals bad = sample_signals();
    bad.wheel_encoder_count = 1;
    bad.boom_height_adc = 5000;
    EXPECT_THROW(slave.set_device_signals(bad), std::invalid_argument);
    expect_signals(slave.device_signals(), sample_signals());
}

// =============================================================== RTU through a pty pair

class ModbusSlaveRtu : public ::testing::Test {
protected:
    void SetUp() override {
        ASSERT_TRUE(mt::require_tool("socat"));
        pair_ = std::make_unique<mt::PtyPair>(::testing::UnitTest::GetInstance()->current_test_info()->name());
        RtuSlaveOptions options;
        options.line.device = pair_->slave_end();
        options.slave_id = 1;
        slave_ = std::make_unique<ModbusSlave>(options);
        slave_->set_device_signals(sample_signals());
    }

    RtuMasterOptions master_options() const {
        RtuMasterOptions options;
        options.line.device = pair_->master_end();
        return options;
    }

    // A good request, sent again until answered (as a master retries after its
    // timeout): right after garbage the slave drops bytes until the line has been
    // quiet, and on a loaded machine "quiet" may be noticed late.
    Bytes ask_until_answered(mt::RawSerial& line, const Bytes& request_frame, std::size_t response_size) {
        std::this_thread::sleep_for(50ms);  // usually enough quiet for the slave to notice; else the retry
        for (int attempt = 0; attempt < 5; ++attempt) {
            line.write(request_frame);
            Bytes response = line.read(response_size, 2s);
            if (!response.empty()) {
                if (response.size() < response_size) {
                    const Bytes rest = line.read(response_size - response.size(), kGenerous);
                    response.insert(response.end(), rest.begin(), rest.end());
                }
                return response;
            }
        }
        return {};
    }

    // FC 04 read of the map version, and its exact answer.
    static Bytes version_request() { return frame_rtu(1, Bytes{0x04, 0x00, 0x06, 0x00, 0x01}); }
    static Bytes version_response() { return frame_rtu(1, Bytes{0x04, 0x02, 0x00, kRegisterMapVersion}); }

    std::unique_ptr<mt::PtyPair> pair_;
    std::unique_ptr<ModbusSlave> slave_;
};

TEST_F(ModbusSlaveRtu, MasterReadsInputsAndWritesOutputs) {
    ModbusMaster master(master_options(), patient());
    expect_signals(master.read_device_signals(), sample_signals());
    master.write_actuator_commands(sample_commands());
    expect_commands(slave_->actuator_commands(), sample_commands());
    io::ControllerIndicators indicators;
    indicators.breakpoints_stored = 1;
    indicators.breakpoint_pending = true;
    master.write_indicators(indicators);
    EXPECT_EQ(slave_->indicators().breakpoints_stored, 1);
    EXPECT_TRUE(slave_->indicators().breakpoint_pending);
    expect_commands(master.read_actuator_commands(), sample_commands());
    EXPECT_EQ(slave_->master_write_count(), 2u);
    EXPECT_EQ(slave_->statistics().bad_crc_frames, 0u);
}

// Noise on the line (a case's board.line_noise, emulators/wire_faults.h): a
// master that retries a failed exchange gets each answer within three tries,
// as long as no three responses in a row are damaged. Responses are damaged on
// a fixed schedule: every 7th has a byte hit (bad CRC), every 5th is followed
// by noise bytes the master finds in front of the next one. A master that
// flushed the line at once after a bad response left the rest of the broken
// frame, or the response still on its way, to be read as the retry's
// (cases/wire-faults/modbus-line-noise-wired-rtu: the controller died at 0.2 s).
TEST_F(ModbusSlaveRtu, MasterRecoversFromDamagedResponsesWithinItsRetries) {
    auto responses = std::make_shared<std::atomic<int>>(0);
    slave_->set_response_damage([responses](Bytes frame) {
        const int index = ++*responses;
        if (index % 7 == 0) frame[frame.size() / 2] ^= 0x5A;
        // Noise that reads as the start of a long frame for this slave, or as another slave's.
        if (index % 5 == 0) {
            const Bytes noise = index % 10 == 0 ? Bytes{0x01, 0x03, 0xFA} : Bytes{0x7E, 0x00, 0xC3, 0x11};
            frame.insert(frame.end(), noise.begin(), noise.end());
        }
        return frame;
    });
    ModbusMaster master(master_options(), MasterTimeouts{2000ms, 50ms});
    int failed_attempts = 0;
    io::DeviceSignals signals = sample_signals();
    for (std::uint32_t call = 0; call < 60; ++call) {
        // The inputs change before every call: a response left over from an
        // earlier exchange would show an earlier count.
        signals.wheel_encoder_count = 1000 + call;
        slave_->set_device_signals(signals);
        std::optional<io::DeviceSignals> read;
        std::string last_error;
        for (int attempt = 0; attempt < 3 && !read; ++attempt) {
            try {
                read = master.read_device_signals();
            } catch (const ModbusMasterError& error) {
                ASSERT_TRUE(error.kind() == ModbusMasterError::Kind::bad_response ||
                            error.kind() == ModbusMasterError::Kind::timeout)
                    << error.what();
                ++failed_attempts;
                last_error = error.what();
            }
        }
        ASSERT_TRUE(read.has_value()) << "call " << call << ": three tries failed; the last: " << last_error;
        ASSERT_EQ(read->wheel_encoder_count, 1000 + call) << "call " << call << " read an earlier exchange's response";
    }
    EXPECT_GE(failed_attempts, 60 * 2 / 7);
    EXPECT_EQ(slave_->statistics().bad_crc_frames, 0u) << "the master's requests were intact";
}

TEST_F(ModbusSlaveRtu, BadCrcIsIgnoredAndCounted) {
    mt::RawSerial line(pair_->master_end());
    Bytes bad = frame_rtu(1, Bytes{0x05, 0x00, 0x00, 0xFF, 0x00});  // would switch relay 1 on
    bad[bad.size() - 1] ^= 0x5A;
    line.write(bad);
    ASSERT_TRUE(mt::eventually([&] { return slave_->statistics().bad_crc_frames == 1; }));
    EXPECT_EQ(ask_until_answered(line, version_request(), 7), version_response())
        << "no answer to the bad frame may come before the good one's";
    EXPECT_TRUE(line.read_pending().empty());
    EXPECT_FALSE(slave_->actuator_commands().ball_valve_forward) << "a frame with a bad CRC was carried out";
    EXPECT_EQ(slave_->statistics().bad_crc_frames, 1u);
}

TEST_F(ModbusSlaveRtu, FrameForAnotherSlaveIsIgnored) {
    mt::RawSerial line(pair_->master_end());
    line.write(frame_rtu(2, Bytes{0x05, 0x00, 0x00, 0xFF, 0x00}));
    ASSERT_TRUE(mt::eventually([&] { return slave_->statistics().other_slave_frames == 1; }));
    EXPECT_EQ(ask_until_answered(line, version_request(), 7), version_response());
    EXPECT_FALSE(slave_->actuator_commands().ball_valve_forward);
}

TEST_F(ModbusSlaveRtu, UnknownFunctionGetsIllegalFunction) {
    mt::RawSerial line(pair_->master_end());
    EXPECT_EQ(ask_until_answered(line, frame_rtu(1, Bytes{0x2B, 0x0E, 0x01, 0x00}), 5),
              frame_rtu(1, Bytes{0xAB, 0x01}));
    EXPECT_EQ(ask_until_answered(line, frame_rtu(1, Bytes{0x04, 0x00, 0x0B, 0x00, 0x01}), 5),
              frame_rtu(1, Bytes{0x84, 0x02}));
    EXPECT_GE(slave_->statistics().illegal_function, 1u);
}

TEST_F(ModbusSlaveRtu, TruncatedFrameIsDroppedAndCounted) {
    mt::RawSerial line(pair_->master_end());
    const Bytes whole = version_request();
    line.write(Bytes(whole.begin(), whole.begin() + 5));
    ASSERT_TRUE(mt::eventually([&] { return slave_->statistics().malformed_frames == 1; }));
    EXPECT_EQ(ask_until_answered(line, version_request(), 7), version_response());
}

TEST_F(ModbusSlaveRtu, BroadcastWriteIsCarriedOutAndNotAnswered) {
    mt::RawSerial line(pair_->master_end());
    line.write(frame_rtu(0, Bytes{0x05, 0x00, 0x01, 0xFF, 0x00}));
    ASSERT_TRUE(mt::eventually([&] { return slave_->actuator_commands().ball_valve_reverse; }));
    EXPECT_EQ(ask_until_answered(line, version_request(), 7), version_response())
        << "a broadcast must not be answered";
    EXPECT_EQ(slave_->statistics().broadcast_requests, 1u);
}

TEST_F(ModbusSlaveRtu, DeviceInUseIsAClearError) {
    RtuSlaveOptions options;
    options.line.device = pair_->slave_end();
    const std::string message = what_of([&] { ModbusSlave second(options); });
    EXPECT_NE(message.find("serial device " + pair_->slave_end() + " is in use by another process"), std::string::npos)
        << message;
}

TEST(ModbusSlaveRtuErrors, MissingOrWrongDeviceAndBadSettings) {
    RtuSlaveOptions options;
    options.line.device = "/nonexistent/ttyRIG0";
    EXPECT_EQ(what_of([&] { ModbusSlave slave(options); }),
              "cannot open serial device /nonexistent/ttyRIG0: No such file or directory");
    options.line.device = "/dev/null";
    EXPECT_NE(what_of([&] { ModbusSlave slave(options); }).find("/dev/null is not a serial device"), std::string::npos);
    options.line.baud = 12345;
    EXPECT_THROW(ModbusSlave slave(options), std::invalid_argument);
    options.line.baud = 9600;
    options.slave_id = 0;
    EXPECT_NE(what_of([&] { ModbusSlave slave(options); }).find("slave id 0 for /dev/null outside 1..247"),
              std::string::npos);
}

// =============================================================== master errors

// A TCP slave that answers every request with what `respond` makes of its PDU.
class ScriptedTcpSlave {
public:
    explicit ScriptedTcpSlave(std::function<Bytes(const Bytes&)> respond) : respond_(std::move(respond)) {
        listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
        sockaddr_in address{};
        address.sin_family = AF_INET;
        address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        socklen_t length = sizeof address;
        ::bind(listen_fd_, reinterpret_cast<sockaddr*>(&address), sizeof address);
        ::listen(listen_fd_, 4);
        ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length);
        port_ = ntohs(address.sin_port);
        thread_ = std::thread([this] { serve(); });
    }
    ~ScriptedTcpSlave() {
        stop_ = true;
        thread_.join();
        ::close(listen_fd_);
    }
    std::uint16_t port() const { return port_; }

private:
    bool wait_readable(int fd) {
        while (!stop_) {
            pollfd fds{fd, POLLIN, 0};
            if (::poll(&fds, 1, 50) > 0) return true;
        }
        return false;
    }
    bool read_exactly(int fd, std::uint8_t* out, std::size_t count) {
        std::size_t got = 0;
        while (got < count && wait_readable(fd)) {
            const ssize_t n = ::recv(fd, out + got, count - got, 0);
            if (n <= 0) return false;
            got += static_cast<std::size_t>(n);
        }
        return got == count;
    }
    void serve() {
        if (!wait_readable(listen_fd_)) return;
        const int fd = ::accept(listen_fd_, nullptr, nullptr);
        std::uint8_t header[7];
        while (read_exactly(fd, header, 7)) {
            Bytes pdu(static_cast<std::size_t>((header[4] << 8 | header[5]) - 1));
            if (!read_exactly(fd, pdu.data(), pdu.size())) break;
            const Bytes response = respond_(pdu);
            Bytes adu{header[0], header[1], 0, 0, 0, static_cast<std::uint8_t>(response.size() + 1), header[6]};
            adu.insert(adu.end(), response.begin(), response.end());
            ::send(fd, adu.data(), adu.size(), MSG_NOSIGNAL);
        }
        ::close(fd);
    }

    std::function<Bytes(const Bytes&)> respond_;
    int listen_fd_ = -1;
    std::uint16_t port_ = 0;
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

ModbusMasterError master_error_of(const std::function<void()>& action) {
    try {
        action();
    } catch (const ModbusMasterError& error) {
        return error;
    }
    ADD_FAILURE() << "no ModbusMasterError";
    return ModbusMasterError(ModbusMasterError::Kind::io_error, "", "");
}

TEST(ModbusMasterErrors, RefusedConnectionIsClearAndQuick) {
    TcpMasterOptions options;
    options.slave.port = mt::unused_tcp_port();
    const WallStopwatch clock;
    const ModbusMasterError error = master_error_of([&] { ModbusMaster master(options, patient()); });
    EXPECT_LT(clock.elapsed(), kGenerous);
    EXPECT_EQ(error.kind(), ModbusMasterError::Kind::connect_failed);
    EXPECT_EQ(std::string(error.what()), "Modbus master tcp 127.0.0.1:" + std::to_string(options.slave.port) +
                                             " unit 1: cannot connect: Connection refused");
}

TEST(ModbusMasterErrors, SilentEndpointTimesOutInBoundedTime) {
    mt::SilentTcpListener silent;
    TcpMasterOptions options;
    options.slave.port = silent.port();
    ModbusMaster master(options, {300ms, 300ms});  // the kernel completes the handshake
    for (int call = 0; call < 2; ++call) {      // the second call reconnects and times out again
        const WallStopwatch clock;
        const ModbusMasterError error = master_error_of([&] { master.read_device_signals(); });
        EXPECT_LT(clock.elapsed(), kGenerous);
        EXPECT_EQ(error.kind(), ModbusMasterError::Kind::timeout);
        EXPECT_EQ(std::string(error.what()), "Modbus master tcp 127.0.0.1:" + std::to_string(silent.port()) +
                                                 " unit 1: read input registers 0..10 (FC 04): no response within 300 ms "
                                                 "(timeout)");
    }
}

TEST(ModbusMasterErrors, ExceptionResponseIsNamed) {
    ScriptedTcpSlave scripted([](const Bytes& pdu) { return Bytes{static_cast<std::uint8_t>(pdu[0] | 0x80), 0x02}; });
    TcpMasterOptions options;
    options.slave.port = scripted.port();
    ModbusMaster master(options, patient());
    const ModbusMasterError error = master_error_of([&] { master.write_actuator_commands(sample_commands()); });
    EXPECT_EQ(error.kind(), ModbusMasterError::Kind::exception_response);
    EXPECT_EQ(error.exception_code(), 2);
    EXPECT_EQ(std::string(error.what()), "Modbus master tcp 127.0.0.1:" + std::to_string(scripted.port()) +
                                             " unit 1: write coils 0..15 (FC 15): slave answered exception 02 ILLEGAL "
                                             "DATA ADDRESS");
    // An exception leaves the connection usable.
    EXPECT_EQ(master_error_of([&] { master.read_indicators(); }).kind(), ModbusMasterError::Kind::exception_response);
}

TEST(ModbusMasterErrors, OtherMapVersionIsRefused) {
    // A slave that says map version 2 (no encoder capture) in register 6 of an
    // 11-register answer: this master speaks 3 and refuses it.
    ScriptedTcpSlave scripted([](const Bytes&) {
        return Bytes{0x04, 22, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0};
    });
    TcpMasterOptions options;
    options.slave.port = scripted.port();
    ModbusMaster master(options, patient());
    const ModbusMasterError error = master_error_of([&] { master.read_device_signals(); });
    EXPECT_EQ(error.kind(), ModbusMasterError::Kind::map_mismatch);
    EXPECT_NE(std::string(error.what()).find("slave serves register map version 2, this master speaks version 3"),
              std::string::npos);
}

TEST(ModbusMasterErrors, NonLoopbackSlaveIsRefusedBeforeAnyTraffic) {
    TcpMasterOptions options;
    options.slave.address = "10.1.2.3";
    const std::string message = what_of([&] { ModbusMaster master(options); });
    EXPECT_NE(message.find("10.1.2.3:1502 is not loopback"), std::string::npos) << message;
}

TEST(ModbusMasterErrors, MissingSerialDevice) {
    RtuMasterOptions options;
    options.line.device = "/nonexistent/ttyRIG0";
    const ModbusMasterError error = master_error_of([&] { ModbusMaster master(options); });
    EXPECT_EQ(error.kind(), ModbusMasterError::Kind::connect_failed);
    EXPECT_EQ(std::string(error.what()),
              "Modbus master rtu /nonexistent/ttyRIG0 115200 8N1 slave 1: cannot connect: No such file or directory");
}

TEST(ModbusMasterErrors, SilentSerialLineTimesOut) {
    ASSERT_TRUE(mt::require_tool("socat"));
    mt::PtyPair pair("silent-line");  // nobody on the other end
    RtuMasterOptions options;
    options.line.device = pair.master_end();
    ModbusMaster master(options, {300ms, 300ms});
    const WallStopwatch clock;
    const ModbusMasterError error = master_error_of([&] { master.write_indicators({}); });
    EXPECT_LT(clock.elapsed(), kGenerous);
    EXPECT_EQ(error.kind(), ModbusMasterError::Kind::timeout);
    EXPECT_EQ(std::string(error.what()), "Modbus master rtu " + pair.master_end() +
                                             " 115200 8N1 slave 1: write holding registers 0..2 (FC 16): no response "
                                             "within 300 ms (timeout)");
}

}  // namespace
}  // namespace rig::modbus

namespace rig::modbus {
namespace {

// Waits (bounded far above the fail-safe timeout) until the slave's watchdog has tripped.
bool wait_for_failsafe(const ModbusSlave& slave) {
    const RealtimeClock clock;
    while (!slave.failsafe_active()) {
        if (clock.now_ns() > seconds_to_ns(10.0)) return false;
        clock.sleep_until_ns(clock.now_ns() + seconds_to_ns(0.01));
    }
    return true;
}

// The comms-loss watchdog (docs/modbus-register-map.md "External boards"): after
// the last valid request, `safe` de-energises every coil and tells it like a write;
// a new request re-arms it without restoring the coils.
TEST(ModbusSlaveFailsafe, SafeModeDeEnergisesTheCoilsAfterTheLastRequest) {
    std::atomic<int> commands_changed{0};
    ModbusSlaveCallbacks callbacks;
    callbacks.on_master_write = [&](const MasterWrite& write) { commands_changed += write.commands_changed ? 1 : 0; };
    TcpSlaveOptions options = any_port();
    options.failsafe = {std::chrono::milliseconds(100), FailsafeMode::safe};
    ModbusSlave slave(options, callbacks);
    EXPECT_FALSE(slave.since_last_request().has_value());
    // Not armed before the first request: a board not yet attached trips nothing.
    ModbusMaster master(master_for(slave), patient());
    master.write_actuator_commands(sample_commands());
    ASSERT_TRUE(slave.since_last_request().has_value());
    ASSERT_TRUE(wait_for_failsafe(slave));
    EXPECT_EQ(slave.actuator_commands(), io::ActuatorCommands{});
    EXPECT_EQ(slave.statistics().failsafe_trips, 1u);
    EXPECT_EQ(commands_changed.load(), 2);  // the write, then the fail-safe
    EXPECT_NE(slave.statistics().last_problem.find("comms-loss fail-safe (safe)"), std::string::npos);
    // A read re-arms it; the master reads back what the fail-safe left.
    EXPECT_EQ(master.read_actuator_commands(), io::ActuatorCommands{});
    ASSERT_TRUE(wait_for_failsafe(slave));  // tripped again: the read had re-armed it
    EXPECT_EQ(slave.statistics().failsafe_trips, 2u);
}

TEST(ModbusSlaveFailsafe, HoldModeKeepsTheCoilsAndCountsTheTrip) {
    TcpSlaveOptions options = any_port();
    options.failsafe = {std::chrono::milliseconds(100), FailsafeMode::hold};
    ModbusSlave slave(options);
    ModbusMaster master(master_for(slave), patient());
    master.write_actuator_commands(sample_commands());
    ASSERT_TRUE(wait_for_failsafe(slave));
    EXPECT_EQ(slave.actuator_commands(), sample_commands());
    EXPECT_EQ(slave.statistics().failsafe_trips, 1u);
    EXPECT_EQ(slave.statistics().valid_requests, 1u);
}

TEST(ModbusSlaveFailsafe, OffByDefaultAndANegativeTimeoutIsRefused) {
    EXPECT_EQ(TcpSlaveOptions{}.failsafe.timeout.count(), 0);
    TcpSlaveOptions options = any_port();
    options.failsafe.timeout = std::chrono::milliseconds(-1);
    EXPECT_THROW(ModbusSlave{options}, std::invalid_argument);
}

}  // namespace
}  // namespace rig::modbus
