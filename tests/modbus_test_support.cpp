#include "modbus_test_support.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "rig/runtime/clock.h"

namespace rig::modbus::testing {
namespace {

sockaddr_in loopback(std::uint16_t port) {
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    return address;
}

std::string read_file(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

int remaining_ms(const WallStopwatch& clock, std::chrono::milliseconds limit) {
    const auto left = limit - clock.elapsed();
    return left.count() > 0 ? static_cast<int>(left.count()) : 0;
}

}  // namespace

std::filesystem::path fresh_dir(const std::string& name) {
    const auto dir = std::filesystem::path(::testing::TempDir()) / ("modbus-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

bool eventually(const std::function<bool()>& condition, std::chrono::milliseconds timeout) {
    const WallStopwatch clock;
    while (!condition()) {
        if (clock.elapsed() > timeout) return condition();
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return true;
}

CommandResult run_command(const std::string& command, int timeout_s) {
    const std::string bounded = "timeout -k 5 " + std::to_string(timeout_s) + " " + command + " 2>&1";
    CommandResult result;
    FILE* pipe = ::popen(bounded.c_str(), "r");
    if (pipe == nullptr) {
        result.output = "popen failed: " + std::string(std::strerror(errno));
        return result;
    }
    char buffer[4096];
    std::size_t got = 0;
    while ((got = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) result.output.append(buffer, got);
    const int status = ::pclose(pipe);
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return result;
}

bool require_tool(const std::string& tool) {
    const char* path = std::getenv("PATH");
    std::stringstream directories(path != nullptr ? path : "/usr/bin:/bin");
    for (std::string directory; std::getline(directories, directory, ':');) {
        if (!directory.empty() && ::access((std::filesystem::path(directory) / tool).c_str(), X_OK) == 0) return true;
    }
    ADD_FAILURE() << tool << " is not installed; it is in scripts/debian-packages.txt (scripts/setup installs it)";
    return false;
}

PtyPair::PtyPair(const std::string& name) : dir_(fresh_dir(name)) {
    socat_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{"socat", "-d", "-d", "pty,raw,echo=0,link=" + (dir_ / "A").string(),
                                 "pty,raw,echo=0,link=" + (dir_ / "B").string()},
        dir_ / "socat.log");
    // socat logs this once both ends exist and it copies between them.
    const bool up = eventually([&] { return read_file(dir_ / "socat.log").find("starting data transfer loop") != std::string::npos; },
                               std::chrono::milliseconds(20000));
    if (!up) {
        throw std::runtime_error("socat did not come up in 20 s; its log: " + read_file(dir_ / "socat.log"));
    }
}

PtyPair::~PtyPair() {
    if (!socat_) return;
    ::kill(socat_->pid(), SIGTERM);  // socat never ends by itself: ask at once, then let stop() wait
    socat_->stop(std::chrono::milliseconds(3000));
}

RawSerial::RawSerial(const std::string& path) {
    fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) throw std::runtime_error("cannot open " + path + ": " + std::strerror(errno));
    termios settings{};
    if (::tcgetattr(fd_, &settings) == 0) {
        ::cfmakeraw(&settings);
        ::tcsetattr(fd_, TCSANOW, &settings);
    }
}

RawSerial::~RawSerial() {
    if (fd_ >= 0) ::close(fd_);
}

void RawSerial::write(const Bytes& bytes) {
    std::size_t written = 0;
    const WallStopwatch clock;
    while (written < bytes.size() && clock.elapsed() < std::chrono::milliseconds(5000)) {
        const ssize_t result = ::write(fd_, bytes.data() + written, bytes.size() - written);
        if (result > 0) {
            written += static_cast<std::size_t>(result);
        } else {
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
    }
    if (written < bytes.size()) throw std::runtime_error("raw serial write did not complete");
}

Bytes RawSerial::read(std::size_t count, std::chrono::milliseconds timeout) {
    Bytes received;
    const WallStopwatch clock;
    while (received.size() < count) {
        pollfd fds{fd_, POLLIN, 0};
        const int wait_ms = remaining_ms(clock, timeout);
        if (wait_ms <= 0 || ::poll(&fds, 1, wait_ms) <= 0) break;
        std::uint8_t chunk[512];
        const ssize_t got = ::read(fd_, chunk, std::min(sizeof chunk, count - received.size()));
        if (got <= 0) break;
        received.insert(received.end(), chunk, chunk + got);
    }
    return received;
}

Bytes RawSerial::read_pending(std::chrono::milliseconds look) {
    return read(4096, look);
}

RawTcpClient::RawTcpClient(std::uint16_t port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const sockaddr_in address = loopback(port);
    if (fd_ < 0 || ::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
        throw std::runtime_error("raw client cannot connect to 127.0.0.1:" + std::to_string(port) + ": " +
                                 std::strerror(errno));
    }
}

RawTcpClient::~RawTcpClient() { close(); }

void RawTcpClient::close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
}

void RawTcpClient::send(const Bytes& bytes) {
    if (::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(bytes.size())) {
        throw std::runtime_error(std::string("raw client send failed: ") + std::strerror(errno));
    }
}

Bytes RawTcpClient::receive(std::size_t count, std::chrono::milliseconds timeout) {
    Bytes received;
    const WallStopwatch clock;
    while (received.size() < count) {
        pollfd fds{fd_, POLLIN, 0};
        const int wait_ms = remaining_ms(clock, timeout);
        if (wait_ms <= 0 || ::poll(&fds, 1, wait_ms) <= 0) break;
        std::uint8_t chunk[512];
        const ssize_t got = ::recv(fd_, chunk, std::min(sizeof chunk, count - received.size()), 0);
        if (got <= 0) break;
        received.insert(received.end(), chunk, chunk + got);
    }
    return received;
}

bool RawTcpClient::closed_by_peer(std::chrono::milliseconds timeout) {
    const WallStopwatch clock;
    for (;;) {
        pollfd fds{fd_, POLLIN, 0};
        const int wait_ms = remaining_ms(clock, timeout);
        if (wait_ms <= 0 || ::poll(&fds, 1, wait_ms) <= 0) return false;
        std::uint8_t chunk[512];
        const ssize_t got = ::recv(fd_, chunk, sizeof chunk, 0);
        if (got == 0) return true;
        if (got < 0) return errno == ECONNRESET;
    }
}

SilentTcpListener::SilentTcpListener() {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address = loopback(0);
    socklen_t length = sizeof address;
    if (fd_ < 0 || ::bind(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0 ||
        ::listen(fd_, 4) != 0 || ::getsockname(fd_, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
        throw std::runtime_error(std::string("silent listener: ") + std::strerror(errno));
    }
    port_ = ntohs(address.sin_port);
}

SilentTcpListener::~SilentTcpListener() {
    if (fd_ >= 0) ::close(fd_);
}

std::uint16_t unused_tcp_port() {
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address = loopback(0);
    socklen_t length = sizeof address;
    ::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address);
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
    ::close(fd);
    return ntohs(address.sin_port);
}

Bytes tcp_frame(std::uint16_t transaction_id, const Bytes& pdu, std::uint8_t unit_id,
                std::optional<std::uint16_t> length_field, std::uint16_t protocol_id) {
    const auto length = length_field.value_or(static_cast<std::uint16_t>(pdu.size() + 1));
    Bytes frame;
    frame.reserve(7 + pdu.size());
    for (std::uint16_t word : {transaction_id, protocol_id, length}) {
        frame.push_back(static_cast<std::uint8_t>(word >> 8));
        frame.push_back(static_cast<std::uint8_t>(word & 0xFF));
    }
    frame.push_back(unit_id);
    for (std::uint8_t byte : pdu) frame.push_back(byte);
    return frame;
}

}  // namespace rig::modbus::testing
