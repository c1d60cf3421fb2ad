// The HID I/O board end to end against a fake that behaves like its firmware
// (tests/fake_hid_board.h): cumulative pulse counts arrive exactly, however
// reports overlap, come late or wrap; relay sensing maps to ActuatorCommands;
// faults from the board are clear errors. And with no board attached (these
// machines have none): a clear error, and `rig hid list` exits non-zero.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cctype>
#include <cstdio>
#include <random>
#include <string>

#include "rig/wire/hid_board.h"
#include "tests/fake_hid_board.h"

namespace rig {
namespace {

using testing::FakeHidBoard;
constexpr TimeNs kMs = 1'000'000;

struct Rig {
    FakeHidBoard* fake;  // owned by board
    HidBoard board;
};

Rig make_rig() {
    auto fake = std::make_unique<FakeHidBoard>();
    FakeHidBoard* raw = fake.get();
    return Rig{raw, HidBoard(std::move(fake))};
}

io::DeviceSignals counts(std::uint32_t wheel, std::uint32_t flow) {
    io::DeviceSignals signals;
    signals.wheel_encoder_count = wheel;
    signals.main_flow_pulses = flow;
    return signals;
}

TEST(HidBoard, FirstApplyRebasesThenPulsesSpreadEvenly) {
    auto [fake, board] = make_rig();
    board.apply(counts(1'000'000, 500), 200 * kMs);  // the run starts where the board is
    EXPECT_EQ(fake->wheel_encoder_emitted(), 1'000'000u);
    EXPECT_EQ(fake->main_flow_emitted(), 500u);

    board.apply(counts(1'001'000, 590), 100 * kMs);  // +1000 and +90 over 100 ms
    fake->advance_us(50'000);
    EXPECT_EQ(fake->wheel_encoder_emitted(), 1'000'500u);  // the k-th of n at k * interval / n
    EXPECT_EQ(fake->main_flow_emitted(), 545u);
    board.read_actuators();
    EXPECT_TRUE(board.last_status()->pulses_pending);
    fake->advance_us(50'000);
    EXPECT_EQ(fake->wheel_encoder_emitted(), 1'001'000u);
    EXPECT_EQ(fake->main_flow_emitted(), 590u);
    board.read_actuators();
    EXPECT_FALSE(board.last_status()->pulses_pending);
    EXPECT_EQ(board.last_status()->wheel_encoder_emitted, 1'001'000u);
    EXPECT_EQ(board.last_status()->last_command_sequence, board.last_command_sequence());
}

TEST(HidBoard, ANewCommandSupersedesTheRestOfTheOldOne) {
    auto [fake, board] = make_rig();
    board.apply(counts(0, 0), 0);
    board.apply(counts(1000, 0), 100 * kMs);
    fake->advance_us(30'000);
    EXPECT_EQ(fake->wheel_encoder_emitted(), 300u);
    board.apply(counts(1500, 0), 100 * kMs);  // 1200 left, over a fresh 100 ms
    fake->advance_us(50'000);
    EXPECT_EQ(fake->wheel_encoder_emitted(), 900u);
    fake->advance_us(50'000);
    EXPECT_EQ(fake->wheel_encoder_emitted(), 1500u);
    fake->advance_us(1'000'000);
    EXPECT_EQ(fake->wheel_encoder_emitted(), 1500u);  // and not one more
}

TEST(HidBoard, CumulativeCountsArriveExactlyThroughLateAndOverlappingReports) {
    auto [fake, board] = make_rig();
    std::mt19937 random(5);
    std::uint32_t wheel = 0xFFFFC000u;  // wraps at 2^32 on the way
    std::uint32_t flow = 7;
    board.apply(counts(wheel, flow), 0);
    std::uint32_t last_wheel_seen = wheel;
    for (int step = 0; step < 2000; ++step) {
        // The rig's 20 Hz loop: counts grow by what the plant produced...
        wheel += static_cast<std::uint32_t>(random() % 60);  // up to 1200 Hz
        flow += static_cast<std::uint32_t>(random() % 20);
        board.apply(counts(wheel, flow), 50 * kMs);
        // ...and the board's time runs a little early or late against it.
        fake->advance_us(30'000 + random() % 40'000);
        board.read_actuators();
        const hid::BoardStatus& status = *board.last_status();
        // Never ahead of the target, never backwards.
        EXPECT_GE(hid::counter_ahead(status.wheel_encoder_emitted, wheel), 0) << step;
        EXPECT_GE(hid::counter_ahead(last_wheel_seen, status.wheel_encoder_emitted), 0) << step;
        EXPECT_GE(hid::counter_ahead(status.main_flow_emitted, flow), 0) << step;
        last_wheel_seen = status.wheel_encoder_emitted;
    }
    fake->advance_us(1'000'000);
    board.read_actuators();
    EXPECT_EQ(fake->wheel_encoder_emitted(), wheel);
    EXPECT_EQ(fake->main_flow_emitted(), flow);
    EXPECT_EQ(board.last_status()->wheel_encoder_emitted, wheel);
    EXPECT_EQ(board.last_status()->main_flow_emitted, flow);
    EXPECT_LT(wheel, 0xFFFFC000u) << "the counter did not wrap: the test lost its point";
}

TEST(HidBoard, AFasterDemandThanTheBoardCanPulseArrivesLateNotLost) {
    auto [fake, board] = make_rig();
    board.apply(counts(0, 0), 0);
    board.apply(counts(100'000, 0), 1 * kMs);  // 100 MHz asked, 20 kHz possible
    fake->advance_us(1'000);
    board.read_actuators();
    EXPECT_TRUE(board.last_status()->rate_limited);
    EXPECT_EQ(fake->wheel_encoder_emitted(), 20u);
    fake->advance_us(5'000'000);
    EXPECT_EQ(fake->wheel_encoder_emitted(), 100'000u);
}

TEST(HidBoard, CountsThatGoBackwardsAreRefused) {
    auto [fake, board] = make_rig();
    board.apply(counts(500, 500), 0);
    try {
        board.apply(counts(499, 600), 10 * kMs);
        FAIL();
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("wheel_encoder_count went back from 500 to 499"), std::string::npos)
            << error.what();
    }
    EXPECT_THROW(board.apply(counts(600, 600), -1), std::invalid_argument);
    EXPECT_EQ(fake->commands_applied(), 1u);  // nothing was sent
    board.rebase(counts(10, 10));             // starting over is explicit
    EXPECT_EQ(fake->wheel_encoder_emitted(), 10u);
}

TEST(HidBoard, LevelsAndAnalogCodesReachTheBoard) {
    auto [fake, board] = make_rig();
    io::DeviceSignals signals = counts(0, 0);
    signals.breakpoint_button = true;
    signals.spray_switch = true;
    signals.pump_flow_adc = 2048;
    signals.boom_height_adc = 1234;
    board.apply(signals, 0);
    const io::DeviceSignals outputs = fake->outputs();
    EXPECT_TRUE(outputs.breakpoint_button);
    EXPECT_TRUE(outputs.spray_switch);
    EXPECT_EQ(outputs.pump_flow_adc, 2048);
    EXPECT_EQ(outputs.boom_height_adc, 1234);
    signals.pump_flow_adc = 4096;
    EXPECT_THROW(board.apply(signals, 0), std::invalid_argument);
}

TEST(HidBoard, RelaySensingMapsToActuatorCommands) {
    auto [fake, board] = make_rig();
    board.apply(counts(0, 0), 0);
    EXPECT_FALSE(board.read_actuators().ball_valve_forward);

    io::ActuatorCommands relays;
    relays.ball_valve_forward = true;
    relays.ball_valve_reverse = false;
    relays.unloading_valve_open = true;
    relays.section_valves_open = 0b1011'0101;
    fake->set_relay_inputs(relays);
    io::ControllerIndicators indicators;
    indicators.breakpoints_stored = 2;
    indicators.breakpoints_reached = 1;
    indicators.odometer_active = true;
    fake->set_indicator_inputs(indicators);

    const io::ActuatorCommands sensed = board.read_actuators();
    EXPECT_TRUE(sensed.ball_valve_forward);
    EXPECT_FALSE(sensed.ball_valve_reverse);
    EXPECT_TRUE(sensed.unloading_valve_open);
    EXPECT_EQ(sensed.section_valves_open, 0b1011'0101);
    EXPECT_EQ(board.indicators().breakpoints_stored, 2);
    EXPECT_EQ(board.indicators().breakpoints_reached, 1);
    EXPECT_TRUE(board.indicators().odometer_active);
    EXPECT_FALSE(board.indicators().breakpoint_pending);

    relays.ball_valve_forward = false;
    relays.ball_valve_reverse = true;
    fake->set_relay_inputs(relays);
    EXPECT_TRUE(board.read_actuators().ball_valve_reverse);
}

TEST(HidBoard, LostStatusReportsAreCounted) {
    auto [fake, board] = make_rig();
    board.apply(counts(0, 0), 0);
    board.read_actuators();
    fake->advance_us(2'000'000);  // 200 periodic reports; the queue keeps the last 64
    board.read_actuators();
    EXPECT_EQ(board.status_reports_lost(), 200u - FakeHidBoard::kQueueCapacity);
}

TEST(HidBoard, BoardFaultsAreClearErrors) {
    auto [fake, board] = make_rig();
    board.apply(counts(0, 0), 0);
    board.read_actuators();

    std::vector<std::uint8_t> foreign(64, 0);
    foreign[0] = 0x05;  // another gadget on the shared test PID
    fake->queue_raw_report(foreign);
    try {
        board.read_actuators();
        FAIL();
    } catch (const HidError& error) {
        EXPECT_EQ(std::string(error.what()),
                  "fake HID I/O board: malformed status report: report id 0x05, expected 0x02 (status)");
    }

    const std::vector<std::uint8_t> garbage(64, 0xFF);  // a command the firmware must refuse
    board.transport().write_report(garbage);
    try {
        board.read_actuators();
        FAIL();
    } catch (const HidError& error) {
        EXPECT_NE(std::string(error.what()).find("the board refused the last command report (wrong report id)"),
                  std::string::npos)
            << error.what();
    }
}

// A board that never answers.
class SilentTransport final : public HidTransport {
public:
    void write_report(std::span<const std::uint8_t>) override {}
    std::optional<std::vector<std::uint8_t>> read_report(std::chrono::milliseconds) override { return std::nullopt; }
    std::string description() const override { return "silent board"; }
};

TEST(HidBoard, SilentBoardIsABoundedError) {
    HidBoard board(std::make_unique<SilentTransport>(), std::chrono::milliseconds(50));
    try {
        board.read_actuators();
        FAIL();
    } catch (const HidError& error) {
        EXPECT_EQ(std::string(error.what()), "silent board: no status report within 50 ms");
    }
}

// --- no board attached ---------------------------------------------------------

// "no HID I/O board VID:PID 1209:0001 found (N HID devices present)" somewhere in
// `text`, N being however many HID devices this machine has. (No std::regex:
// GCC 12's sanitizer build warns inside <regex>.)
bool says_no_board(const std::string& text) {
    const std::string head = "no HID I/O board VID:PID 1209:0001 found (";
    const std::size_t start = text.find(head);
    if (start == std::string::npos) return false;
    std::size_t digits_end = start + head.size();
    while (digits_end < text.size() && std::isdigit(static_cast<unsigned char>(text[digits_end]))) ++digits_end;
    if (digits_end == start + head.size()) return false;
    const std::string tail = text.substr(digits_end);
    return tail.starts_with(" HID devices present)") || tail.starts_with(" HID device present)");
}

TEST(HidBoardAbsent, OpeningSaysNoBoardAndHowManyHidDevices) {
    if (!list_hid_boards().empty()) GTEST_SKIP() << "a board with the default VID:PID is attached";
    try {
        HidapiTransport::open();
        FAIL();
    } catch (const HidError& error) {
        EXPECT_TRUE(says_no_board(error.what())) << error.what();
    }
    EXPECT_EQ(no_board_message(0x1209, 0xbeef, 1), "no HID I/O board VID:PID 1209:beef found (1 HID device present)");
}

// Runs `rig ARGS` and returns {exit status, stdout + stderr}.
std::pair<int, std::string> run_rig(const std::string& args) {
    const std::string command = "'" RIG_BINARY_DIR "/bin/rig' " + args + " 2>&1";
    FILE* pipe = ::popen(command.c_str(), "r");
    if (pipe == nullptr) return {-1, "popen failed"};
    std::string output;
    char buffer[512];
    while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
    const int status = ::pclose(pipe);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

TEST(HidBoardAbsent, RigHidListExitsNonZeroWithTheReason) {
    if (!list_hid_boards().empty()) GTEST_SKIP() << "a board with the default VID:PID is attached";
    for (const char* args : {"hid list", "hid list --vid 0x1209 --pid 0x0001", "hid list --vid 1209 --pid 1"}) {
        const auto [status, output] = run_rig(args);
        EXPECT_EQ(status, 1) << args << ": " << output;
        EXPECT_TRUE(says_no_board(output)) << args << ": " << output;
        EXPECT_EQ(output.rfind("rig hid list: ", 0), 0u) << output;
    }
    const auto [status, output] = run_rig("hid list --vid 0x12345");
    EXPECT_EQ(status, 2) << output;
    EXPECT_NE(output.find("--vid '0x12345' is not a USB id"), std::string::npos) << output;
}

}  // namespace
}  // namespace rig
