// The HID I/O board's PWM edge capture (protocol version 2, docs/hid-io-board.md
// "PWM edge capture"): the new bytes worked by hand, backward compatibility
// with version 1, malformed edge reports refused naming the byte, and the
// rig's decoding of duty and frequency per nozzle (rig/wire/pwm_capture.h)
// end to end through HidBoard against the fake board's simulated PWM, on the
// board's own clock, including hostile input: glitches, bounce, missed edges,
// a full edge buffer, lost reports, 0 % and 100 %, the 32-bit clock's wrap.
//
// Tolerance, from the board's 1 us timestamps: each edge is within 0.5 us of
// the true instant, so a period and a high time are each within 1 us; at 9 Hz
// (111111 us) the duty is within 2 us / 111111 us = 0.0018 percentage points
// and the frequency within 9 Hz x 1e-5 = 9e-5 Hz. The tests allow 0.002 points
// and 1e-4 Hz. A bounce moves an edge by its own length (stated where used).
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "rig/wire/hid_board.h"
#include "rig/wire/hid_board_protocol.h"
#include "rig/wire/pwm_capture.h"
#include "tests/fake_hid_board.h"

namespace rig {
namespace {

using Bytes = std::vector<std::uint8_t>;
using testing::FakeHidBoard;
using State = NozzlePwmReading::State;

constexpr double kDutyTolerancePct = 0.002;
constexpr double kFrequencyToleranceHz = 1e-4;
constexpr std::uint64_t kReadEveryUs = 20'000;  // the rig's loop reads the board every 20 ms here

// ------------------------------------------------------------------ protocol

TEST(HidPwmCaptureProtocol, ACommandWithoutCaptureIsVersionOneByteForByte) {
    hid::BoardCommand command;
    command.sequence = 7;
    command.spread_interval_us = 50'000;
    const hid::Report v1 = hid::encode_command(command);
    EXPECT_EQ(v1[1], 1);   // version 1: a version-1 board takes it
    EXPECT_EQ(v1[22], 0);  // reserved in version 1
    command.pwm_capture_inputs = 0x3F;
    const hid::Report v2 = hid::encode_command(command);
    EXPECT_EQ(v2[1], 2);
    EXPECT_EQ(v2[22], 0x3F);
    for (std::size_t i = 2; i < v1.size(); ++i) {
        if (i != 22) {
            EXPECT_EQ(v1[i], v2[i]) << "byte " << i << " differs between the versions";
        }
    }
    const auto decoded = hid::decode_command(v2);
    ASSERT_TRUE(decoded.ok()) << decoded.error.reason;
    EXPECT_EQ(decoded.value->pwm_capture_inputs, 0x3F);
    EXPECT_EQ(decoded.value->protocol_version, 2);

    Bytes bad(v2.begin(), v2.end());
    bad[22] = 0x7F;  // a seventh input
    const auto refused = hid::decode_command(bad);
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.error.problem, hid::ReportProblem::reserved_bits_set);
    EXPECT_NE(refused.error.reason.find("byte 22 (PWM capture inputs): reserved bits 0x40 set"), std::string::npos)
        << refused.error.reason;
    command.pwm_capture_inputs = 0x40;
    EXPECT_THROW(hid::encode_command(command), std::invalid_argument);
}

TEST(HidPwmCaptureProtocol, EdgeReportBytesByHand) {
    hid::EdgeReport report;
    report.sequence = 0x0102;
    report.report_time_us = 0x00100000;
    report.levels = 0x21;  // inputs 0 and 5 high
    report.overflow = true;
    report.edges = {{1000, 2, true}, {1000 + 0x12345, 5, false}};
    const hid::Report bytes = hid::encode_edges(report);
    const Bytes expected{
        0x03, 0x02,              // report id, version 2
        0x02, 0x01,              // sequence 0x0102
        0x00, 0x00, 0x10, 0x00,  // report time 0x100000
        0x21,                    // levels
        0x01,                    // flags: overflow
        0x02,                    // two edges
        0x00,                    // reserved
        0xE8, 0x03, 0x00, 0x00,  // base 1000
        0x00, 0x00, 0xA0,        // +0 us, input 2, rising: 0xA00000
        0x45, 0x23, 0x51,        // +0x12345 us, input 5, falling: 0x512345
    };
    EXPECT_EQ(Bytes(bytes.begin(), bytes.begin() + 22), expected);
    EXPECT_EQ(Bytes(bytes.begin() + 22, bytes.end()), Bytes(42, 0));
    const auto decoded = hid::decode_edges(bytes);
    ASSERT_TRUE(decoded.ok()) << decoded.error.reason;
    EXPECT_EQ(decoded.value->sequence, 0x0102);
    EXPECT_EQ(decoded.value->levels, 0x21);
    EXPECT_TRUE(decoded.value->overflow);
    ASSERT_EQ(decoded.value->edges.size(), 2u);
    EXPECT_EQ(decoded.value->edges[1].time_us, 1000u + 0x12345u);
    EXPECT_EQ(decoded.value->edges[1].input, 5);
    EXPECT_FALSE(decoded.value->edges[1].rising);
}

TEST(HidPwmCaptureProtocol, EdgesAcrossTheClockWrapRoundTrip) {
    std::mt19937 random(12);
    for (int i = 0; i < 500; ++i) {
        hid::EdgeReport report;
        report.sequence = static_cast<std::uint16_t>(random());
        std::uint32_t t = 0xFFFFFFFFu - static_cast<std::uint32_t>(random() % 300'000);
        const std::size_t n = random() % (hid::kMaxEdgesPerReport + 1);
        for (std::size_t e = 0; e < n; ++e) {
            report.edges.push_back({t, static_cast<std::uint8_t>(random() % 6), (random() % 2) == 0});
            t += static_cast<std::uint32_t>(random() % 50'000);  // wraps past 2^32
        }
        report.report_time_us = t;
        report.levels = static_cast<std::uint8_t>(random() & 0x3F);
        const auto decoded = hid::decode_edges(hid::encode_edges(report));
        ASSERT_TRUE(decoded.ok()) << decoded.error.reason;
        ASSERT_EQ(decoded.value->edges.size(), n);
        for (std::size_t e = 0; e < n; ++e) {
            EXPECT_EQ(decoded.value->edges[e].time_us, report.edges[e].time_us);
            EXPECT_EQ(decoded.value->edges[e].input, report.edges[e].input);
            EXPECT_EQ(decoded.value->edges[e].rising, report.edges[e].rising);
        }
        EXPECT_EQ(decoded.value->report_time_us, report.report_time_us);
    }
}

TEST(HidPwmCaptureProtocol, MalformedEdgeReportsAreRefusedNamingTheByte) {
    hid::EdgeReport good;
    good.sequence = 9;
    good.report_time_us = 50'000;
    good.edges = {{10'000, 0, true}, {20'000, 1, false}};
    const hid::Report valid = hid::encode_edges(good);
    struct Row {
        const char* legend;
        std::function<void(Bytes&)> damage;
        hid::ReportProblem problem;
        const char* reason;
    };
    const std::vector<Row> table{
        {"a 63-byte read", [](Bytes& b) { b.pop_back(); }, hid::ReportProblem::wrong_length, "edge report is 63 bytes"},
        {"version 1: edge reports did not exist", [](Bytes& b) { b[1] = 1; }, hid::ReportProblem::unsupported_version,
         "edge report has protocol version 1, this rig speaks versions 2..2"},
        {"17 edges", [](Bytes& b) { b[10] = 17; }, hid::ReportProblem::value_out_of_range,
         "byte 10 (edge count): 17 edges"},
        {"level of a seventh input", [](Bytes& b) { b[8] = 0x40; }, hid::ReportProblem::reserved_bits_set,
         "byte 8 (capture input levels): reserved bits 0x40 set"},
        {"a flag from a future version", [](Bytes& b) { b[9] = 0x02; }, hid::ReportProblem::reserved_bits_set,
         "byte 9 (edge flags)"},
        {"byte 11 set", [](Bytes& b) { b[11] = 1; }, hid::ReportProblem::reserved_bits_set, "reserved byte 11"},
        {"input 6 in edge 1", [](Bytes& b) { b[21] = static_cast<std::uint8_t>((b[21] & 0x8F) | 0x60); },
         hid::ReportProblem::value_out_of_range, "bytes 19-21 (edge 1): input 6"},
        {"edge 1 at the base's microsecond: two inputs switched together (legal)",
         [](Bytes& b) { b[19] = 0; b[20] = 0; b[21] = static_cast<std::uint8_t>(b[21] & 0xF0); },
         hid::ReportProblem::none, ""},
        {"a third edge's bytes left behind", [](Bytes& b) { b[22] = 0x10; }, hid::ReportProblem::reserved_bits_set,
         "reserved byte 22"},
        {"edge 0 not at the base", [](Bytes& b) { b[16] = 5; }, hid::ReportProblem::value_out_of_range,
         "the first edge is the base"},
        {"an edge after the report time", [](Bytes& b) { b[4] = 0; b[5] = 0; b[6] = 0; b[7] = 0; },
         hid::ReportProblem::value_out_of_range, "after the report time"},
    };
    for (const Row& row : table) {
        Bytes bytes(valid.begin(), valid.end());
        row.damage(bytes);
        const auto decoded = hid::decode_edges(bytes);
        if (std::string(row.reason).empty()) {
            // Two edges at the same microsecond (two inputs switched together) are legal.
            EXPECT_TRUE(decoded.ok()) << row.legend << ": " << decoded.error.reason;
            continue;
        }
        ASSERT_FALSE(decoded.ok()) << row.legend;
        EXPECT_EQ(decoded.error.problem, row.problem) << row.legend << ": " << decoded.error.reason;
        EXPECT_NE(decoded.error.reason.find(row.reason), std::string::npos)
            << row.legend << ": got '" << decoded.error.reason << "'";
    }
    // Offsets going back: edge 1 at +100 us, edge 2 at +50 us.
    hid::EdgeReport three = good;
    three.edges = {{10'000, 0, true}, {10'100, 1, true}, {10'200, 2, true}};
    Bytes bytes;
    {
        const hid::Report r = hid::encode_edges(three);
        bytes.assign(r.begin(), r.end());
    }
    bytes[22] = 50;  // edge 2's offset low byte: 200 -> 50
    const auto back = hid::decode_edges(bytes);
    ASSERT_FALSE(back.ok());
    EXPECT_NE(back.error.reason.find("before the previous edge"), std::string::npos) << back.error.reason;
    // What the encoder refuses.
    three.edges[2].time_us = 9'000;
    EXPECT_THROW(hid::encode_edges(three), std::invalid_argument);
    three.edges[2].time_us = 10'000 + hid::kMaxEdgeOffsetUs + 1;
    three.report_time_us = three.edges[2].time_us;
    EXPECT_THROW(hid::encode_edges(three), std::invalid_argument);
}

TEST(HidPwmCaptureProtocol, ArbitraryBytesNeverCrashTheEdgeDecoder) {
    std::mt19937 random(7);
    for (int i = 0; i < 20000; ++i) {
        Bytes bytes(random() % 80);
        for (auto& byte : bytes) byte = static_cast<std::uint8_t>(random());
        if (!bytes.empty() && (i % 2) == 0) bytes[0] = hid::kEdgeReportId;
        if (bytes.size() > 10 && (i % 3) == 0) {
            bytes[1] = 2;
            bytes[10] = static_cast<std::uint8_t>(random() % 18);
        }
        const auto decoded = hid::decode_edges(bytes);
        EXPECT_TRUE(decoded.ok() || !decoded.error.reason.empty());
    }
}

// ------------------------------------------------------------------ decoding through the board

// A HidBoard over the fake, capture on all six inputs, the rig reading every 20 ms.
struct Bench {
    FakeHidBoard* fake = nullptr;
    std::unique_ptr<HidBoard> board;
    explicit Bench(PwmCaptureParams params = {}, std::uint64_t start_us = 0) {
        auto transport = std::make_unique<FakeHidBoard>();
        fake = transport.get();
        if (start_us > 0) fake->advance_us(start_us);  // capture still off: only the clock moves
        board = std::make_unique<HidBoard>(std::move(transport));
        board->enable_pwm_capture(hid::kPwmCaptureInputMask, params);
        board->rebase({});
        board->read_actuators();
    }
    void run_us(std::uint64_t duration_us) {
        for (std::uint64_t t = 0; t < duration_us; t += kReadEveryUs) {
            fake->advance_us(kReadEveryUs);
            board->read_actuators();
        }
    }
    const PwmCapture& capture() const { return *board->pwm_capture(); }
    const NozzlePwmReading& reading(int i) const { return capture().readings()[static_cast<std::size_t>(i)]; }
};

void expect_pwm(const NozzlePwmReading& r, double duty_pct, double frequency_hz, double tolerance_pct,
                const std::string& what) {
    EXPECT_EQ(r.state, State::pwm) << what;
    EXPECT_NEAR(r.duty_pct, duty_pct, tolerance_pct) << what;
    EXPECT_NEAR(r.frequency_hz, frequency_hz, kFrequencyToleranceHz) << what;
}

TEST(HidPwmCapture, SixNozzlesAt9HzDecodeToTheDutiesTheControllerSet) {
    Bench bench;
    // Seed 001's levels (40 %, 100 %) and duties between, each nozzle its own phase.
    const std::vector<double> duty{30.0, 40.0, 55.5, 70.25, 85.0, 99.0};
    for (int i = 0; i < 6; ++i) {
        bench.fake->set_pwm_source(i, {9.0, duty[static_cast<std::size_t>(i)], 12'345.6 * i + 777.7});
    }
    bench.run_us(2'000'000);
    for (int i = 0; i < 6; ++i) {
        expect_pwm(bench.reading(i), duty[static_cast<std::size_t>(i)], 9.0, kDutyTolerancePct, "nozzle " + std::to_string(i));
    }
    // The actuator state the DDS path carries (actuator/nozzle_pwm/duty).
    const msg::NozzlePwm pwm = bench.capture().nozzle_pwm();
    EXPECT_NEAR(pwm.frequency_hz(), 9.0, kFrequencyToleranceHz);
    ASSERT_EQ(pwm.duty_pct().size(), 6u);
    for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(pwm.duty_pct()[i], duty[i], kDutyTolerancePct);
    // About 18 periods per input in 2 s, none lost, nothing filtered.
    EXPECT_GE(bench.capture().periods(), 6u * 16u);
    EXPECT_EQ(bench.capture().glitches(), 0u);
    EXPECT_EQ(bench.capture().periods_dropped(), 0u);
    EXPECT_EQ(bench.capture().reports_lost(), 0u);
    EXPECT_EQ(bench.fake->edges_lost(), 0u);

    // A duty change shows after the next complete period (latched PWM: 2 periods at most).
    bench.fake->set_pwm_source(2, {9.0, 40.0, 100.0});
    bench.run_us(300'000);
    expect_pwm(bench.reading(2), 40.0, 9.0, kDutyTolerancePct, "nozzle 2 after the change");
    // Other frequencies decode too (the controller's parameter, not a constant here).
    bench.fake->set_pwm_source(3, {50.0, 25.0, 0.0});
    bench.run_us(200'000);
    expect_pwm(bench.reading(3), 25.0, 50.0, 0.02, "nozzle 3 at 50 Hz");  // 2 us of 20000 us
}

TEST(HidPwmCapture, ZeroAndHundredPercentAreSteadyLevels) {
    Bench bench;
    bench.fake->set_pwm_source(0, {9.0, 0.0, 0.0});
    bench.fake->set_pwm_source(1, {9.0, 100.0, 0.0});
    for (int i = 2; i < 6; ++i) bench.fake->set_pwm_source(i, {9.0, 50.0, 1000.0 * i});
    bench.run_us(600'000);
    EXPECT_EQ(bench.reading(0).state, State::steady);
    EXPECT_EQ(bench.reading(0).duty_pct, 0.0);
    EXPECT_EQ(bench.reading(0).frequency_hz, 0.0);
    EXPECT_EQ(bench.reading(1).state, State::steady);
    EXPECT_EQ(bench.reading(1).duty_pct, 100.0);
    EXPECT_NEAR(bench.capture().frequency_hz(), 9.0, kFrequencyToleranceHz);  // from the inputs with a PWM
    // A PWM set to 100 % (always on) and one back from 0 % to 40 %.
    bench.fake->set_pwm_source(2, {9.0, 100.0, 0.0});
    bench.fake->set_pwm_source(0, {9.0, 40.0, 5000.0});
    bench.run_us(500'000);
    EXPECT_EQ(bench.reading(2).state, State::steady);
    EXPECT_EQ(bench.reading(2).duty_pct, 100.0);
    expect_pwm(bench.reading(0), 40.0, 9.0, kDutyTolerancePct, "nozzle 0 back from 0 %");
    // All off: every reading 0 %, the frequency 0 (no PWM left to measure).
    for (int i = 0; i < 6; ++i) bench.fake->set_pwm_source(i, {9.0, 0.0, 0.0});
    bench.run_us(400'000);
    const msg::NozzlePwm pwm = bench.capture().nozzle_pwm();
    EXPECT_EQ(pwm.duty_pct(), std::vector<double>(6, 0.0));
    EXPECT_EQ(pwm.frequency_hz(), 0.0);
}

// Out of a steady level the first edge counts at once: a nozzle held on at 100 %
// is shut off by one falling edge, and the valve follows the line then, not
// steady_after_us (250 ms, 0.375 m at 1.5 m/s) later.
TEST(HidPwmCapture, TheFirstEdgeOutOfASteadyLevelIsTakenAtOnce) {
    Bench bench;
    bench.fake->set_pwm_source(0, {9.0, 100.0, 0.0});
    bench.fake->set_pwm_source(1, {9.0, 0.0, 0.0});
    bench.fake->set_pwm_source(2, {9.0, 100.0, 0.0});
    bench.run_us(600'000);
    ASSERT_EQ(bench.reading(0).state, State::steady);
    ASSERT_EQ(bench.reading(0).duty_pct, 100.0);
    ASSERT_EQ(bench.reading(1).duty_pct, 0.0);
    bench.fake->set_pwm_source(0, {9.0, 0.0, 0.0});    // shut off
    bench.fake->set_pwm_source(1, {9.0, 100.0, 0.0});  // switched full on
    bench.run_us(2 * kReadEveryUs);
    EXPECT_EQ(bench.reading(0).duty_pct, 0.0) << "a falling edge after 100 % is 0 % from that edge";
    EXPECT_EQ(bench.reading(1).duty_pct, 100.0) << "a rising edge after 0 % is 100 % from that edge";
    // A PWM that starts from a steady level reads as a PWM after its first complete period.
    bench.fake->set_pwm_source(2, {9.0, 50.0, 0.0});
    bench.run_us(300'000);
    expect_pwm(bench.reading(2), 50.0, 9.0, kDutyTolerancePct, "nozzle 2 from 100 % to 50 %");
}

TEST(HidPwmCapture, GlitchesAreRemovedAndABounceMovesAnEdgeByItsLength) {
    Bench bench;
    const double period_us = 1e6 / 9.0;
    for (int i = 0; i < 6; ++i) bench.fake->set_pwm_source(i, {9.0, 50.0, 0.0});
    bench.run_us(400'000);
    // Periods of every input start at k x period. Period 10 (1.111 s on):
    // input 3 gets a 20 us dip in its high phase and a 50 us spike in its low phase.
    const auto at = [&](int k, double after_us) { return static_cast<std::uint64_t>(k * period_us + after_us); };
    bench.fake->inject_edge(3, at(10, 20'000), false);
    bench.fake->inject_edge(3, at(10, 20'020), true);
    bench.fake->inject_edge(3, at(10, 80'000), true);
    bench.fake->inject_edge(3, at(10, 80'050), false);
    bench.run_us(900'000);  // past period 11's rising edge: period 10 measured
    EXPECT_EQ(bench.capture().glitches(), 2u);
    expect_pwm(bench.reading(3), 50.0, 9.0, kDutyTolerancePct, "input 3 after two glitches");
    // Period 12: input 4's falling edge bounces (fall, rise 30 us later, fall
    // 60 us later): the fall is taken 60 us late, 0.054 points of duty, once.
    // (The source's own fall, at the next microsecond, is replaced by the bounce.)
    bench.fake->suppress_edges(4, at(12, period_us / 2) + 1, at(12, period_us / 2) + 2);
    bench.fake->inject_edge(4, at(12, period_us / 2), false);
    bench.fake->inject_edge(4, at(12, period_us / 2 + 30), true);
    bench.fake->inject_edge(4, at(12, period_us / 2 + 60), false);
    bench.run_us(at(13, 1000) - bench.fake->now_us());
    EXPECT_EQ(bench.capture().glitches(), 3u);
    expect_pwm(bench.reading(4), 50.0 + 100.0 * 60.0 / period_us, 9.0, kDutyTolerancePct, "input 4, bounced period");
    bench.run_us(300'000);
    expect_pwm(bench.reading(4), 50.0, 9.0, kDutyTolerancePct, "input 4 after the bounce");
}

TEST(HidPwmCapture, AMissedEdgeDropsThatPeriodNotTheReading) {
    Bench bench;
    const double period_us = 1e6 / 9.0;
    for (int i = 0; i < 6; ++i) bench.fake->set_pwm_source(i, {9.0, 60.0, 0.0});
    bench.run_us(500'000);
    const std::uint64_t measured = bench.capture().periods();
    // Input 1 misses a falling edge (period 6), input 2 a rising edge (period 7).
    const auto fall = static_cast<std::uint64_t>(6 * period_us + 0.6 * period_us);
    const auto rise = static_cast<std::uint64_t>(7 * period_us);
    bench.fake->suppress_edges(1, fall - 2, fall + 2);
    bench.fake->suppress_edges(2, rise - 2, rise + 2);
    bench.run_us(1'000'000);
    EXPECT_GE(bench.capture().periods_dropped(), 2u);
    EXPECT_GT(bench.capture().periods(), measured);
    // Never a wrong value: the drop is counted and the next periods measure right.
    expect_pwm(bench.reading(1), 60.0, 9.0, kDutyTolerancePct, "input 1");
    expect_pwm(bench.reading(2), 60.0, 9.0, kDutyTolerancePct, "input 2");
}

TEST(HidPwmCapture, AFullEdgeBufferIsFlaggedAndCaptureRecovers) {
    Bench bench;
    // Six 2.5 kHz inputs make 30000 edges/s; the board sends at most 16 per
    // 1 ms: its buffer fills and edges are lost (a wrongly wired clock line, say).
    for (int i = 0; i < 6; ++i) bench.fake->set_pwm_source(i, {2500.0, 50.0, 37.0 * i});
    // Whatever survives is measured right or not at all: never a period
    // spliced across lost edges (which would read 1250 Hz, 833 Hz, ...).
    // 1 us of a 400 us period: 0.25 points of duty, 6.25 Hz.
    const std::int64_t switched_at_us = static_cast<std::int64_t>(bench.fake->now_us());
    for (int step = 0; step < 5; ++step) {
        bench.run_us(kReadEveryUs);
        for (int i = 0; i < 6; ++i) {
            const NozzlePwmReading& r = bench.reading(i);
            if (r.state != State::pwm || r.measured_at_us <= switched_at_us) continue;
            EXPECT_NEAR(r.frequency_hz, 2500.0, 12.5) << "input " << i << " at step " << step;
            EXPECT_NEAR(r.duty_pct, 50.0, 0.5) << "input " << i << " at step " << step;
        }
    }
    EXPECT_GT(bench.fake->edges_lost(), 0u);
    EXPECT_GE(bench.capture().overflows(), 1u);
    for (int i = 0; i < 6; ++i) bench.fake->set_pwm_source(i, {9.0, 35.0, 1000.0 * i});
    bench.run_us(800'000);
    for (int i = 0; i < 6; ++i) expect_pwm(bench.reading(i), 35.0, 9.0, kDutyTolerancePct, "input " + std::to_string(i));
}

TEST(HidPwmCapture, LostEdgeReportsRestartMeasurement) {
    Bench bench;
    for (int i = 0; i < 6; ++i) bench.fake->set_pwm_source(i, {9.0, 45.0, 2000.0 * i});
    bench.run_us(400'000);
    // The rig stalls for 0.5 s: 50 edge and 50 status reports overrun the
    // 64-report hidraw queue, the oldest are dropped.
    bench.fake->advance_us(500'000);
    bench.board->read_actuators();
    EXPECT_GT(bench.capture().reports_lost(), 0u);
    EXPECT_GT(bench.board->status_reports_lost(), 0u);
    bench.run_us(400'000);
    for (int i = 0; i < 6; ++i) expect_pwm(bench.reading(i), 45.0, 9.0, kDutyTolerancePct, "input " + std::to_string(i));
}

TEST(HidPwmCapture, TheBoardClockWrapsUnnoticed) {
    // Start 1 s before the 32-bit microsecond clock wraps (71.6 min of board time).
    Bench bench({}, (std::uint64_t{1} << 32) - 1'000'000);
    for (int i = 0; i < 6; ++i) bench.fake->set_pwm_source(i, {9.0, 10.0 * (i + 2), 333.0 * i});
    bench.run_us(2'500'000);
    ASSERT_GT(bench.fake->now_us(), std::uint64_t{1} << 32);
    for (int i = 0; i < 6; ++i) expect_pwm(bench.reading(i), 10.0 * (i + 2), 9.0, kDutyTolerancePct, "input " + std::to_string(i));
    EXPECT_EQ(bench.capture().periods_dropped(), 0u);
}

TEST(HidPwmCapture, AVersionOneBoardSaysItHasNoCapture) {
    auto transport = std::make_unique<FakeHidBoard>();
    transport->set_firmware_version(1);
    FakeHidBoard* fake = transport.get();
    HidBoard board(std::move(transport));
    // Without capture the rig speaks version 1 and the old board is fine.
    board.rebase({});
    fake->advance_us(10'000);
    board.read_actuators();
    ASSERT_TRUE(board.last_status());
    EXPECT_EQ(board.last_status()->protocol_version, 1);
    EXPECT_EQ(fake->edge_reports_sent(), 0u);
    // Asking for capture: the board refuses the version-2 command; the rig says why.
    board.enable_pwm_capture(0x3F);
    board.apply({}, 20'000'000);
    try {
        board.read_actuators();
        FAIL() << "a version-1 board's refusal passed unnoticed";
    } catch (const HidError& error) {
        const std::string what = error.what();
        EXPECT_NE(what.find("protocol version 1"), std::string::npos) << what;
        EXPECT_NE(what.find("PWM capture"), std::string::npos) << what;
    }
}

TEST(HidPwmCapture, AVersionTwoBoardAnswersAVersionOneRigInVersionOne) {
    // A rig that never asks for capture (every rig before version 2) sees
    // version-1 status reports and no edge reports, whatever the pins do.
    auto transport = std::make_unique<FakeHidBoard>();
    FakeHidBoard* fake = transport.get();
    HidBoard board(std::move(transport));
    fake->set_pwm_source(0, {9.0, 50.0, 0.0});
    board.rebase({});
    fake->advance_us(300'000);
    board.read_actuators();
    EXPECT_EQ(board.last_status()->protocol_version, 1);
    EXPECT_EQ(fake->edge_reports_sent(), 0u);
    EXPECT_EQ(board.pwm_capture(), nullptr);
}

TEST(HidPwmCapture, BadParametersAreRefused) {
    EXPECT_THROW(PwmCapture({200, 100}), std::invalid_argument);
    EXPECT_THROW(PwmCapture({200'000, 250'000}), std::invalid_argument);
    EXPECT_THROW(PwmCapture({100, 20'000'000}), std::invalid_argument);
    Bench bench;
    EXPECT_THROW(bench.board->enable_pwm_capture(0x40), std::invalid_argument);
    EXPECT_THROW(bench.capture().nozzle_pwm(7), std::invalid_argument);
}

}  // namespace
}  // namespace rig
