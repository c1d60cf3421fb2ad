#pragma once
// `rig emulate gnss`: one emulated device onto a real port, for a person at the
// bench (issue: plug in a real controller). The case file's vehicle drives its
// route in real time and the G970II's NMEA stream goes out on a serial port, or
// on a pseudo-terminal the rig creates, exactly what the receiver puts on the
// wire; point a controller board, gpsd or a terminal at it.
//
//   rig emulate gnss CASE [--port /dev/ttyUSB0 | --pty [--link PATH]] [--baud N]
//                         [--seed N] [--seconds S]
//
// Runs until the case's route ends (or --seconds), or SIGINT / SIGTERM; exit 0.
// A port that cannot be opened or closes under it is an error naming the port (exit 1).
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>

#include "harness/cli/subcommand.h"

namespace rig::harness {

struct EmulateGnssOptions {
    std::string case_file;
    std::string port;            // a serial device; empty with pty
    bool pty = false;
    std::string link;            // with pty: a symlink to the slave end
    int baud = 115200;
    std::optional<std::uint64_t> seed;
    std::optional<double> seconds;
};

int run_emulate_gnss(const EmulateGnssOptions& options, std::ostream& out, std::ostream& err);

// The subcommand, registered in harness/commands/main.cpp's table.
class EmulateBenchCommand final : public Subcommand {
public:
    explicit EmulateBenchCommand(CLI::App& app);
    EmulateBenchCommand(const EmulateBenchCommand&) = delete;
    EmulateBenchCommand& operator=(const EmulateBenchCommand&) = delete;
    bool parsed() const override;
    int run() override;

private:
    CLI::App* gnss_ = nullptr;
    EmulateGnssOptions options_;
    std::uint64_t seed_ = 0;
    double seconds_ = 0.0;
};

}  // namespace rig::harness
