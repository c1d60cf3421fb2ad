// Seed 001's bench path with the Pi's PWM measured by the HID I/O board
// (`wiring: { board_io: hid, controller: external }`, docs/seed001-boundary.md
// "Bench path"), the whole run in one process: the rig's real-time runner
// (harness::run_case) with the in-process fake board (tests/fake_hid_board.h)
// as its HID transport, the fake's clock following the wall clock; a "Pi"
// process attaches to the two ptys from attach.json, runs the reference logic
// on the RMC and laser lines, and drives the fake board's six capture inputs
// with its PWM. What reaches the plant is what the board captured
// (NozzlePwmCaptureAdapter -> actuator/nozzle_pwm/duty), and the drive out is
// judged on the wired case's limit plus the capture's steady-level window,
// with the rig's lateness valid. (The Pi
// is a forked process: the rig sees a board attach by another process opening
// the ptys.)
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "controller/boundary/boundary_controller.h"
#include "controller/boundary/boundary_node_config.h"
#include "fake_hid_board.h"
#include "harness/run/case_runner.h"
#include "harness/spec/case_spec.h"
#include "harness/systems/systems.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/realtime.h"
#include "rig/wire/serial_port.h"
#include "run_support.h"

namespace fs = std::filesystem;

namespace {

// The fake board on the wall clock: before the rig or the Pi touches it, its
// clock is brought up to now (it only moves when told, tests/fake_hid_board.h).
class WallClockBoard {
public:
    void set_pwm(int input, const rig::testing::FakeHidBoard::PwmSource& source) {
        std::lock_guard lock(mutex_);
        catch_up();
        board_.set_pwm_source(input, source);
    }
    std::uint64_t edges_captured() {
        std::lock_guard lock(mutex_);
        return board_.edges_captured();
    }

    // The rig's side: a HidTransport onto the shared board.
    class Transport final : public rig::HidTransport {
    public:
        explicit Transport(WallClockBoard& shared) : shared_(shared) {}
        void write_report(std::span<const std::uint8_t> report) override {
            std::lock_guard lock(shared_.mutex_);
            shared_.catch_up();
            shared_.board_.write_report(report);
        }
        std::optional<std::vector<std::uint8_t>> read_report(std::chrono::milliseconds timeout) override {
            std::lock_guard lock(shared_.mutex_);
            shared_.catch_up();
            return shared_.board_.read_report(timeout);
        }
        std::string description() const override { return "fake HID I/O board on the wall clock"; }

    private:
        WallClockBoard& shared_;
    };

private:
    void catch_up() {
        const auto now_us = static_cast<std::uint64_t>(clock_.now_ns() / 1000);
        if (now_us > board_.now_us()) board_.advance_us(now_us - board_.now_us());
    }
    std::mutex mutex_;
    rig::RealtimeClock clock_;
    rig::testing::FakeHidBoard board_;
};

std::string port_of(const nlohmann::json& attach, const std::string& role) {
    for (const nlohmann::json& port : attach.at("ports")) {
        if (port.at("role") == role) return port.at("path").get<std::string>();
    }
    return {};
}

// The Pi, in a process of its own (the rig waits for another process to open
// the ptys, harness/session/board_attach.h): the reference logic on the two lines; each
// duty change goes to the parent as "nozzle frequency_hz duty_pct\n" on
// `duty_fd`, which puts it on the fake board's capture input of that nozzle
// (nozzle n on input n, docs/hid-io-board.md "Wiring a Raspberry Pi"). Ends
// when the rig closes the lines at the case's end; returns the exit code.
int pi_main(const fs::path& attach_file, int duty_fd) {
    const rig::RealtimeClock clock;
    while (!fs::exists(attach_file)) {
        if (rig::ns_to_seconds(clock.now_ns()) > 60.0) {
            std::cerr << "pi: no attach.json at " << attach_file << "\n";
            return 1;
        }
        clock.sleep_until_ns(clock.now_ns() + rig::seconds_to_ns(0.02));
    }
    // A Pi's controller loop runs at real-time priority, as the reference controller asks.
    std::cerr << "pi: " << rig::request_realtime_scheduling(40).detail << "\n";
    try {
        std::ifstream in(attach_file);
        const nlohmann::json attach = nlohmann::json::parse(in);
        rig::controller::boundary::BoundaryController logic(
            rig::controller::boundary::load_boundary_node_config(
                attach_file.parent_path() / "controller.yaml",
                attach_file.parent_path() / attach.at("job").get<std::string>())
                .controller);
        rig::SerialPort rmc(port_of(attach, "gnss_nmea"));
        rig::SerialPort laser(port_of(attach, "laser_serial"));
        std::vector<double> driven;
        for (;;) {
            const rig::TimeNs now = clock.now_ns();
            while (auto line = laser.read_line(std::chrono::milliseconds(0))) logic.on_laser_line(*line, now);
            while (auto line = rmc.read_line(std::chrono::milliseconds(0))) logic.on_nmea_sentence(*line, now);
            logic.update(now);
            const std::vector<double>& duty = logic.duty_pct();
            for (std::size_t n = 0; n < duty.size(); ++n) {
                if (driven.size() == duty.size() && driven[n] == duty[n]) continue;
                const std::string change = std::to_string(n) + " " + std::to_string(logic.pwm_frequency_hz()) + " " +
                                           std::to_string(duty[n]) + "\n";
                if (::write(duty_fd, change.data(), change.size()) != static_cast<ssize_t>(change.size())) return 1;
            }
            driven = duty;
            clock.sleep_until_ns(now + rig::seconds_to_ns(0.005));  // a 200 Hz loop, as a Pi's would be
        }
    } catch (const rig::SerialError& error) {
        if (error.kind() == rig::SerialError::Kind::closed) return 0;  // the case is over
        std::cerr << "pi: " << error.what() << "\n";
    } catch (const std::exception& error) {
        std::cerr << "pi: " << error.what() << "\n";
    }
    return 1;
}

// The capture inputs' side: the Pi's duty changes onto the board, until the Pi ends.
void drive_capture_inputs(int duty_fd, WallClockBoard& board) {
    std::string pending;
    char buffer[512];
    for (;;) {
        const ssize_t got = ::read(duty_fd, buffer, sizeof buffer);
        if (got <= 0) return;
        pending.append(buffer, static_cast<std::size_t>(got));
        for (std::size_t end = pending.find('\n'); end != std::string::npos; end = pending.find('\n')) {
            std::istringstream change(pending.substr(0, end));
            pending.erase(0, end + 1);
            int nozzle = 0;
            double frequency_hz = 0.0, duty_pct = 0.0;
            if (change >> nozzle >> frequency_hz >> duty_pct) board.set_pwm(nozzle, {frequency_hz, duty_pct, 0.0});
        }
    }
}

}  // namespace

