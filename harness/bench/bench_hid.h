#pragma once
// `rig hid list [--vid 0x1209] [--pid 0x0001]`: lists the USB-HID bench I/O
// boards (rig/wire/hid_board.h) attached to this machine, one per line:
//   1209:0001 /dev/hidraw3 "rig bench" "sprayer HIL I/O board" serial 0042 interface 0
// Exit 0 when at least one is found; otherwise 1 and
//   rig hid list: no HID I/O board VID:PID 1209:0001 found (3 HID devices present)
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>

#include "harness/cli/subcommand.h"

namespace rig::harness {

// A USB vendor or product id as hex, with or without 0x ("0x1209", "1209");
// nullopt when it is not 1 to 4 hex digits.
std::optional<std::uint16_t> parse_usb_id(const std::string& text);

int run_hid_list(std::uint16_t vendor_id, std::uint16_t product_id, std::ostream& out, std::ostream& err);

// The subcommand, registered in harness/commands/main.cpp's table: declares `rig hid list` on `app`.
class HidBenchCommand final : public Subcommand {
public:
    explicit HidBenchCommand(CLI::App& app);
    HidBenchCommand(const HidBenchCommand&) = delete;  // CLI11 holds pointers into the members
    HidBenchCommand& operator=(const HidBenchCommand&) = delete;
    bool parsed() const override;
    int run() override;

private:
    CLI::App* list_ = nullptr;
    std::string vendor_id_;
    std::string product_id_;
};

}  // namespace rig::harness
