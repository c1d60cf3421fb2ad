#pragma once
// The bounds checks of the camera parameters and of those built on them (the
// camera emulators', the seed-001 vision's): one message shape,
// "<where>.<field>: <value> is outside <bounds>".
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rig::camera {

inline bool finite_within(double value, double low, double high) { return std::isfinite(value) && value >= low && value <= high; }

// Throws std::invalid_argument unless `ok`.
inline void require_parameter(bool ok, const std::string& where, const std::string& field, double value, const char* bounds) {
    if (ok) return;
    std::ostringstream message;
    message << where << "." << field << ": " << value << " is outside " << bounds;
    throw std::invalid_argument(message.str());
}

}  // namespace rig::camera
