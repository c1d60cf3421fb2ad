#include "rig/host/stop_signals.h"

#include <poll.h>
#include <pthread.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace rig {

StopSignals::StopSignals() {
    sigemptyset(&signals_);
    sigaddset(&signals_, SIGINT);
    sigaddset(&signals_, SIGTERM);
    if (::pthread_sigmask(SIG_BLOCK, &signals_, &previous_) != 0) {
        throw std::runtime_error("pthread_sigmask failed");
    }
    fd_ = ::signalfd(-1, &signals_, SFD_CLOEXEC);
    if (fd_ < 0) {
        const int error = errno;
        ::pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
        throw std::runtime_error(std::string("signalfd: ") + std::strerror(error));
    }
}

StopSignals::~StopSignals() {
    ::close(fd_);
    ::pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
}

std::string StopSignals::take() const {
    signalfd_siginfo info{};
    const ssize_t n = ::read(fd_, &info, sizeof info);
    if (n != static_cast<ssize_t>(sizeof info)) return "signal";
    return info.ssi_signo == SIGINT ? "SIGINT" : "SIGTERM";
}

bool StopSignals::pending() const {
    pollfd watch{fd_, POLLIN, 0};
    return ::poll(&watch, 1, 0) > 0;
}

}  // namespace rig
