#include "rig/wire/serial_port.h"

#include <fcntl.h>
#include <grp.h>
#include <poll.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <utility>

namespace rig {
namespace {

struct BaudConstant {
    int baud;
    speed_t constant;
};

constexpr std::array<BaudConstant, 16> kBaudTable{{
    {1200, B1200},       {2400, B2400},       {4800, B4800},       {9600, B9600},
    {19200, B19200},     {38400, B38400},     {57600, B57600},     {115200, B115200},
    {230400, B230400},   {460800, B460800},   {500000, B500000},   {576000, B576000},
    {921600, B921600},   {1000000, B1000000}, {1500000, B1500000}, {2000000, B2000000},
}};

constexpr std::array<int, kBaudTable.size()> kSupportedBauds = [] {
    std::array<int, kBaudTable.size()> bauds{};
    for (std::size_t i = 0; i < kBaudTable.size(); ++i) bauds[i] = kBaudTable[i].baud;
    return bauds;
}();

std::optional<speed_t> speed_constant(int baud) {
    for (const auto& entry : kBaudTable) {
        if (entry.baud == baud) return entry.constant;
    }
    return std::nullopt;
}

tcflag_t character_size_flag(int data_bits) {
    switch (data_bits) {
        case 5: return CS5;
        case 6: return CS6;
        case 7: return CS7;
        default: return CS8;
    }
}

constexpr const char* kHungUp = "port closed: the other side hung up (pty peer closed, or device unplugged)";

std::string errno_text(int error) {
    return std::string(std::strerror(error)) + " (errno " + std::to_string(error) + ")";
}

// Milliseconds left of `timeout` after `stopwatch` started, never negative.
int remaining_ms(const WallStopwatch& stopwatch, std::int64_t timeout_ms) {
    const std::int64_t left = timeout_ms - stopwatch.elapsed().count();
    return static_cast<int>(std::clamp<std::int64_t>(left, 0, 1'000'000'000));
}

// Why a device node cannot be opened by this user, with the group to join when
// the node belongs to one (Debian: dialout for serial adapters).
std::string permission_cause(const std::string& path) {
    std::string cause = "permission denied";
    struct stat info {};
    if (::stat(path.c_str(), &info) == 0) {
        if (const group* owner_group = ::getgrgid(info.st_gid); owner_group != nullptr && info.st_gid != 0) {
            cause += " (the device belongs to group '" + std::string(owner_group->gr_name) +
                     "'; add the user to it, then log in again)";
        }
    }
    return cause;
}

// A pty slave (Unix98 majors 136-143) or master (/dev/ptmx, 5:2).
bool is_pseudo_terminal(int fd) {
    struct stat info {};
    if (::fstat(fd, &info) != 0 || !S_ISCHR(info.st_mode)) return false;
    const unsigned device_major = major(info.st_rdev);
    constexpr unsigned kFirstPtySlaveMajor = 136, kLastPtySlaveMajor = 143;
    constexpr unsigned kTtyAuxMajor = 5, kPtmxMinor = 2;
    return (device_major >= kFirstPtySlaveMajor && device_major <= kLastPtySlaveMajor) ||
           (device_major == kTtyAuxMajor && minor(info.st_rdev) == kPtmxMinor);
}

}  // namespace

std::span<const int> supported_bauds() { return kSupportedBauds; }

std::string describe(const SerialSettings& settings) {
    const char parity = settings.parity == Parity::none ? 'N' : settings.parity == Parity::even ? 'E' : 'O';
    return std::to_string(settings.baud) + " " + std::to_string(settings.data_bits) + parity +
           std::to_string(settings.stop_bits);
}

void apply_frame_format(std::string_view frame_format, SerialSettings& settings) {
    const auto bad = [&](const std::string& why) {
        return std::invalid_argument("serial frame format '" + std::string(frame_format) + "': " + why +
                                     " (expected data bits 5-8, parity N/E/O, stop bits 1-2, e.g. 8N1)");
    };
    if (frame_format.size() != 3) throw bad("not three characters");
    const char data = frame_format[0];
    const char parity = static_cast<char>(frame_format[1] & ~0x20);  // upper case
    const char stop = frame_format[2];
    if (data < '5' || data > '8') throw bad("data bits must be 5, 6, 7 or 8");
    if (parity != 'N' && parity != 'E' && parity != 'O') throw bad("parity must be N, E or O");
    if (stop != '1' && stop != '2') throw bad("stop bits must be 1 or 2");
    settings.data_bits = data - '0';
    settings.parity = parity == 'N' ? Parity::none : parity == 'E' ? Parity::even : Parity::odd;
    settings.stop_bits = stop - '0';
}

void validate(const SerialSettings& settings) {
    if (!speed_constant(settings.baud)) {
        std::string list;
        for (int baud : kSupportedBauds) list += (list.empty() ? "" : ", ") + std::to_string(baud);
        throw std::invalid_argument("baud " + std::to_string(settings.baud) + " is not supported (supported: " +
                                    list + ")");
    }
    if (settings.data_bits < 5 || settings.data_bits > 8) {
        throw std::invalid_argument("data bits " + std::to_string(settings.data_bits) + " must be 5..8");
    }
    if (settings.stop_bits != 1 && settings.stop_bits != 2) {
        throw std::invalid_argument("stop bits " + std::to_string(settings.stop_bits) + " must be 1 or 2");
    }
    if (settings.parity != Parity::none && settings.parity != Parity::even && settings.parity != Parity::odd) {
        throw std::invalid_argument("parity must be none, even or odd");
    }
}

int bits_per_character(const SerialSettings& settings) {
    constexpr int kStartBits = 1;
    return kStartBits + settings.data_bits + (settings.parity == Parity::none ? 0 : 1) + settings.stop_bits;
}

TimeNs wire_time_ns(std::size_t bytes, const SerialSettings& settings) {
    if (settings.baud <= 0) throw std::invalid_argument("baud must be > 0 to compute wire time");
    // Integer arithmetic, split so that nothing overflows: bits * 1e9 / baud.
    constexpr std::uint64_t kNsPerSecond = 1'000'000'000;
    const auto baud = static_cast<std::uint64_t>(settings.baud);
    const std::uint64_t bits = bytes * static_cast<std::uint64_t>(bits_per_character(settings));
    const std::uint64_t whole_seconds = bits / baud;
    const std::uint64_t remainder_ns = ((bits % baud) * kNsPerSecond + baud / 2) / baud;
    return static_cast<TimeNs>(whole_seconds * kNsPerSecond + remainder_ns);
}

SerialPort::SerialPort(const std::string& path, const SerialSettings& settings) : path_(path) {
    try {
        validate(settings);
    } catch (const std::invalid_argument& error) {
        throw SerialError(SerialError::Kind::unsupported, path_, error.what());
    }
    // O_NONBLOCK: open must not wait for the carrier-detect line of a modem port.
    fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) {
        const int error = errno;
        switch (error) {
            case ENOENT:
                throw SerialError(SerialError::Kind::not_found, path_,
                                  "no such file or device (is the adapter plugged in? is the path right?)");
            case ENXIO:
            case ENODEV:
                throw SerialError(SerialError::Kind::not_found, path_,
                                  "no device behind this node (unplugged, or the pty's other side is gone): " +
                                      errno_text(error));
            case EACCES:
            case EPERM: throw SerialError(SerialError::Kind::permission_denied, path_, permission_cause(path_));
            case EISDIR:
                throw SerialError(SerialError::Kind::not_a_tty, path_, "is a directory, not a terminal device");
            case EBUSY:
                throw SerialError(SerialError::Kind::io, path_,
                                  "busy: another program holds it exclusively (" + errno_text(error) + ")");
            default: throw SerialError(SerialError::Kind::io, path_, "cannot open: " + errno_text(error));
        }
    }
    if (!::isatty(fd_)) {
        ::close(fd_);
        fd_ = -1;
        throw SerialError(SerialError::Kind::not_a_tty, path_,
                          "not a terminal device (a serial port or a pseudo-terminal is needed)");
    }
    try {
        configure(settings);
    } catch (...) {
        ::close(fd_);
        fd_ = -1;
        throw;
    }
}

SerialPort::SerialPort(int fd, std::string name, const SerialSettings& settings) : fd_(fd), path_(std::move(name)) {
    try {
        validate(settings);
        const int status_flags = ::fcntl(fd_, F_GETFL);
        if (status_flags < 0 || ::fcntl(fd_, F_SETFL, status_flags | O_NONBLOCK) < 0 ||
            ::fcntl(fd_, F_SETFD, FD_CLOEXEC) < 0) {
            throw SerialError(SerialError::Kind::io, path_, "cannot make the descriptor non-blocking: " +
                                                                errno_text(errno));
        }
        configure(settings);
    } catch (const std::invalid_argument& error) {
        ::close(fd_);
        fd_ = -1;
        throw SerialError(SerialError::Kind::unsupported, path_, error.what());
    } catch (...) {
        ::close(fd_);
        fd_ = -1;
        throw;
    }
}

SerialPort SerialPort::adopt(int fd, std::string name, const SerialSettings& settings) {
    return SerialPort(fd, std::move(name), settings);
}

SerialPort::~SerialPort() { close(); }

SerialPort::SerialPort(SerialPort&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      path_(std::move(other.path_)),
      settings_(other.settings_),
      pending_(std::move(other.pending_)),
      hung_up_(other.hung_up_) {}

SerialPort& SerialPort::operator=(SerialPort&& other) noexcept {
    if (this != &other) {
        close();
        fd_ = std::exchange(other.fd_, -1);
        path_ = std::move(other.path_);
        settings_ = other.settings_;
        pending_ = std::move(other.pending_);
        hung_up_ = other.hung_up_;
    }
    return *this;
}

void SerialPort::close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
}

void SerialPort::throw_errno(const std::string& what, int error) const {
    if (error == EIO || error == ENODEV || error == ENXIO) {
        throw SerialError(SerialError::Kind::closed, path_,
                          std::string(kHungUp) + " (" + what + ": " + errno_text(error) + ")");
    }
    throw SerialError(SerialError::Kind::io, path_, what + ": " + errno_text(error));
}

void SerialPort::configure(const SerialSettings& settings) {
    termios tio{};
    if (::tcgetattr(fd_, &tio) != 0) {
        const int error = errno;
        if (error == ENOTTY || error == EINVAL) {
            throw SerialError(SerialError::Kind::not_a_tty, path_,
                              "not a terminal device (tcgetattr: " + errno_text(error) + ")");
        }
        throw_errno("tcgetattr", error);
    }
    // Linux ptys always carry 8-bit bytes without parity: the kernel resets CSIZE
    // and PARENB on them and glibc's tcsetattr then fails with EINVAL. There
    // the frame is nominal (as the baud is): set what a pty can carry.
    const bool pseudo_terminal = is_pseudo_terminal(fd_);
    const int wire_data_bits = pseudo_terminal ? 8 : settings.data_bits;
    const Parity wire_parity = pseudo_terminal ? Parity::none : settings.parity;
    // Raw: nothing between the wire and the bytes we read or write.
    tio.c_iflag &= ~static_cast<tcflag_t>(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL | IXON | IXOFF |
                                          IXANY | IGNPAR | INPCK);
    // With parity on, a byte that arrives with a parity or framing error is read
    // as '\0' (INPCK without IGNPAR/PARMRK): the stream stays in step and the
    // receiver's checksum catches it, as on a real board.
    if (wire_parity != Parity::none) tio.c_iflag |= INPCK;
    tio.c_oflag &= ~static_cast<tcflag_t>(OPOST);
    tio.c_lflag &= ~static_cast<tcflag_t>(ECHO | ECHONL | ECHOE | ECHOK | ICANON | ISIG | IEXTEN);
    tio.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | PARODD | CSTOPB | CRTSCTS);
    tio.c_cflag |= CLOCAL | CREAD | character_size_flag(wire_data_bits);
    if (wire_parity != Parity::none) tio.c_cflag |= PARENB;
    if (wire_parity == Parity::odd) tio.c_cflag |= PARODD;
    if (settings.stop_bits == 2) tio.c_cflag |= CSTOPB;
    // VMIN 1 with O_NONBLOCK: no data -> EAGAIN, hang-up -> 0 or EIO, so the
    // three cases can be told apart (VMIN 0 would return 0 for "no data" too).
    tio.c_cc[VMIN] = 1;
    tio.c_cc[VTIME] = 0;
    const speed_t speed = *speed_constant(settings.baud);
    if (::cfsetispeed(&tio, speed) != 0 || ::cfsetospeed(&tio, speed) != 0) {
        throw SerialError(SerialError::Kind::unsupported, path_,
                          "baud " + std::to_string(settings.baud) + " rejected: " + errno_text(errno));
    }
    if (::tcsetattr(fd_, TCSANOW, &tio) != 0) {
        const int error = errno;
        if (error == EINVAL) {
            throw SerialError(SerialError::Kind::unsupported, path_,
                              "the driver refused " + describe(settings) + " (" + errno_text(error) + ")");
        }
        throw_errno("tcsetattr", error);
    }
    // tcsetattr succeeds if any one change was made: read back what the driver kept.
    termios applied{};
    if (::tcgetattr(fd_, &applied) != 0) throw_errno("tcgetattr", errno);
    const tcflag_t frame_bits = CSIZE | PARENB | PARODD | CSTOPB;
    if (::cfgetospeed(&applied) != speed || (applied.c_cflag & frame_bits) != (tio.c_cflag & frame_bits)) {
        throw SerialError(SerialError::Kind::unsupported, path_,
                          "the driver did not accept " + describe(settings));
    }
    settings_ = settings;
}

void SerialPort::write_all(std::string_view bytes, std::chrono::milliseconds timeout) {
    write_all(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), timeout);
}

