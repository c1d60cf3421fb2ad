#pragma once
// `rig modbus serve`: the rig's Modbus slave on its own, for the bench. It
// serves the register map (docs/modbus-register-map.md) over TCP or RTU so a
// person can point a controller board, or mbpoll, at it; the board inputs come
// from a synthetic source given on the command line (a vehicle at constant
// speed, a constant main-pipeline flow), the counts advancing with wall time;
// every change the master writes to the coils or holding registers is printed,
// one line each. Runs until SIGINT/SIGTERM, then exits 0.
//
//   rig modbus serve --tcp 127.0.0.1:1502 --speed-km-h 6 --flow-l-min 20
//   rig modbus serve --rtu /dev/ttyUSB0 --baud 115200 --parity N --slave-id 1
//   rig modbus serve --tcp 127.0.0.1:1502 --failsafe-timeout-s 1 --failsafe safe
#include <atomic>
#include <iosfwd>
#include <string>

#include "rig/runtime/io_image.h"

#include "harness/cli/subcommand.h"
#include "rig/papers/seed000.h"

namespace rig::harness {

struct ModbusServeOptions {
    // Wire: TCP unless rtu_device is set.
    std::string tcp = "127.0.0.1:1502";  // ADDRESS:PORT; port 0 = any free port (printed)
    bool allow_non_loopback = false;
    std::string rtu_device;
    int baud = 115200;
    std::string parity = "N";
    int data_bits = 8;
    int stop_bits = 1;
    int slave_id = 1;

    // Synthetic board inputs (seed 000: Eq. 5 land wheel, Eq. 3 flow meter).
    double speed_km_h = 0.0;
    double wheel_diameter_m = papers::seed000::kLandWheelDiameterM;
    double pulses_per_rev = papers::seed000::kEncoderPulsesPerRev;
    double flow_l_min = 0.0;
    double pulses_per_l = papers::seed000::kFlowMeterPulsesPerLitre;
    int pump_flow_adc = 0;
    int boom_height_adc = 0;
    bool spray_switch = false;
    bool breakpoint_button = false;
    double update_hz = 100.0;  // how often the served counts are refreshed

    // The comms-loss watchdog (docs/modbus-register-map.md "Board timeouts"):
    // off by default, since a person with mbpoll polls when they like; a board
    // left on the bench overnight gets `--failsafe-timeout-s 1`.
    double failsafe_timeout_s = 0.0;  // s after the last valid request; 0 = off
    std::string failsafe = "safe";    // safe (every coil de-energised) | hold (counted only)
};

// The synthetic inputs `elapsed_s` after the start: cumulative wheel encoder
// and flow meter counts (wrapping at 2^32 like the board's counters).
io::DeviceSignals synthetic_device_signals(const ModbusServeOptions& options, double elapsed_s);
// Empty = usable; otherwise which option is wrong and why.
std::string modbus_serve_options_problem(const ModbusServeOptions& options);


// Serves until `stop_requested`; the startup line, the change lines and a
// closing summary go to `out`, problems (refused requests, dropped frames)
// to `err`. Returns 0 after a requested stop, 1 when the port cannot be had or
// the slave fails, 2 for bad options.
int serve_modbus(const ModbusServeOptions& options, std::ostream& out, std::ostream& err,
                 const std::atomic<bool>& stop_requested);
// `rig modbus serve`: serve_modbus() on std::cout / std::cerr, stopped by SIGINT or SIGTERM.
class ModbusCommand final : public Subcommand {
public:
    explicit ModbusCommand(CLI::App& app);
    ModbusCommand(const ModbusCommand&) = delete;  // CLI11 holds pointers into options_
    ModbusCommand& operator=(const ModbusCommand&) = delete;
    bool parsed() const override;
    int run() override;

private:
    CLI::App* serve_ = nullptr;
    ModbusServeOptions options_;
};

}  // namespace rig::harness
