#pragma once
// SIGINT and SIGTERM as readable events on a descriptor, for the bench
// commands that run until a person stops them (`rig pty`, `rig emulate`).
// Construct it before starting any thread: the signals are blocked in the
// calling thread and every thread it starts inherits that, so the signal only
// ever arrives here; the previous mask is restored when this goes away.
#include <signal.h>

#include <string>

namespace rig {

class StopSignals {
public:
    StopSignals();
    ~StopSignals();
    StopSignals(const StopSignals&) = delete;
    StopSignals& operator=(const StopSignals&) = delete;
    int fd() const { return fd_; }
    // The name of the signal that arrived ("SIGTERM"); blocks until one has.
    std::string take() const;
    // True when a stop signal is waiting (does not consume it).
    bool pending() const;

private:
    sigset_t signals_{};
    sigset_t previous_{};
    int fd_ = -1;
};

}  // namespace rig