void SerialPort::write_all(std::span<const std::uint8_t> bytes, std::chrono::milliseconds timeout) {
    if (fd_ < 0) throw SerialError(SerialError::Kind::closed, path_, "port closed: write after close()");
    const WallStopwatch stopwatch;
    std::size_t written = 0;
    while (written < bytes.size()) {
        const ssize_t n = ::write(fd_, bytes.data() + written, bytes.size() - written);
        if (n > 0) {
            written += static_cast<std::size_t>(n);
            continue;
        }
        const int error = n < 0 ? errno : EAGAIN;
        if (error == EINTR) continue;
        if (error != EAGAIN) throw_errno("write", error);
        // Output buffer full: wait for room, within what is left of the timeout.
        const int wait_ms = remaining_ms(stopwatch, timeout.count());
        pollfd watch{fd_, POLLOUT, 0};
        const int ready = wait_ms > 0 ? ::poll(&watch, 1, wait_ms) : 0;
        if (ready < 0 && errno == EINTR) continue;
        if (ready < 0) throw_errno("poll", errno);
        if (ready == 0) {
            throw SerialError(SerialError::Kind::timeout, path_,
                              "write timed out after " + std::to_string(timeout.count()) + " ms with " +
                                  std::to_string(written) + " of " + std::to_string(bytes.size()) +
                                  " bytes written (is anything reading the other side?)");
        }
        // POLLHUP/POLLERR: the next write reports the cause (EIO on a hung-up pty).
    }
}

