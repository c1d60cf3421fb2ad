#include "rig/wire/hid_board.h"

#include <hidapi.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <mutex>

namespace rig {
namespace {

// hidapi reports strings as wchar_t (UTF-32 on Linux): encode as UTF-8.
std::string utf8(const wchar_t* text) {
    std::string out;
    if (text == nullptr) return out;
    for (; *text != L'\0'; ++text) {
        auto code = static_cast<std::uint32_t>(*text);
        if (code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) code = 0xFFFD;
        if (code < 0x80) {
            out += static_cast<char>(code);
        } else if (code < 0x800) {
            out += static_cast<char>(0xC0 | (code >> 6));
            out += static_cast<char>(0x80 | (code & 0x3F));
        } else if (code < 0x10000) {
            out += static_cast<char>(0xE0 | (code >> 12));
            out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
            out += static_cast<char>(0x80 | (code & 0x3F));
        } else {
            out += static_cast<char>(0xF0 | (code >> 18));
            out += static_cast<char>(0x80 | ((code >> 12) & 0x3F));
            out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
            out += static_cast<char>(0x80 | (code & 0x3F));
        }
    }
    return out;
}

// hidapi's reason for the last failure on `device` (nullptr: of open/enumerate).
std::string hidapi_error(hid_device* device) {
    const std::string text = utf8(::hid_error(device));
    return text.empty() ? std::string("no reason given") : text;
}

// hidapi's static state: initialised once, before the first call that may race
// (its documentation asks for hid_init when several threads may open devices),
// and released at exit.
class HidapiLibrary {
public:
    static void ensure_initialised() {
        static HidapiLibrary library;
        if (!library.ok_) throw HidError("hidapi: hid_init failed: " + library.error_);
    }

private:
    HidapiLibrary() {
        ok_ = ::hid_init() == 0;
        if (!ok_) error_ = hidapi_error(nullptr);
    }
    ~HidapiLibrary() {
        if (ok_) ::hid_exit();
    }
    bool ok_ = false;
    std::string error_;
};

}  // namespace

std::string format_vid_pid(std::uint16_t vendor_id, std::uint16_t product_id) {
    char text[16];
    std::snprintf(text, sizeof text, "%04x:%04x", static_cast<unsigned>(vendor_id), static_cast<unsigned>(product_id));
    return text;
}

std::string no_board_message(std::uint16_t vendor_id, std::uint16_t product_id, std::size_t devices_present) {
    return "no HID I/O board VID:PID " + format_vid_pid(vendor_id, product_id) + " found (" +
           std::to_string(devices_present) + " HID device" + (devices_present == 1 ? "" : "s") + " present)";
}

std::vector<HidDeviceInfo> list_hid_devices(std::uint16_t vendor_id, std::uint16_t product_id) {
    HidapiLibrary::ensure_initialised();
    std::vector<HidDeviceInfo> devices;
    hid_device_info* const first = ::hid_enumerate(vendor_id, product_id);
    for (const hid_device_info* info = first; info != nullptr; info = info->next) {
        HidDeviceInfo device;
        device.path = info->path != nullptr ? info->path : "";
        device.vendor_id = info->vendor_id;
        device.product_id = info->product_id;
        device.manufacturer = utf8(info->manufacturer_string);
        device.product = utf8(info->product_string);
        device.serial_number = utf8(info->serial_number);
        device.interface_number = info->interface_number;
        devices.push_back(std::move(device));
    }
    ::hid_free_enumeration(first);
    return devices;
}

std::vector<HidDeviceInfo> list_hid_boards(std::uint16_t vendor_id, std::uint16_t product_id) {
    return list_hid_devices(vendor_id, product_id);
}

HidapiTransport::HidapiTransport(hid_device_* device, std::string description)
    : device_(device), description_(std::move(description)) {}

HidapiTransport::~HidapiTransport() { ::hid_close(device_); }

std::unique_ptr<HidapiTransport> HidapiTransport::open(std::uint16_t vendor_id, std::uint16_t product_id,
                                                       const std::string& serial_number) {
    const auto boards = list_hid_boards(vendor_id, product_id);
    const auto chosen = std::find_if(boards.begin(), boards.end(), [&](const HidDeviceInfo& board) {
        return serial_number.empty() || board.serial_number == serial_number;
    });
    if (chosen == boards.end()) {
        std::string message = no_board_message(vendor_id, product_id, list_hid_devices(0, 0).size());
        if (!serial_number.empty()) {
            message += "; with serial number '" + serial_number + "': none of the " + std::to_string(boards.size()) +
                       " with this VID:PID";
        }
        throw HidError(message);
    }
    return open_path(chosen->path);
}

std::unique_ptr<HidapiTransport> HidapiTransport::open_path(const std::string& path) {
    HidapiLibrary::ensure_initialised();
    hid_device* const device = ::hid_open_path(path.c_str());
    if (device == nullptr) {
        throw HidError("HID I/O board " + path + ": cannot open: " + hidapi_error(nullptr) +
                       " (permissions: see the udev rule in docs/hid-io-board.md)");
    }
    return std::unique_ptr<HidapiTransport>(new HidapiTransport(device, "HID I/O board " + path));
}

void HidapiTransport::write_report(std::span<const std::uint8_t> report) {
    const int written = ::hid_write(device_, report.data(), report.size());
    if (written < 0) throw HidError(description_ + ": write failed: " + hidapi_error(device_));
    if (static_cast<std::size_t>(written) != report.size()) {
        throw HidError(description_ + ": short write, " + std::to_string(written) + " of " +
                       std::to_string(report.size()) + " bytes");
    }
}

std::optional<std::vector<std::uint8_t>> HidapiTransport::read_report(std::chrono::milliseconds timeout) {
    // One byte more than a report: a longer report shows up as the wrong length
    // instead of being silently cut to size.
    std::vector<std::uint8_t> buffer(hid::kReportSize + 1);
    const auto timeout_ms =
        static_cast<int>(std::clamp<std::int64_t>(timeout.count(), 0, std::numeric_limits<int>::max()));
    const int received = ::hid_read_timeout(device_, buffer.data(), buffer.size(), timeout_ms);
    if (received < 0) throw HidError(description_ + ": read failed (unplugged?): " + hidapi_error(device_));
    if (received == 0) return std::nullopt;
    buffer.resize(static_cast<std::size_t>(received));
    return buffer;
}

HidBoard::HidBoard(std::unique_ptr<HidTransport> transport, std::chrono::milliseconds status_timeout)
    : transport_(std::move(transport)), status_timeout_(status_timeout) {
    if (!transport_) throw std::invalid_argument("HidBoard needs a transport");
}

void HidBoard::apply(const io::DeviceSignals& signals, TimeNs spread_ns) {
    constexpr TimeNs kNsPerUs = 1000;
    constexpr auto kMaxSpreadNs = static_cast<TimeNs>(std::numeric_limits<std::uint32_t>::max()) * kNsPerUs;
    if (spread_ns < 0 || spread_ns > kMaxSpreadNs) {
        throw std::invalid_argument("HID board: spread interval " + std::to_string(spread_ns) + " ns outside 0.." +
                                    std::to_string(kMaxSpreadNs) + " ns");
    }
    if (!last_sent_) {
        rebase(signals);
        return;
    }
    const auto check_forward = [](std::uint32_t before, std::uint32_t after, const char* field) {
        if (hid::counter_ahead(before, after) < 0) {
            throw std::invalid_argument(std::string("HID board: ") + field + " went back from " +
                                        std::to_string(before) + " to " + std::to_string(after) +
                                        "; a pulse output cannot take pulses back (rebase() to start over)");
        }
    };
    check_forward(last_sent_->wheel_encoder_count, signals.wheel_encoder_count, "wheel_encoder_count");
    check_forward(last_sent_->main_flow_pulses, signals.main_flow_pulses, "main_flow_pulses");
    send(signals, static_cast<std::uint32_t>((spread_ns + kNsPerUs / 2) / kNsPerUs), false);
}

void HidBoard::rebase(const io::DeviceSignals& signals) { send(signals, 0, true); }

void HidBoard::send(const io::DeviceSignals& signals, std::uint32_t spread_interval_us, bool rebase) {
    hid::BoardCommand command;
    command.sequence = next_sequence_;
    command.signals = signals;
    command.spread_interval_us = spread_interval_us;
    command.rebase_counters = rebase;
    command.pwm_capture_inputs = pwm_capture_inputs_;
    const hid::Report report = hid::encode_command(command);  // throws before anything is sent
    transport_->write_report(report);
    last_sent_ = signals;
    ++next_sequence_;
}

void HidBoard::enable_pwm_capture(std::uint8_t inputs, PwmCaptureParams params) {
    if ((inputs & ~hid::kPwmCaptureInputMask) != 0) {
        throw std::invalid_argument("HID board: PWM capture inputs mask " + std::to_string(inputs) +
                                    " names an input above " + std::to_string(hid::kPwmCaptureInputs - 1));
    }
    pwm_capture_inputs_ = inputs;
    if (inputs == 0) {
        pwm_capture_.reset();
    } else {
        pwm_capture_.emplace(params);
    }
}

io::ActuatorCommands HidBoard::read_actuators() {
    // A board with capture on interleaves edge reports with the status reports.
    bool status_seen = false;
    const auto consume = [this, &status_seen](const std::vector<std::uint8_t>& bytes) {
        if (!bytes.empty() && bytes[0] == hid::kEdgeReportId) {
            const auto edges = hid::decode_edges(bytes);
            if (!edges.ok()) {
                throw HidError(transport_->description() + ": malformed edge report: " + edges.error.reason);
            }
            if (!pwm_capture_) {
                throw HidError(transport_->description() + ": an edge report though PWM capture is off");
            }
            pwm_capture_->on_report(*edges.value);
            return;
        }
        status_seen = true;
        const auto decoded = hid::decode_status(bytes);
        if (!decoded.ok()) {
            throw HidError(transport_->description() + ": malformed status report: " + decoded.error.reason);
        }
        const hid::BoardStatus& status = *decoded.value;
        if (last_status_) {
            const auto gap = static_cast<std::uint16_t>(status.sequence - last_status_->sequence - 1);
            status_reports_lost_ += gap;
        }
        last_status_ = status;
        if (status.last_command_problem == hid::ReportProblem::unsupported_version && pwm_capture_inputs_ != 0 &&
            status.protocol_version < hid::kPwmCaptureVersion) {
            throw HidError(transport_->description() + ": the board speaks protocol version " +
                           std::to_string(status.protocol_version) + " and refused PWM capture (version " +
                           std::to_string(hid::kPwmCaptureVersion) + "); update its firmware");
        }
        if (status.last_command_problem != hid::ReportProblem::none) {
            throw HidError(transport_->description() + ": the board refused the last command report (" +
                           hid::to_string(status.last_command_problem) + "); last command applied: #" +
                           std::to_string(status.last_command_sequence));
        }
    };
    // Bounded: the firmware sends a status at least every 10 ms, and at most
    // one report per 1 ms interrupt interval, so a status comes within a few
    // dozen reports; a board sending only edge reports is an error, not a hang.
    constexpr int kMaxReportsWithoutStatus = 256;
    for (int read = 0; !status_seen; ++read) {
        if (read == kMaxReportsWithoutStatus) {
            throw HidError(transport_->description() + ": " + std::to_string(read) +
                           " reports in a row without a status report");
        }
        const auto next = transport_->read_report(status_timeout_);
        if (!next) {
            throw HidError(transport_->description() + ": no status report within " +
                           std::to_string(status_timeout_.count()) + " ms");
        }
        consume(*next);
    }
    // Reports queued behind it are newer: the newest wins.
    while (const auto queued = transport_->read_report(std::chrono::milliseconds(0))) consume(*queued);
    return last_status_->actuators;
}

io::ControllerIndicators HidBoard::indicators() const {
    return last_status_ ? last_status_->indicators : io::ControllerIndicators{};
}

}  // namespace rig