TEST(Seed001BenchHidRealTime, ThePisPwmCapturedByTheBoardPassesTheDriveOut) {
    const fs::path dir = rig::testing::fresh_dir("seed001-bench-hid");
    std::string text = rig::testing::read_all(RIG_SOURCE_DIR "/cases/bench-wired/seed001-drive-out-wired.yaml");
    const std::string wiring = "\nwiring:\n";
    const std::size_t at = text.find(wiring);
    ASSERT_NE(at, std::string::npos);
    text.insert(at + wiring.size(), "  controller: external\n  board_io: hid\n");
    // The case's own limit, as on the DDS path: a nozzle at 100 % is a steady
    // high line, and the capture takes its shut-off (one falling edge) at once
    // (rig/wire/pwm_capture.h), not steady_after_us later (0.375 m at 1.5 m/s).
    ASSERT_NE(text.find("drive_out_excess_mean_m: 0.67"), std::string::npos);
    const fs::path case_file = dir / "drive-out-hid.yaml";
    std::ofstream(case_file) << text;
    const rig::harness::CaseSpec spec = rig::harness::load_case_file(case_file);

    WallClockBoard board;
    rig::harness::RunOptions options;
    options.out_dir = dir / "out";
    options.open_hid = [&board](std::uint16_t, std::uint16_t) { return std::make_unique<WallClockBoard::Transport>(board); };
    // The Pi's process first, while this one has no other thread (fork).
    int duty_pipe[2];
    ASSERT_EQ(::pipe(duty_pipe), 0);
    const pid_t pi = ::fork();
    ASSERT_GE(pi, 0);
    if (pi == 0) {
        ::close(duty_pipe[0]);
        ::_exit(pi_main(options.out_dir / "cases" / spec.name / "attach.json", duty_pipe[1]));
    }
    ::close(duty_pipe[1]);
    std::thread capture_inputs([&] { drive_capture_inputs(duty_pipe[0], board); });
    // The board's pins follow the Pi at once, however busy the machine: above
    // the rig's wire threads' 45, as a separate board would be.
    rig::raise_thread_to_realtime(capture_inputs, 46);
    const rig::harness::CaseRun run = rig::harness::run_case(spec, options);
    int pi_status = 0;
    // The Pi leaves when the rig closes the lines; one that did not is stopped.
    const rig::RealtimeClock waited;
    while (::waitpid(pi, &pi_status, WNOHANG) == 0) {
        if (rig::ns_to_seconds(waited.now_ns()) > 10.0) {
            ::kill(pi, SIGKILL);
            ::waitpid(pi, &pi_status, 0);
            break;
        }
        waited.sleep_until_ns(waited.now_ns() + rig::seconds_to_ns(0.05));
    }
    capture_inputs.join();
    ::close(duty_pipe[0]);
    EXPECT_TRUE(WIFEXITED(pi_status) && WEXITSTATUS(pi_status) == 0) << "the Pi process: status " << pi_status;

    const rig::harness::CaseResult& result = run.result;
    EXPECT_TRUE(result.passed) << result.error_kind << ": " << result.error;
    EXPECT_EQ(result.error_kind, "") << result.error;
    EXPECT_EQ(result.controller_mode, "external");
    EXPECT_NE(result.wiring.find("board_io hid fake HID I/O board on the wall clock"), std::string::npos) << result.wiring;
    EXPECT_NE(result.wiring.find("laser serial /dev/pts/"), std::string::npos) << result.wiring;
    // The board captured the Pi's edges (each of the six nozzles at least
    // opened and closed), and the plant sprayed and shut off by them.
    EXPECT_GE(board.edges_captured(), 12u);
    ASSERT_TRUE(result.metrics.contains("drive_out_excess_mean_m"));
    EXPECT_EQ(result.metrics.at("drive_out_excess_stations"), 8.0);
    EXPECT_EQ(result.metrics.at("drive_out_excess_stations_dry"), 0.0);
    EXPECT_LE(result.metrics.at("drive_out_excess_mean_m"), result.limits.at("drive_out_excess_mean_m"));
    // The rig kept time: its lateness verdict is valid.
    ASSERT_TRUE(result.rig_lateness.is_object());
    EXPECT_EQ(result.rig_lateness.value("overloaded", std::string("?")), "") << result.rig_lateness.dump(2);
}
