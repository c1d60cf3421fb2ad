#pragma once
// A HidTransport that behaves like the bench I/O board's firmware
// (rig/wire/hid_board_protocol.h), for machines without the board: it decodes the
// rig's command reports, emits pulses on its two outputs by the protocol's
// spreading rule on its own simulated clock, and sends status reports carrying
// relay inputs the test sets.
//
// Time is the test's: it only moves in advance_us(). Status reports are queued
// like the kernel's hidraw buffer (at most kQueueCapacity; the oldest is dropped
// when full, which the rig sees as a sequence gap): one every kStatusPeriodUs of
// board time, one after each command, one when an input changes. A read that
// finds the queue empty and may wait gets the board's next periodic report.
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "rig/wire/hid_board.h"
#include "rig/wire/hid_board_protocol.h"
#include "rig/runtime/io_image.h"

namespace rig::testing {

class FakeHidBoard final : public HidTransport {
public:
    static constexpr std::uint64_t kStatusPeriodUs = 10'000;
    static constexpr std::size_t kQueueCapacity = 64;

    // HidTransport: what the rig calls.
    void write_report(std::span<const std::uint8_t> report) override;
    std::optional<std::vector<std::uint8_t>> read_report(std::chrono::milliseconds timeout) override;
    std::string description() const override { return "fake HID I/O board"; }

    // The test's side.
    void advance_us(std::uint64_t microseconds);
    void set_relay_inputs(const io::ActuatorCommands& relays);
    void set_indicator_inputs(const io::ControllerIndicators& indicators);
    void queue_raw_report(std::vector<std::uint8_t> bytes);  // e.g. a malformed one

    std::uint64_t now_us() const { return now_us_; }
    std::uint32_t wheel_encoder_emitted() const { return wheel_.emitted_at(now_us_); }
    std::uint32_t main_flow_emitted() const { return flow_.emitted_at(now_us_); }
    // Button, switch and analog outputs as currently driven (counts: emitted).
    io::DeviceSignals outputs() const;
    std::uint64_t commands_applied() const { return commands_applied_; }
    std::uint64_t commands_refused() const { return commands_refused_; }
    hid::ReportProblem last_command_problem() const { return last_problem_; }

private:
    // One pulse output under the protocol's spreading rule.
    struct PulseOutput {
        std::uint32_t count_at_command = 0;
        std::uint32_t to_emit = 0;
        std::uint64_t command_time_us = 0;
        std::uint32_t interval_us = 0;
        bool behind = false;
        std::uint32_t emitted_at(std::uint64_t time_us) const;
        bool rate_limited() const;
        void command(std::uint32_t target, std::uint32_t interval, bool rebase, std::uint64_t time_us);
    };
    hid::BoardStatus status_at(std::uint64_t time_us);
    void queue_status(std::uint64_t time_us);

    std::uint64_t now_us_ = 0;
    PulseOutput wheel_;
    PulseOutput flow_;
    io::DeviceSignals levels_;
    io::ActuatorCommands relays_;
    io::ControllerIndicators indicators_;
    std::uint16_t status_sequence_ = 0;
    std::uint16_t last_command_sequence_ = 0;
    hid::ReportProblem last_problem_ = hid::ReportProblem::none;
    std::uint64_t commands_applied_ = 0;
    std::uint64_t commands_refused_ = 0;
    std::deque<std::vector<std::uint8_t>> queue_;
};

}  // namespace rig::testing
