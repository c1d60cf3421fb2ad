// `rig modbus serve` end to end: the real executable serves over TCP (port 0,
// the chosen port read from its first line) and over RTU (a socat pty pair);
// our master reads the synthetic inputs advancing with wall time, writes
// outputs, and the test checks the one line per change the command prints;
// SIGINT ends it with status 0. Plus the synthetic source's arithmetic and
// the option errors.
#include <gtest/gtest.h>

#include <signal.h>

#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "harness/bench/bench_modbus.h"
#include "rig/wire/modbus_register_map.h"
#include "modbus_test_support.h"
#include "rig/host/child_process.h"
#include "rig/wire/modbus_master.h"

namespace rig::harness {
namespace {

using namespace std::chrono_literals;
namespace mt = rig::modbus::testing;

const std::string kRig = RIG_BINARY_DIR "/bin/rig";

std::string read_file(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

std::vector<std::string> lines_containing(const std::string& text, const std::string& needle) {
    std::vector<std::string> found;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) {
        if (line.find(needle) != std::string::npos) found.push_back(line);
    }
    return found;
}

TEST(ModbusServeSynthetic, CountsFollowTheWheelAndFlowEquations) {
    ModbusServeOptions options;
    options.speed_km_h = 3.6;                      // 1 m/s
    options.wheel_diameter_m = 1.0 / std::acos(-1.0);  // circumference 1 m
    options.pulses_per_rev = 1000;
    options.flow_l_min = 60;                       // 1 L/s
    options.pulses_per_l = 90;
    options.pump_flow_adc = 1234;
    options.spray_switch = true;
    const io::DeviceSignals at_start = synthetic_device_signals(options, 0.0);
    EXPECT_EQ(at_start.wheel_encoder_count, 0u);
    EXPECT_EQ(at_start.main_flow_pulses, 0u);
    const io::DeviceSignals later = synthetic_device_signals(options, 2.5);
    EXPECT_NEAR(later.wheel_encoder_count, 2500, 1);
    EXPECT_NEAR(later.main_flow_pulses, 225, 1);
    EXPECT_EQ(later.pump_flow_adc, 1234);
    EXPECT_TRUE(later.spray_switch);
    EXPECT_FALSE(later.breakpoint_button);
    // 32-bit counters wrap: at 1000 pulses/s, 2^32 pulses after ~49.7 days.
    const double wrap_s = 4294967296.0 / 1000.0;
    EXPECT_NEAR(synthetic_device_signals(options, wrap_s + 1.0).wheel_encoder_count, 1000, 2);
}

TEST(ModbusServeSynthetic, OptionProblemsNameTheOption) {
    ModbusServeOptions options;
    EXPECT_EQ(modbus_serve_options_problem(options), "");
    options.wheel_diameter_m = 0;
    EXPECT_EQ(modbus_serve_options_problem(options), "--wheel-diameter-m must be > 0");
    options = {};
    options.pump_flow_adc = 4096;
    EXPECT_EQ(modbus_serve_options_problem(options), "--pump-flow-adc must be 0..4095");
    options = {};
    options.tcp = "127.0.0.1";
    EXPECT_NE(modbus_serve_options_problem(options).find("--tcp: TCP endpoint '127.0.0.1' is not ADDRESS:PORT"),
              std::string::npos);
    options = {};
    options.rtu_device = "/dev/ttyUSB0";
    options.parity = "X";
    EXPECT_NE(modbus_serve_options_problem(options).find("--parity"), std::string::npos);
    options = {};
    options.failsafe_timeout_s = 0.001;  // shorter than any master's poll period
    EXPECT_EQ(modbus_serve_options_problem(options), "--failsafe-timeout-s must be 0 (off) or 0.01..3600");
    options = {};
    options.failsafe_timeout_s = 1.0;
    EXPECT_EQ(modbus_serve_options_problem(options), "");
    options.failsafe = "latch";
    EXPECT_EQ(modbus_serve_options_problem(options), "--failsafe must be safe or hold");
}

// The running command, its log, and a way to wait for a line in it.
class ServeProcess {
public:
    ServeProcess(const std::string& name, std::vector<std::string> arguments) : dir_(mt::fresh_dir(name)) {
        std::vector<std::string> argv{kRig, "modbus", "serve"};
        argv.insert(argv.end(), arguments.begin(), arguments.end());
        process_ = std::make_unique<ChildProcess>(argv, log_path());
    }
    std::filesystem::path log_path() const { return dir_ / "serve.log"; }
    std::string log() const { return read_file(log_path()); }
    // The port it chose for --tcp 127.0.0.1:0, from its first line.
    std::optional<std::uint16_t> tcp_port() const {
        const std::string text = log();
        const std::string marker = "on tcp 127.0.0.1:";
        const auto at = text.find(marker);
        if (at == std::string::npos) return std::nullopt;
        return static_cast<std::uint16_t>(std::stoi(text.substr(at + marker.size())));
    }
    bool wait_for(const std::string& text, std::size_t count = 1) const {
        return mt::eventually([&] { return lines_containing(log(), text).size() >= count; }, 20s);
    }
    // SIGINT, then how it ended.
    std::string interrupt() {
        ::kill(process_->pid(), SIGINT);
        return process_->stop(10000ms);
    }

private:
    std::filesystem::path dir_;
    std::unique_ptr<ChildProcess> process_;
};

TEST(ModbusServeCommand, ServesTcpPrintsEveryChangeAndStopsOnSigint) {
    ServeProcess serve("serve-tcp", {"--tcp", "127.0.0.1:0", "--speed-km-h", "6", "--wheel-diameter-m", "1.0",
                                     "--pulses-per-rev", "1000", "--flow-l-min", "20", "--pulses-per-l", "90",
                                     "--pump-flow-adc", "1000", "--spray-switch"});
    ASSERT_TRUE(serve.wait_for("serving register map v" + std::to_string(rig::modbus::kRegisterMapVersion) + " on tcp 127.0.0.1:")) << serve.log();
    const std::optional<std::uint16_t> port = serve.tcp_port();
    ASSERT_TRUE(port) << serve.log();
    modbus::TcpMasterOptions options;
    options.slave.port = *port;
    modbus::ModbusMaster master(options, {5000ms, 2000ms});

    const io::DeviceSignals first = master.read_device_signals();
    EXPECT_EQ(first.pump_flow_adc, 1000);
    EXPECT_TRUE(first.spray_switch);
    EXPECT_FALSE(first.breakpoint_button);
    // Counts advance with wall time (6 km/h on a 1 m wheel: ~531 pulses/s; 20 L/min: 30 pulses/s).
    ASSERT_TRUE(mt::eventually([&] {
        const io::DeviceSignals now = master.read_device_signals();
        return now.wheel_encoder_count > first.wheel_encoder_count && now.main_flow_pulses > first.main_flow_pulses;
    }));

    io::ActuatorCommands commands;
    commands.ball_valve_forward = true;
    commands.section_valves_open = 0b0000'0011;
    master.write_actuator_commands(commands);
    master.write_actuator_commands(commands);  // no change: no line
    io::ControllerIndicators indicators;
    indicators.breakpoints_stored = 1;
    indicators.breakpoint_pending = true;
    master.write_indicators(indicators);
    commands.ball_valve_forward = false;
    master.write_actuator_commands(commands);

    ASSERT_TRUE(serve.wait_for("actuator_commands", 2)) << serve.log();
    ASSERT_TRUE(serve.wait_for("controller_indicators")) << serve.log();
    EXPECT_EQ(serve.interrupt(), "process exited with status 0");
    const std::string final_log = serve.log();
    const auto command_lines = lines_containing(final_log, "actuator_commands");
    ASSERT_EQ(command_lines.size(), 2u) << final_log;
    const std::string expected_tail =
        "s actuator_commands ball_valve_forward=1 ball_valve_reverse=0 unloading_valve_open=0 "
        "section_valves_open=0b00000011";
    EXPECT_EQ(command_lines[0].rfind("t=", 0), 0u) << command_lines[0];
    EXPECT_TRUE(command_lines[0].ends_with(expected_tail)) << command_lines[0];
    EXPECT_NE(command_lines[1].find("ball_valve_forward=0"), std::string::npos) << command_lines[1];
    const auto indicator_lines = lines_containing(final_log, "controller_indicators");
    ASSERT_EQ(indicator_lines.size(), 1u) << final_log;
    EXPECT_NE(indicator_lines[0].find("controller_indicators breakpoints_stored=1 breakpoints_reached=0 "
                                      "breakpoint_pending=1 odometer_active=0"),
              std::string::npos)
        << indicator_lines[0];
    EXPECT_NE(final_log.find("rig modbus serve: stopped; answered"), std::string::npos) << final_log;
}

// A board left on the bench that stops polling: with --failsafe-timeout-s the
// coils are de-energised (safe), the trip is printed and counted, and they stay
// so until the master writes them again.
TEST(ModbusServeCommand, TheCommsLossFailsafeDeEnergisesTheCoilsOfAQuietMaster) {
    ServeProcess serve("serve-failsafe", {"--tcp", "127.0.0.1:0", "--failsafe-timeout-s", "0.2", "--failsafe", "safe"});
    ASSERT_TRUE(serve.wait_for("; comms-loss fail-safe safe after 200 ms; Ctrl-C stops")) << serve.log();
    const std::optional<std::uint16_t> port = serve.tcp_port();
    ASSERT_TRUE(port) << serve.log();
    modbus::TcpMasterOptions options;
    options.slave.port = *port;
    modbus::ModbusMaster master(options, {5000ms, 2000ms});

    io::ActuatorCommands commands;
    commands.ball_valve_forward = true;
    commands.section_valves_open = 0b0000'0111;
    master.write_actuator_commands(commands);
    // The master goes quiet; the watchdog trips 200 ms after its last request.
    ASSERT_TRUE(serve.wait_for("no valid request for 200 ms: comms-loss fail-safe (safe)")) << serve.log();
    const io::ActuatorCommands after = master.read_actuator_commands();
    EXPECT_FALSE(after.ball_valve_forward);
    EXPECT_EQ(after.section_valves_open, 0);
    // Writing again restores them.
    master.write_actuator_commands(commands);
    EXPECT_EQ(master.read_actuator_commands().section_valves_open, 0b0000'0111);
    EXPECT_EQ(serve.interrupt(), "process exited with status 0");
    EXPECT_NE(serve.log().find("fail-safe trips: "), std::string::npos) << serve.log();
    EXPECT_EQ(lines_containing(serve.log(), "fail-safe trips: 0").size(), 0u) << serve.log();
}

TEST(ModbusServeCommand, ServesRtuWithTheGivenLineSettings) {
    ASSERT_TRUE(mt::require_tool("socat"));
    mt::PtyPair pair("serve-rtu");
    ServeProcess serve("serve-rtu-log", {"--rtu", pair.slave_end(), "--baud", "57600", "--parity", "E",
                                         "--slave-id", "7", "--breakpoint-button", "--boom-height-adc", "4095"});
    ASSERT_TRUE(serve.wait_for("serving register map v" + std::to_string(rig::modbus::kRegisterMapVersion) + " on rtu " + pair.slave_end() + " 57600 8E1 slave 7"))
        << serve.log();
    modbus::RtuMasterOptions options;
    options.line.device = pair.master_end();
    options.line.baud = 57600;
    options.line.parity = modbus::Parity::even;
    options.slave_id = 7;
    modbus::ModbusMaster master(options, {5000ms, 2000ms});
    const io::DeviceSignals signals = master.read_device_signals();
    EXPECT_TRUE(signals.breakpoint_button);
    EXPECT_EQ(signals.boom_height_adc, 4095);
    EXPECT_EQ(signals.wheel_encoder_count, 0u);  // speed 0 by default
    io::ActuatorCommands commands;
    commands.unloading_valve_open = true;
    master.write_actuator_commands(commands);
    ASSERT_TRUE(serve.wait_for("actuator_commands")) << serve.log();
    EXPECT_NE(serve.log().find("unloading_valve_open=1"), std::string::npos);
    EXPECT_EQ(serve.interrupt(), "process exited with status 0");
}

TEST(ModbusServeCommand, BadOptionsAndMissingDevicesAreClearErrors) {
    mt::CommandResult result = mt::run_command("'" + kRig + "' modbus serve --tcp 127.0.0.1");
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_NE(result.output.find("rig modbus serve: --tcp: TCP endpoint '127.0.0.1' is not ADDRESS:PORT"),
              std::string::npos)
        << result.output;

    result = mt::run_command("'" + kRig + "' modbus serve --tcp 0.0.0.0:1502");
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_NE(result.output.find("'0.0.0.0' is not loopback"), std::string::npos) << result.output;

    result = mt::run_command("'" + kRig + "' modbus serve --rtu /nonexistent/ttyRIG0");
    EXPECT_EQ(result.exit_code, 1) << result.output;
    EXPECT_NE(result.output.find("rig modbus serve: cannot open serial device /nonexistent/ttyRIG0: No such file or "
                                 "directory"),
              std::string::npos)
        << result.output;

    result = mt::run_command("'" + kRig + "' modbus serve --tcp 127.0.0.1:1 --rtu /dev/ttyUSB0");
    EXPECT_NE(result.exit_code, 0) << result.output;
    EXPECT_NE(result.output.find("excludes"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace rig::harness
