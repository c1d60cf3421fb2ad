#pragma once
// The bounds check the devices' parameters share (the AD300 receiver's, the L4
// laser's): one message shape, "<section>.<name>: must be in [lo, hi], got value",
// which names the key of the case file that is wrong.
#include <string_view>

namespace rig::emulators {

// Throws std::invalid_argument unless `value` is finite and in [lo, hi]
// ([lo, hi) when `hi_open`). The numbers are printed with six decimals, as
// the devices' messages always printed them (std::to_string's %f).
void check_range(std::string_view section, std::string_view name, double value, double lo, double hi,
                 bool hi_open = false);

}  // namespace rig::emulators
