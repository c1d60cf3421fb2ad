// The Debian tool mbpoll, a Modbus master nobody here wrote, against our
// ModbusSlave: over TCP on 127.0.0.1 and over RTU through a socat pty pair it
// reads the input registers (16-bit, and as 32-bit big-endian-word integers,
// which checks the word order independently) and the discrete inputs, writes
// coils and holding registers with single and multiple writes, and sees our
// exceptions. The test checks the values mbpoll prints and what the slave got.
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <sstream>
#include <string>

#include "modbus_test_support.h"
#include "rig/wire/modbus_slave.h"

namespace rig::modbus {
namespace {

namespace mt = rig::modbus::testing;

// mbpoll prints one "[reference]: <tab>value" line per value. (Parsed by
// hand: <regex> trips GCC 12's -Wmaybe-uninitialized in the sanitizer build.)
std::map<int, long long> printed_values(const std::string& output) {
    std::map<int, long long> values;
    std::istringstream lines(output);
    for (std::string line; std::getline(lines, line);) {
        const auto close = line.find("]:");
        if (line.empty() || line[0] != '[' || close == std::string::npos) continue;
        try {
            values[std::stoi(line.substr(1, close - 1))] = std::stoll(line.substr(close + 2));
        } catch (const std::exception&) {
            // not a value line
        }
    }
    return values;
}

io::DeviceSignals served_signals() {
    io::DeviceSignals signals;
    signals.wheel_encoder_count = 0x12345678;  // registers 0x1234, 0x5678
    signals.main_flow_pulses = 123456;         // registers 0x0001, 0xE240
    signals.wheel_encoder_last_edge_us = 70000;  // registers 0x0001, 0x1170
    signals.pump_flow_adc = 2048;
    signals.boom_height_adc = 310;
    signals.breakpoint_button = false;
    signals.spray_switch = true;
    return signals;
}

// Runs mbpoll (PDU addressing, one poll, 5 s timeout) on the fixture's wire,
// e.g. mbpoll("-t 3 -r 0 -c 7") to read, mbpoll("-t 0 -r 8", "1 0 1") to write
// (mbpoll wants the values after the host or device).
class MbpollPeer {
public:
    virtual ~MbpollPeer() = default;
    mt::CommandResult mbpoll(const std::string& options, const std::string& values = "") const {
        return mt::run_command("mbpoll -a 1 -0 -1 -o 5 " + options + " " + wire_options() + " " + target() + " " + values);
    }
    virtual std::string wire_options() const = 0;
    virtual std::string target() const = 0;  // host or serial device
};

void check_reads(const MbpollPeer& peer) {
    const mt::CommandResult registers = peer.mbpoll("-t 3 -r 0 -c 11");
    ASSERT_EQ(registers.exit_code, 0) << registers.output;
    const std::map<int, long long> expected{{0, 0x1234}, {1, 0x5678}, {2, 0x0001}, {3, 0xE240},
                                            {4, 2048},   {5, 310},    {6, kRegisterMapVersion},
                                            {7, 0},      {8, 0},      {9, 0x0001}, {10, 0x1170}};
    EXPECT_EQ(printed_values(registers.output), expected) << registers.output;

    const mt::CommandResult counters = peer.mbpoll("-t 3:int -B -r 0 -c 2");
    ASSERT_EQ(counters.exit_code, 0) << counters.output;
    EXPECT_EQ(printed_values(counters.output), (std::map<int, long long>{{0, 0x12345678}, {2, 123456}}))
        << counters.output;

    const mt::CommandResult inputs = peer.mbpoll("-t 1 -r 0 -c 2");
    ASSERT_EQ(inputs.exit_code, 0) << inputs.output;
    EXPECT_EQ(printed_values(inputs.output), (std::map<int, long long>{{0, 0}, {1, 1}})) << inputs.output;
}

void check_writes(const MbpollPeer& peer, const ModbusSlave& slave) {
    // FC 15: relays forward and unloading on, reverse off.
    mt::CommandResult result = peer.mbpoll("-t 0 -r 0", "1 0 1");
    ASSERT_EQ(result.exit_code, 0) << result.output;
    io::ActuatorCommands commands = slave.actuator_commands();
    EXPECT_TRUE(commands.ball_valve_forward);
    EXPECT_FALSE(commands.ball_valve_reverse);
    EXPECT_TRUE(commands.unloading_valve_open);
    // FC 15: sections 1, 3, 4 and 8.
    result = peer.mbpoll("-t 0 -r 8", "1 0 1 1 0 0 0 1");
    ASSERT_EQ(result.exit_code, 0) << result.output;
    EXPECT_EQ(slave.actuator_commands().section_valves_open, 0b1000'1101);
    // FC 05: one coil, relay 1 off.
    result = peer.mbpoll("-t 0 -r 0", "0");
    ASSERT_EQ(result.exit_code, 0) << result.output;
    EXPECT_FALSE(slave.actuator_commands().ball_valve_forward);
    EXPECT_TRUE(slave.actuator_commands().unloading_valve_open);
    // FC 16 then FC 06: indicators.
    result = peer.mbpoll("-t 4 -r 0", "3 5 2");
    ASSERT_EQ(result.exit_code, 0) << result.output;
    io::ControllerIndicators indicators = slave.indicators();
    EXPECT_EQ(indicators.breakpoints_stored, 3);
    EXPECT_EQ(indicators.breakpoints_reached, 5);
    EXPECT_FALSE(indicators.breakpoint_pending);
    EXPECT_TRUE(indicators.odometer_active);
    result = peer.mbpoll("-t 4 -r 2", "1");
    ASSERT_EQ(result.exit_code, 0) << result.output;
    EXPECT_TRUE(slave.indicators().breakpoint_pending);
    EXPECT_FALSE(slave.indicators().odometer_active);
    EXPECT_EQ(slave.master_write_count(), 5u);
    // mbpoll reads back what it wrote.
    const mt::CommandResult coils = peer.mbpoll("-t 0 -r 8 -c 8");
    ASSERT_EQ(coils.exit_code, 0) << coils.output;
    EXPECT_EQ(printed_values(coils.output),
              (std::map<int, long long>{{8, 1}, {9, 0}, {10, 1}, {11, 1}, {12, 0}, {13, 0}, {14, 0}, {15, 1}}));
}

void check_exceptions(const MbpollPeer& peer, const ModbusSlave& slave) {
    const auto before = slave.statistics();
    const mt::CommandResult reserved = peer.mbpoll("-t 0 -r 4", "1");
    EXPECT_NE(reserved.exit_code, 0);
    EXPECT_NE(reserved.output.find("Illegal data value"), std::string::npos) << reserved.output;
    const mt::CommandResult outside = peer.mbpoll("-t 3 -r 11 -c 1");
    EXPECT_NE(outside.exit_code, 0);
    EXPECT_NE(outside.output.find("Illegal data address"), std::string::npos) << outside.output;
    const auto after = slave.statistics();
    EXPECT_EQ(after.illegal_data_value, before.illegal_data_value + 1);
    EXPECT_EQ(after.illegal_data_address, before.illegal_data_address + 1);
}

class MbpollTcp : public ::testing::Test, public MbpollPeer {
protected:
    void SetUp() override {
        ASSERT_TRUE(mt::require_tool("mbpoll"));
        TcpSlaveOptions options;
        options.port = 0;
        slave_ = std::make_unique<ModbusSlave>(options);
        slave_->set_device_signals(served_signals());
    }
    std::string wire_options() const override { return "-m tcp -p " + std::to_string(slave_->tcp_port()); }
    std::string target() const override { return "127.0.0.1"; }
    std::unique_ptr<ModbusSlave> slave_;
};

TEST_F(MbpollTcp, ReadsInputRegistersAndDiscreteInputs) { check_reads(*this); }
TEST_F(MbpollTcp, WritesCoilsAndHoldingRegisters) { check_writes(*this, *slave_); }
TEST_F(MbpollTcp, SeesOurExceptions) { check_exceptions(*this, *slave_); }

class MbpollRtu : public ::testing::Test, public MbpollPeer {
protected:
    void SetUp() override {
        ASSERT_TRUE(mt::require_tool("mbpoll"));
        ASSERT_TRUE(mt::require_tool("socat"));
        pair_ = std::make_unique<mt::PtyPair>(std::string("mbpoll-") +
                                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
        RtuSlaveOptions options;
        options.line.device = pair_->slave_end();
        options.line.baud = 115200;
        options.slave_id = 1;
        slave_ = std::make_unique<ModbusSlave>(options);
        slave_->set_device_signals(served_signals());
    }
    // mbpoll's default parity is even: say none, as the slave has.
    std::string wire_options() const override { return "-m rtu -b 115200 -P none"; }
    std::string target() const override { return pair_->master_end(); }
    std::unique_ptr<mt::PtyPair> pair_;
    std::unique_ptr<ModbusSlave> slave_;
};

TEST_F(MbpollRtu, ReadsInputRegistersAndDiscreteInputs) {
    check_reads(*this);
    EXPECT_EQ(slave_->statistics().bad_crc_frames, 0u);
}
TEST_F(MbpollRtu, WritesCoilsAndHoldingRegisters) { check_writes(*this, *slave_); }
TEST_F(MbpollRtu, SeesOurExceptions) { check_exceptions(*this, *slave_); }

}  // namespace
}  // namespace rig::modbus