bool SerialPort::fill_pending(std::int64_t timeout_ms) {
    if (fd_ < 0) throw SerialError(SerialError::Kind::closed, path_, "port closed: read after close()");
    const WallStopwatch stopwatch;
    while (true) {
        pollfd watch{fd_, POLLIN, 0};
        const int ready = ::poll(&watch, 1, remaining_ms(stopwatch, timeout_ms));
        if (ready < 0 && errno == EINTR) continue;
        if (ready < 0) throw_errno("poll", errno);
        if (ready == 0) return false;
        if (watch.revents & POLLNVAL) throw SerialError(SerialError::Kind::io, path_, "descriptor is not open");
        std::array<char, 4096> buffer{};
        const ssize_t n = ::read(fd_, buffer.data(), buffer.size());
        if (n > 0) {
            pending_.append(buffer.data(), static_cast<std::size_t>(n));
            return true;
        }
        if (n == 0) {  // a hung-up terminal reads as end of file
            hung_up_ = true;
            return true;
        }
        const int error = errno;
        if (error == EINTR) continue;
        if (error == EIO || error == ENODEV || error == ENXIO) {
            hung_up_ = true;
            return true;
        }
        if (error != EAGAIN) throw_errno("read", error);
        // Readiness with nothing to read: a hang-up without data is final; anything
        // else was spurious, wait again within the timeout.
        if (watch.revents & (POLLHUP | POLLERR)) {
            hung_up_ = true;
            return true;
        }
        if (remaining_ms(stopwatch, timeout_ms) == 0) return false;
    }
}

