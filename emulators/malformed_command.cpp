#include "emulators/malformed_command.h"

#include <cmath>
#include <vector>

#include "rig/runtime/failure_kind.h"
#include "rig/text/number_text.h"

namespace rig::emulators {

namespace {

// "bits 0-2", "bit 0": the bits a boom of `count` sections answers to.
std::string bit_range(int count) {
    return count == 1 ? std::string("bit 0") : "bits 0-" + std::to_string(count - 1);
}

}  // namespace

std::optional<std::string> section_valves_problem(const msg::SectionValves& command, int section_count) {
    const unsigned mask = command.open_mask();
    std::string extra_bits;
    int extra_count = 0;
    for (int bit = section_count; bit < 16; ++bit) {
        if ((mask & (1u << bit)) == 0) continue;
        extra_bits += (extra_bits.empty() ? "" : ", ") + std::to_string(bit);
        ++extra_count;
    }
    if (extra_count == 0) return std::nullopt;
    return "open_mask " + std::to_string(mask) + " sets " + (extra_count == 1 ? "bit " : "bits ") + extra_bits +
           ", but the boom has " + std::to_string(section_count) + (section_count == 1 ? " section (" : " sections (") +
           bit_range(section_count) + ")";
}

std::optional<std::string> nozzle_pwm_problem(const msg::NozzlePwm& command, int nozzle_count) {
    const std::vector<double>& duty = command.duty_pct();
    if (duty.size() != static_cast<std::size_t>(nozzle_count)) {
        return std::to_string(duty.size()) + (duty.size() == 1 ? " duty entry for " : " duty entries for ") +
               std::to_string(nozzle_count) + (nozzle_count == 1 ? " nozzle" : " nozzles");
    }
    for (std::size_t n = 0; n < duty.size(); ++n) {
        // A PWM stage is on for a share of each period: no less than never, no more than always.
        if (!std::isfinite(duty[n]) || duty[n] < 0.0 || duty[n] > 100.0) {
            return "duty_pct[" + std::to_string(n) + "] = " + shortest_text(duty[n]) + ", not a duty in 0-100 %";
        }
    }
    const double frequency_hz = command.frequency_hz();
    if (!std::isfinite(frequency_hz) || frequency_hz < 0.0) {
        return "frequency_hz = " + shortest_text(frequency_hz) + ", not a PWM frequency (finite, 0 Hz or above)";
    }
    if (frequency_hz == 0.0) {
        // 0 Hz is no PWM at all: each line held low or high, which is how a
        // GPIO PWM sets 0 % and 100 % and how the bench's edge capture reads a
        // steady line (rig/wire/pwm_capture.h). A share of a period needs a period.
        for (std::size_t n = 0; n < duty.size(); ++n) {
            if (duty[n] != 0.0 && duty[n] != 100.0) {
                return "frequency_hz = 0 with duty_pct[" + std::to_string(n) + "] = " + shortest_text(duty[n]) +
                       ": a duty between 0 and 100 % needs a PWM period";
            }
        }
    }
    return std::nullopt;
}

NodeFailure malformed_command(std::string_view topic, TimeNs at_ns, const std::string& problem) {
    return NodeFailure(FailureKind::malformed_command, "controller",
                       std::string(topic) + " at t=" + fixed_text(ns_to_seconds(at_ns), 3) + " s: " + problem);
}

}  // namespace rig::emulators
