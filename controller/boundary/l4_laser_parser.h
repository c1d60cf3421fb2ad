#pragma once
// The controller's reader of the L4 laser's serial lines (the format the rig
// assumes, emulators/l4_laser_sensor.h: "D=0.503m" for a distance in metres,
// "E=<code>" for a device error, each ended by CR LF). Firmware-like contract:
// any bytes may come in; it never throws on bad input and answers with a
// distance, a device error code, or a message naming what is wrong and where.
#include <optional>
#include <string>
#include <string_view>

namespace rig::controller::boundary {

struct L4Reading {
    std::optional<double> distance_m;     // "D=...m"
    std::optional<int> device_error;      // "E=..."
    std::optional<std::string> error;     // malformed line: what and at which column (1-based)
    bool ok() const { return distance_m.has_value(); }
};

// Trailing CR / LF are optional; nothing else may surround the frame. At most
// 32 characters.
L4Reading parse_l4_line(std::string_view line);

}  // namespace rig::controller::boundary