std::string SerialPort::read_some(std::chrono::milliseconds timeout, std::size_t max_bytes) {
    if (pending_.empty() && !hung_up_) fill_pending(timeout.count());
    if (!pending_.empty()) {
        const std::size_t count = std::min(max_bytes, pending_.size());
        std::string out = pending_.substr(0, count);
        pending_.erase(0, count);
        return out;
    }
    if (hung_up_) {
        throw SerialError(SerialError::Kind::closed, path_, kHungUp);
    }
    return {};
}

std::optional<std::string> SerialPort::read_line(std::chrono::milliseconds timeout) {
    const WallStopwatch stopwatch;
    while (true) {
        if (const auto newline = pending_.find('\n'); newline != std::string::npos && newline <= kMaxLineBytes) {
            std::string line = pending_.substr(0, newline);
            pending_.erase(0, newline + 1);
            if (!line.empty() && line.back() == '\r') line.pop_back();
            return line;
        }
        if (pending_.size() >= kMaxLineBytes) {
            std::string piece = pending_.substr(0, kMaxLineBytes);
            pending_.erase(0, kMaxLineBytes);
            return piece;
        }
        if (hung_up_) {
            if (!pending_.empty()) return std::exchange(pending_, {});
            throw SerialError(SerialError::Kind::closed, path_, kHungUp);
        }
        const int wait_ms = remaining_ms(stopwatch, timeout.count());
        if (!fill_pending(wait_ms)) return std::nullopt;
    }
}

}  // namespace rig
