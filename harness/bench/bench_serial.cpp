#include "harness/bench/bench_serial.h"

#include <CLI/CLI.hpp>
#include <poll.h>
#include <signal.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <iostream>
#include <optional>

#include "rig/wire/pty_pair.h"
#include "rig/host/stop_signals.h"
#include "rig/wire/serial_port.h"

namespace rig::harness {
namespace {

std::string path_line(const char* label, const PtyPair& pty) {
    std::string line = std::string(label) + pty.slave_path();
    if (!pty.link_path().empty()) line += " (symlink " + pty.link_path().string() + ")";
    return line + "\n";
}

// Blocks until a stop signal arrives; returns its name.
std::string wait_for_stop(const StopSignals& stop) {
    while (true) {
        pollfd watch{stop.fd(), POLLIN, 0};
        if (::poll(&watch, 1, -1) > 0) return stop.take();
        if (errno != EINTR) throw std::runtime_error(std::string("poll: ") + std::strerror(errno));
    }
}

int run_linked(const PtyBenchOptions& options, const SerialSettings& settings, std::ostream& out) {
    const StopSignals stop;
    PtyLink link(PtyOptions{settings, options.link_a}, PtyOptions{settings, options.link_b});
    out << path_line("pty a: ", link.a()) << path_line("pty b: ", link.b())
        << "linked (" << describe(settings) << " nominal): bytes written to either path come out of the other; "
        << "Ctrl-C to stop" << std::endl;
    const std::string signal_name = wait_for_stop(stop);
    link.stop();
    out << "stopped by " << signal_name << ": a->b " << link.bytes_a_to_b() << " bytes, b->a " << link.bytes_b_to_a()
        << " bytes";
    if (const auto error = link.error()) out << "; " << *error;
    out << std::endl;
    return 0;
}

// One pty; the rig's side is this terminal: pty -> stdout, stdin -> pty.
int run_single(const PtyBenchOptions& options, const SerialSettings& settings, std::ostream& out) {
    const StopSignals stop;
    PtyPair pty(PtyOptions{settings, options.link_a});
    out << path_line("pty: ", pty) << "single (" << describe(settings)
        << " nominal): what a program writes to it appears here; standard input goes to it; Ctrl-C to stop"
        << std::endl;
    constexpr auto kWriteTimeout = std::chrono::milliseconds(5000);
    bool stdin_open = true;
    std::uint64_t bytes_in = 0;
    std::uint64_t bytes_out = 0;
    while (true) {
        std::array<pollfd, 3> watch{{{stop.fd(), POLLIN, 0},
                                     {pty.master().native_handle(), POLLIN, 0},
                                     {stdin_open ? STDIN_FILENO : -1, POLLIN, 0}}};
        if (::poll(watch.data(), watch.size(), -1) < 0) {
            if (errno == EINTR) continue;
            throw std::runtime_error(std::string("poll: ") + std::strerror(errno));
        }
        if (watch[0].revents != 0) {
            out << "stopped by " << stop.take() << ": " << bytes_in << " bytes from the pty, " << bytes_out
                << " bytes to it" << std::endl;
            return 0;
        }
        if (watch[1].revents != 0) {
            const std::string bytes = pty.master().read_some(std::chrono::milliseconds(0));
            bytes_in += bytes.size();
            out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
            out.flush();
        }
        if (watch[2].revents != 0) {
            std::array<char, 4096> buffer{};
            const ssize_t n = ::read(STDIN_FILENO, buffer.data(), buffer.size());
            if (n > 0) {
                pty.master().write_all(std::string_view(buffer.data(), static_cast<std::size_t>(n)), kWriteTimeout);
                bytes_out += static_cast<std::uint64_t>(n);
            } else if (n == 0 || errno != EINTR) {
                stdin_open = false;  // end of input: keep forwarding the other way
            }
        }
    }
}

}  // namespace

int run_pty_bench(const PtyBenchOptions& options, std::ostream& out, std::ostream& err) {
    SerialSettings settings;
    try {
        settings.baud = options.baud;
        apply_frame_format(options.frame, settings);
        validate(settings);
        if (options.single && !options.link_b.empty()) {
            throw std::invalid_argument("--link-b needs two ptys; with --single use --link-a");
        }
    } catch (const std::invalid_argument& error) {
        err << "rig pty: " << error.what() << "\n";
        return 2;
    }
    try {
        return options.single ? run_single(options, settings, out) : run_linked(options, settings, out);
    } catch (const std::exception& error) {
        err << "rig pty: " << error.what() << "\n";
        return 1;
    }
}

PtyBenchCommand::PtyBenchCommand(CLI::App& app) {
    command_ = app.add_subcommand(
        "pty", "bench wiring: a linked pair of pseudo-terminals (like a null-modem cable), or one with --single");
    command_->add_flag("--single", options_.single, "one pty, connected to this terminal (stdin/stdout)");
    command_->add_option("--link-a", options_.link_a, "make a symlink to pty a (or the single pty) at this path");
    command_->add_option("--link-b", options_.link_b, "make a symlink to pty b at this path");
    command_->add_option("--baud", options_.baud, "nominal baud set on the ptys (programs may read it back)");
    command_->add_option("--frame", options_.frame, "nominal frame format, e.g. 8N1, 7E1");
}

bool PtyBenchCommand::parsed() const { return command_->parsed(); }

int PtyBenchCommand::run() { return run_pty_bench(options_, std::cout, std::cerr); }

}  // namespace rig::harness
