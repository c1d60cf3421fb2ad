#include "rig/wire/pty_pair.h"

#include "rig/runtime/realtime.h"

#include <sys/ioctl.h>

#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace rig {
namespace {

std::string errno_text(int error) {
    return std::string(std::strerror(error)) + " (errno " + std::to_string(error) + ")";
}

// Replaces whatever symlink is at `link` with one to `target`, atomically (a
// reader never sees the path missing). Refuses to replace anything that is not
// a symlink: that is somebody's file.
void make_symlink(const std::string& target, const std::filesystem::path& link) {
    namespace fs = std::filesystem;
    std::error_code error;
    const fs::file_status status = fs::symlink_status(link, error);
    if (fs::exists(status) && !fs::is_symlink(status)) {
        throw std::runtime_error("pty " + target + ": cannot make symlink " + link.string() +
                                 ": the path exists and is not a symlink (not replacing it)");
    }
    fs::path temporary = link;
    temporary += ".tmp-" + std::to_string(::getpid());
    fs::remove(temporary, error);
    fs::create_symlink(target, temporary, error);
    if (!error) fs::rename(temporary, link, error);
    if (error) {
        fs::remove(temporary);
        throw std::runtime_error("pty " + target + ": cannot make symlink " + link.string() + ": " + error.message());
    }
}

// Bytes read from one master, not yet written to the other. While it holds
// bytes its source is not read: backpressure instead of an unbounded buffer.
struct Direction {
    std::array<char, 4096> bytes{};
    std::size_t begin = 0;
    std::size_t end = 0;
    bool empty() const { return begin == end; }
};

}  // namespace

PtyPair::PtyPair(const PtyOptions& options) {
    const int master_fd = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master_fd < 0) {
        throw std::runtime_error("cannot create a pseudo-terminal: posix_openpt: " + errno_text(errno) +
                                 " (is /dev/pts mounted?)");
    }
    std::array<char, 128> name{};
    if (::grantpt(master_fd) != 0 || ::unlockpt(master_fd) != 0 ||
        ::ptsname_r(master_fd, name.data(), name.size()) != 0) {
        const int error = errno;
        ::close(master_fd);
        throw std::runtime_error("cannot set up a pseudo-terminal (grantpt/unlockpt/ptsname): " + errno_text(error));
    }
    slave_path_ = name.data();
    master_.emplace(SerialPort::adopt(master_fd, "pty master of " + slave_path_, options.settings));
    held_slave_.emplace(slave_path_, options.settings);
    if (!options.link_path.empty()) {
        make_symlink(slave_path_, options.link_path);
        link_path_ = options.link_path;
    }
}


std::size_t PtyPair::unread_bytes() const {
    int queued = 0;
    if (!held_slave_ || ::ioctl(held_slave_->native_handle(), FIONREAD, &queued) != 0 || queued < 0) return 0;
    return static_cast<std::size_t>(queued);
}

PtyPair::~PtyPair() {
    if (link_path_.empty()) return;
    std::error_code error;
    if (std::filesystem::read_symlink(link_path_, error) == slave_path_ && !error) {
        std::filesystem::remove(link_path_, error);
    }
}

PtyLink::PtyLink(const PtyOptions& a, const PtyOptions& b) : a_(a), b_(b) {
    wake_fd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    if (wake_fd_ < 0) throw std::runtime_error("pty link: eventfd: " + errno_text(errno));
    forwarder_ = std::thread([this] { forward(); });
}

PtyLink::~PtyLink() {
    stop();
    if (wake_fd_ >= 0) ::close(wake_fd_);
}

std::string PtyLink::raise_to_realtime(int priority) { return raise_thread_to_realtime(forwarder_, priority); }

void PtyLink::stop() {
    if (!forwarder_.joinable()) return;
    const std::uint64_t one = 1;
    // An eventfd write of 1 cannot block or fail short of a counter overflow.
    [[maybe_unused]] const ssize_t n = ::write(wake_fd_, &one, sizeof one);
    forwarder_.join();
}

std::optional<std::string> PtyLink::error() const {
    const std::lock_guard lock(error_mutex_);
    return error_;
}

void PtyLink::forward() {
    // The thread only ever blocks in poll(), which the wake eventfd interrupts:
    // stop() returns within one loop iteration.
    const int fd_a = a_.master().native_handle();
    const int fd_b = b_.master().native_handle();
    Direction a_to_b;
    Direction b_to_a;
    bool a_alive = true;
    bool b_alive = true;
    const auto fail = [&](const std::string& message) {
        const std::lock_guard lock(error_mutex_);
        if (!error_) error_ = message;
    };
    // Reads what `from` has into an empty `direction`; false when `from` is gone.
    const auto pull = [&](int from, Direction& direction, const std::string& side) {
        const ssize_t n = ::read(from, direction.bytes.data(), direction.bytes.size());
        if (n > 0) {
            direction.begin = 0;
            direction.end = static_cast<std::size_t>(n);
            return true;
        }
        if (n < 0 && (errno == EAGAIN || errno == EINTR)) return true;
        fail("pty link: side " + side + " hung up (" + (n == 0 ? std::string("end of file") : errno_text(errno)) + ")");
        return false;
    };
    const auto push = [&](int to, Direction& direction, std::atomic<std::uint64_t>& counter, const std::string& side) {
        const ssize_t n = ::write(to, direction.bytes.data() + direction.begin, direction.end - direction.begin);
        if (n > 0) {
            direction.begin += static_cast<std::size_t>(n);
            counter += static_cast<std::uint64_t>(n);
            return true;
        }
        if (n < 0 && (errno == EAGAIN || errno == EINTR)) return true;
        fail("pty link: side " + side + " cannot be written (" + errno_text(errno) + ")");
        return false;
    };

    while (true) {
        std::array<pollfd, 3> watch{};
        watch[0] = {wake_fd_, POLLIN, 0};
        const auto events = [](bool alive, const Direction& outgoing, const Direction& incoming) -> short {
            if (!alive) return 0;
            return static_cast<short>((outgoing.empty() ? POLLIN : 0) | (incoming.empty() ? 0 : POLLOUT));
        };
        // A side that is gone is left out of poll (fd -1): its hang-up would
        // otherwise wake the loop forever.
        watch[1] = {a_alive ? fd_a : -1, events(a_alive, a_to_b, b_to_a), 0};
        watch[2] = {b_alive ? fd_b : -1, events(b_alive, b_to_a, a_to_b), 0};
        if (::poll(watch.data(), watch.size(), -1) < 0) {
            if (errno == EINTR) continue;
            fail("pty link: poll: " + errno_text(errno));
            return;
        }
        if (watch[0].revents != 0) return;  // stop()
        const short ready_a = watch[1].revents;
        const short ready_b = watch[2].revents;
        // POLLHUP/POLLERR count as readable: the read reports the cause.
        const short readable = POLLIN | POLLHUP | POLLERR;
        if (a_alive && a_to_b.empty() && (ready_a & readable)) a_alive = pull(fd_a, a_to_b, "a");
        if (b_alive && b_to_a.empty() && (ready_b & readable)) b_alive = pull(fd_b, b_to_a, "b");
        // Write at once what was just read; poll for room only when a write is short.
        if (b_alive && !a_to_b.empty()) b_alive = push(fd_b, a_to_b, bytes_a_to_b_, "b");
        if (a_alive && !b_to_a.empty()) a_alive = push(fd_a, b_to_a, bytes_b_to_a_, "a");
        if (!a_alive && !b_alive) return;
    }
}

}  // namespace rig
