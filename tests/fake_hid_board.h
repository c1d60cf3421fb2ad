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
//
// PWM capture (protocol version 2): the test gives each of the six capture
// inputs a simulated PWM (frequency, duty, phase on the board's clock; 0 % and
// 100 % are steady levels) and may add or remove single edges (glitches,
// missed edges). While a command has enabled capture on an input, its edges,
// timestamped to the board's microsecond, go into an edge buffer of
// kEdgeBufferCapacity (full: the edge is lost and the next edge report says
// "overflow"); every 1 ms interrupt interval the board sends one edge report
// when 16 edges wait or a 10 ms report period is due. Edge reports share the
// hidraw-like queue with the status reports. set_firmware_version(1) makes it a
// version-1 board, which refuses a version-2 command.
#include <cstdint>
#include <deque>
#include <set>
#include <utility>
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
    // PWM capture inputs (the simulated controller's GPIO PWM outputs).
    static constexpr std::size_t kEdgeBufferCapacity = 256;
    static constexpr std::uint64_t kInterruptIntervalUs = 1'000;
    struct PwmSource {
        double frequency_hz = 9.0;   // > 0
        double duty_pct = 0.0;       // 0..100; 0 and 100 are steady levels
        double phase_us = 0.0;       // a rising edge at phase + k / frequency
    };
    // From now on; the level changes at once if the new source's does.
    void set_pwm_source(int input, PwmSource source);
    void inject_edge(int input, std::uint64_t time_us, bool rising);  // an extra edge (a glitch), not before now
    void suppress_edges(int input, std::uint64_t from_us, std::uint64_t to_us);  // the source's edges there are missed
    void set_firmware_version(std::uint8_t version) { firmware_version_ = version; }
    std::uint64_t edges_captured() const { return edges_captured_; }
    std::uint64_t edges_lost() const { return edges_lost_; }
    std::uint64_t edge_reports_sent() const { return edge_reports_sent_; }

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
    void queue_report(const hid::Report& report);
    // The capture inputs' edges in (from, to], captured into the buffer.
    void capture_edges(std::uint64_t from_us, std::uint64_t to_us);
    void queue_edge_report(std::uint64_t time_us);
    bool pin_level(int input, std::uint64_t time_us) const;

    struct SourceSpell {
        std::uint64_t from_us = 0;
        PwmSource source;
    };
    std::vector<SourceSpell> sources_[hid::kPwmCaptureInputs];
    std::vector<std::pair<std::uint64_t, bool>> injected_[hid::kPwmCaptureInputs];
    std::vector<std::pair<std::uint64_t, std::uint64_t>> suppressed_[hid::kPwmCaptureInputs];
    std::deque<hid::CapturedEdge> edge_buffer_;
    std::uint64_t edge_buffer_oldest_ = 0;  // full board time of the oldest buffered edge
    std::uint8_t capture_inputs_ = 0;
    std::uint8_t firmware_version_ = hid::kProtocolVersion;
    std::uint8_t status_version_ = hid::kOldestProtocolVersion;
    bool overflow_ = false;
    std::uint8_t reported_levels_ = 0;
    std::uint16_t edge_sequence_ = 0;
    std::uint64_t edges_captured_ = 0;
    std::uint64_t edges_lost_ = 0;
    std::uint64_t edge_reports_sent_ = 0;
    std::uint8_t pin_levels_ = 0;  // the inputs' actual levels (missed edges change them too)

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
