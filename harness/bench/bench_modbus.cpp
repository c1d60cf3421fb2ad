#include "harness/bench/bench_modbus.h"

#include <CLI/CLI.hpp>

#include <signal.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <mutex>
#include <numbers>
#include <optional>

#include "rig/runtime/clock.h"
#include "rig/wire/modbus_slave.h"
#include "rig/text/number_text.h"

namespace rig::harness {
namespace {

// The main loop looks at the stop flag at least this often, whatever the update rate.
constexpr TimeNs kMaxSleepNs = 50'000'000;

std::uint32_t wrapped_count(double count) {
    // Counters on the board are 32-bit and wrap; so does the register pair.
    constexpr double kWrap = 4294967296.0;
    const double wrapped = std::fmod(std::floor(count), kWrap);
    return static_cast<std::uint32_t>(wrapped < 0 ? wrapped + kWrap : wrapped);
}

std::string seconds_text(TimeNs ns) { return fixed_text(ns_to_seconds(ns), 3); }

std::string commands_line(const io::ActuatorCommands& commands) {
    std::string sections;
    for (int bit = 7; bit >= 0; --bit) sections += ((commands.section_valves_open >> bit) & 1u) != 0 ? '1' : '0';
    return "actuator_commands ball_valve_forward=" + std::to_string(commands.ball_valve_forward ? 1 : 0) +
           " ball_valve_reverse=" + std::to_string(commands.ball_valve_reverse ? 1 : 0) +
           " unloading_valve_open=" + std::to_string(commands.unloading_valve_open ? 1 : 0) +
           " section_valves_open=0b" + sections;
}

std::string indicators_line(const io::ControllerIndicators& indicators) {
    return "controller_indicators breakpoints_stored=" + std::to_string(indicators.breakpoints_stored) +
           " breakpoints_reached=" + std::to_string(indicators.breakpoints_reached) +
           " breakpoint_pending=" + std::to_string(indicators.breakpoint_pending ? 1 : 0) +
           " odometer_active=" + std::to_string(indicators.odometer_active ? 1 : 0);
}

std::string summary_line(const modbus::ModbusSlaveStatistics& stats) {
    return "answered " + std::to_string(stats.requests_answered) + " requests, " +
           std::to_string(stats.master_writes) + " writes; exceptions: " + std::to_string(stats.illegal_function) +
           " illegal function, " + std::to_string(stats.illegal_data_address) + " illegal data address, " +
           std::to_string(stats.illegal_data_value) + " illegal data value; dropped: " +
           std::to_string(stats.malformed_frames) + " malformed, " + std::to_string(stats.bad_crc_frames) +
           " bad CRC, " + std::to_string(stats.other_slave_frames) + " for other slaves; fail-safe trips: " +
           std::to_string(stats.failsafe_trips);
}

std::atomic<bool> g_stop_signalled{false};

extern "C" void on_stop_signal(int) { g_stop_signalled = true; }

}  // namespace

io::DeviceSignals synthetic_device_signals(const ModbusServeOptions& options, double elapsed_s) {
    io::DeviceSignals signals;
    const double distance_m = options.speed_km_h / 3.6 * elapsed_s;
    const double wheel_revolutions = distance_m / (std::numbers::pi * options.wheel_diameter_m);
    signals.wheel_encoder_count = wrapped_count(wheel_revolutions * options.pulses_per_rev);
    const double litres = options.flow_l_min / 60.0 * elapsed_s;
    signals.main_flow_pulses = wrapped_count(litres * options.pulses_per_l);
    signals.pump_flow_adc = static_cast<std::uint16_t>(options.pump_flow_adc);
    signals.boom_height_adc = static_cast<std::uint16_t>(options.boom_height_adc);
    signals.spray_switch = options.spray_switch;
    signals.breakpoint_button = options.breakpoint_button;
    return signals;
}

std::string modbus_serve_options_problem(const ModbusServeOptions& options) {
    const auto finite_at_least = [](double value, double minimum) { return std::isfinite(value) && value >= minimum; };
    if (!finite_at_least(options.speed_km_h, 0.0)) return "--speed-km-h must be >= 0";
    if (!finite_at_least(options.flow_l_min, 0.0)) return "--flow-l-min must be >= 0";
    if (!(finite_at_least(options.wheel_diameter_m, 0.0) && options.wheel_diameter_m > 0.0)) {
        return "--wheel-diameter-m must be > 0";
    }
    if (!(finite_at_least(options.pulses_per_rev, 0.0) && options.pulses_per_rev > 0.0)) {
        return "--pulses-per-rev must be > 0";
    }
    if (!(finite_at_least(options.pulses_per_l, 0.0) && options.pulses_per_l > 0.0)) return "--pulses-per-l must be > 0";
    if (options.pump_flow_adc < 0 || options.pump_flow_adc > io::kAdcFullScale) {
        return "--pump-flow-adc must be 0.." + std::to_string(io::kAdcFullScale);
    }
    if (options.boom_height_adc < 0 || options.boom_height_adc > io::kAdcFullScale) {
        return "--boom-height-adc must be 0.." + std::to_string(io::kAdcFullScale);
    }
    if (!(finite_at_least(options.update_hz, 1.0) && options.update_hz <= 1000.0)) return "--update-hz must be 1..1000";
    // Up to an hour: beyond it a watchdog protects nothing; below 10 ms it trips between two polls of any master.
    if (!(std::isfinite(options.failsafe_timeout_s) &&
          (options.failsafe_timeout_s == 0.0 || (options.failsafe_timeout_s >= 0.01 && options.failsafe_timeout_s <= 3600.0)))) {
        return "--failsafe-timeout-s must be 0 (off) or 0.01..3600";
    }
    if (options.failsafe != "safe" && options.failsafe != "hold") return "--failsafe must be safe or hold";
    if (options.rtu_device.empty()) {
        try {
            modbus::parse_tcp_endpoint(options.tcp);
        } catch (const std::exception& error) {
            return std::string("--tcp: ") + error.what();
        }
        return {};
    }
    try {
        modbus::parse_parity(options.parity);
    } catch (const std::exception& error) {
        return std::string("--parity: ") + error.what();
    }
    if (options.slave_id < 1 || options.slave_id > 247) return "--slave-id must be 1..247";
    return {};
}

ModbusCommand::ModbusCommand(CLI::App& app) {
    auto* modbus = app.add_subcommand("modbus", "Modbus bench wire tools");
    modbus->require_subcommand(1);
    ModbusServeOptions& options = options_;
    auto* serve = modbus->add_subcommand(
        "serve", "serve the Modbus register map as a slave (TCP or RTU) with synthetic board inputs; "
                 "prints every change the master writes; Ctrl-C stops");
    auto* tcp = serve->add_option("--tcp", options.tcp, "ADDRESS:PORT to listen on (port 0: any free port)")
                    ->capture_default_str();
    serve->add_flag("--allow-non-loopback", options.allow_non_loopback,
                    "allow a --tcp address outside 127.0.0.0/8 (a bench with a board on Ethernet)");
    serve->add_option("--rtu", options.rtu_device, "serve Modbus RTU on this serial device instead of TCP")
        ->excludes(tcp);
    serve->add_option("--baud", options.baud, "RTU baud rate")->capture_default_str();
    serve->add_option("--parity", options.parity, "RTU parity: N, E or O")->capture_default_str();
    serve->add_option("--data-bits", options.data_bits, "RTU data bits (7 or 8)")->capture_default_str();
    serve->add_option("--stop-bits", options.stop_bits, "RTU stop bits (1 or 2)")->capture_default_str();
    serve->add_option("--slave-id", options.slave_id, "RTU slave id (1..247)")->capture_default_str();
    serve->add_option("--speed-km-h", options.speed_km_h, "vehicle speed driving the wheel encoder count")
        ->capture_default_str();
    serve->add_option("--wheel-diameter-m", options.wheel_diameter_m, "land wheel diameter")->capture_default_str();
    serve->add_option("--pulses-per-rev", options.pulses_per_rev, "wheel encoder pulses per revolution")
        ->capture_default_str();
    serve->add_option("--flow-l-min", options.flow_l_min, "main-pipeline flow driving the flow meter pulses")
        ->capture_default_str();
    serve->add_option("--pulses-per-l", options.pulses_per_l, "flow meter pulses per litre")->capture_default_str();
    serve->add_option("--pump-flow-adc", options.pump_flow_adc, "pump flow sensor ADC count (0..4095)")
        ->capture_default_str();
    serve->add_option("--boom-height-adc", options.boom_height_adc, "boom height sensor ADC count (0..4095)")
        ->capture_default_str();
    serve->add_flag("--spray-switch", options.spray_switch, "spray switch on");
    serve->add_flag("--breakpoint-button", options.breakpoint_button, "breakpoint button held pressed");
    serve->add_option("--update-hz", options.update_hz, "how often the served counts advance")->capture_default_str();
    serve->add_option("--failsafe-timeout-s", options.failsafe_timeout_s,
                      "comms-loss watchdog: this long after the last valid request the coils go to --failsafe (0 = off)")
        ->capture_default_str();
    serve->add_option("--failsafe", options.failsafe,
                      "what the watchdog does: safe (every coil de-energised) or hold (only counted)")
        ->capture_default_str();
    serve_ = serve;
}

bool ModbusCommand::parsed() const { return serve_->parsed(); }

int serve_modbus(const ModbusServeOptions& options, std::ostream& out, std::ostream& err,
                 const std::atomic<bool>& stop_requested) {
    if (auto problem = modbus_serve_options_problem(options); !problem.empty()) {
        err << "rig modbus serve: " << problem << std::endl;
        return 2;
    }
    const RealtimeClock clock;
    std::mutex print_mutex;  // callbacks print from the slave's thread
    const auto print = [&](std::ostream& stream, const std::string& line) {
        std::lock_guard lock(print_mutex);
        stream << line << std::endl;  // flushed: a person or a test watches it live
    };

    modbus::ModbusSlaveCallbacks callbacks;
    callbacks.on_master_write = [&](const modbus::MasterWrite& write) {
        const std::string stamp = "t=" + seconds_text(clock.now_ns()) + "s ";
        if (write.commands_changed) print(out, stamp + commands_line(write.commands));
        if (write.indicators_changed) print(out, stamp + indicators_line(write.indicators));
    };
    callbacks.on_problem = [&](const std::string& line) { print(err, "rig modbus serve: " + line); };

    modbus::CommsFailsafe failsafe;
    failsafe.timeout = std::chrono::milliseconds(std::llround(options.failsafe_timeout_s * 1000.0));
    failsafe.mode = options.failsafe == "hold" ? modbus::FailsafeMode::hold : modbus::FailsafeMode::safe;
    std::optional<modbus::ModbusSlave> slave;
    try {
        if (options.rtu_device.empty()) {
            const modbus::TcpEndpoint endpoint = modbus::parse_tcp_endpoint(options.tcp);
            modbus::TcpSlaveOptions tcp;
            tcp.bind_address = endpoint.address;
            tcp.port = endpoint.port;
            tcp.allow_non_loopback = options.allow_non_loopback;
            tcp.failsafe = failsafe;
            slave.emplace(tcp, callbacks);
        } else {
            modbus::RtuSlaveOptions rtu;
            rtu.line.device = options.rtu_device;
            rtu.line.baud = options.baud;
            rtu.line.parity = modbus::parse_parity(options.parity);
            rtu.line.data_bits = options.data_bits;
            rtu.line.stop_bits = options.stop_bits;
            rtu.slave_id = static_cast<std::uint8_t>(options.slave_id);
            rtu.failsafe = failsafe;
            slave.emplace(rtu, callbacks);
        }
        slave->set_device_signals(synthetic_device_signals(options, 0.0));
    } catch (const std::invalid_argument& error) {
        err << "rig modbus serve: " << error.what() << std::endl;
        return 2;
    } catch (const std::exception& error) {
        err << "rig modbus serve: " << error.what() << std::endl;
        return 1;
    }

    const std::string watchdog = failsafe.timeout.count() == 0
                                     ? "no comms-loss fail-safe"
                                     : "comms-loss fail-safe " + std::string(modbus::to_string(failsafe.mode)) +
                                           " after " + std::to_string(failsafe.timeout.count()) + " ms";
    print(out, "rig modbus serve: serving register map v" + std::to_string(modbus::kRegisterMapVersion) + " on " +
                   slave->endpoint() + "; " + watchdog + "; Ctrl-C stops");
    const TimeNs period_ns = static_cast<TimeNs>(1e9 / options.update_hz);
    TimeNs next_update_ns = 0;
    int exit_code = 0;
    while (!stop_requested) {
        const TimeNs now = clock.now_ns();
        if (now >= next_update_ns) {
            slave->set_device_signals(synthetic_device_signals(options, ns_to_seconds(now)));
            // Absolute deadlines; after a long stall, skip missed updates instead of bursting.
            next_update_ns = std::max(next_update_ns + period_ns, now);
        }
        if (auto failure = slave->server_failure()) {
            print(err, "rig modbus serve: " + *failure);
            exit_code = 1;
            break;
        }
        clock.sleep_until_ns(std::min(next_update_ns, clock.now_ns() + kMaxSleepNs));
    }
    slave->stop();
    print(out, "rig modbus serve: stopped; " + summary_line(slave->statistics()));
    return exit_code;
}

int ModbusCommand::run() {
    const ModbusServeOptions& options = options_;
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = 0;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
    return serve_modbus(options, std::cout, std::cerr, g_stop_signalled);
}

}  // namespace rig::harness
