#include "harness/bench/bench_hid.h"

#include <CLI/CLI.hpp>

#include <cctype>
#include <cstdio>
#include <iostream>

#include "rig/wire/hid_board.h"

namespace rig::harness {

std::optional<std::uint16_t> parse_usb_id(const std::string& text) {
    std::string_view digits = text;
    if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) digits.remove_prefix(2);
    if (digits.empty() || digits.size() > 4) return std::nullopt;
    unsigned value = 0;
    for (char c : digits) {
        if (!std::isxdigit(static_cast<unsigned char>(c))) return std::nullopt;
        const unsigned digit = std::isdigit(static_cast<unsigned char>(c)) ? unsigned(c - '0')
                                                                          : unsigned(std::tolower(c) - 'a' + 10);
        value = value * 16 + digit;
    }
    return static_cast<std::uint16_t>(value);
}

int run_hid_list(std::uint16_t vendor_id, std::uint16_t product_id, std::ostream& out, std::ostream& err) {
    try {
        const auto boards = list_hid_boards(vendor_id, product_id);
        if (boards.empty()) {
            err << "rig hid list: " << no_board_message(vendor_id, product_id, list_hid_devices(0, 0).size()) << "\n";
            return 1;
        }
        for (const auto& board : boards) {
            out << format_vid_pid(board.vendor_id, board.product_id) << " " << board.path << " \""
                << board.manufacturer << "\" \"" << board.product << "\" serial "
                << (board.serial_number.empty() ? std::string("-") : board.serial_number) << " interface "
                << board.interface_number << "\n";
        }
        return 0;
    } catch (const std::exception& error) {
        err << "rig hid list: " << error.what() << "\n";
        return 1;
    }
}

namespace {
std::string hex_usb_id(std::uint16_t id) {
    char text[8];
    std::snprintf(text, sizeof text, "0x%04x", static_cast<unsigned>(id));
    return text;
}
}  // namespace

HidBenchCommand::HidBenchCommand(CLI::App& app)
    : vendor_id_(hex_usb_id(kDefaultHidBoardVid)), product_id_(hex_usb_id(kDefaultHidBoardPid)) {
    auto* hid = app.add_subcommand("hid", "USB-HID bench I/O board tools");
    hid->require_subcommand(1);
    list_ = hid->add_subcommand("list", "list the HID I/O boards attached (exit 1 when there is none)");
    list_->add_option("--vid", vendor_id_, "USB vendor id, hex")->capture_default_str();
    list_->add_option("--pid", product_id_, "USB product id, hex")->capture_default_str();
}

bool HidBenchCommand::parsed() const { return list_->parsed(); }

int HidBenchCommand::run() {
    const auto vendor_id = parse_usb_id(vendor_id_);
    const auto product_id = parse_usb_id(product_id_);
    if (!vendor_id || !product_id) {
        std::cerr << "rig hid list: " << (vendor_id ? "--pid '" + product_id_ : "--vid '" + vendor_id_)
                  << "' is not a USB id (1 to 4 hex digits, e.g. 0x1209)\n";
        return 2;
    }
    return run_hid_list(*vendor_id, *product_id, std::cout, std::cerr);
}

}  // namespace rig::harness
