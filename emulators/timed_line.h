#pragma once
// One line of text a device puts on its serial wire, with the instant its last
// byte is there (what a reader of that wire sees, and when).
#include <string>

#include "rig/runtime/clock.h"

namespace rig::emulators {

struct TimedLine {
    TimeNs at_ns = 0;
    std::string text;  // including the line's terminator (CR LF)
};

}  // namespace rig::emulators
