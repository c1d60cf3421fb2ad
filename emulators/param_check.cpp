#include "emulators/param_check.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "rig/text/number_text.h"

namespace rig::emulators {

void check_range(std::string_view section, std::string_view name, double value, double lo, double hi, bool hi_open) {
    const bool ok = std::isfinite(value) && value >= lo && (hi_open ? value < hi : value <= hi);
    if (ok) return;
    // fixed_text(x, 6) is %.6f, the text std::to_string gave these messages.
    throw std::invalid_argument(std::string(section) + "." + std::string(name) + ": must be in [" + fixed_text(lo, 6) +
                                ", " + fixed_text(hi, 6) + (hi_open ? ")" : "]") + ", got " + fixed_text(value, 6));
}

}  // namespace rig::emulators
