#include "rig/runtime/lateness.h"
#include "rig/text/number_text.h"

#include <algorithm>
#include <cstdio>

namespace rig {

namespace {

std::string fixed(double value, int decimals) { return fixed_text(value, decimals); }

// printf's %g: six significant digits.
std::string shortest(double value) { return significant_text(value, 6); }

}  // namespace

void LatenessAccount::record(const std::string& device, TimeNs deadline_ns, TimeNs emitted_ns) {
    const TimeNs late_ns = std::max<TimeNs>(0, emitted_ns - deadline_ns);
    const double late_ms = static_cast<double>(late_ns) * 1e-6;
    DeviceLateness& mine = devices_[device];
    ++mine.emissions;
    ++emissions_;
    if (mine.emissions == 1 || late_ms > mine.max_ms) {
        mine.max_ms = late_ms;
        mine.max_deadline_ns = deadline_ns;
    }
    if (late_ms > bound_.late_after_ms) {
        ++mine.late;
        if (late_++ == 0) {
            first_late_device_ = device;
            first_late_deadline_ns_ = deadline_ns;
        }
    }
}

LatenessVerdict LatenessAccount::verdict() const {
    LatenessVerdict verdict;
    verdict.bound = bound_;
    verdict.emissions = emissions_;
    verdict.late = late_;
    verdict.late_pct = emissions_ == 0 ? 0.0 : 100.0 * static_cast<double>(late_) / static_cast<double>(emissions_);
    verdict.first_late_device = first_late_device_;
    verdict.first_late_deadline_ns = first_late_deadline_ns_;
    verdict.devices = devices_;
    for (const auto& [device, mine] : devices_) {
        if (verdict.worst_device.empty() || mine.max_ms > verdict.max_ms) {
            verdict.max_ms = mine.max_ms;
            verdict.worst_device = device;
            verdict.worst_deadline_ns = mine.max_deadline_ns;
        }
    }
    std::vector<std::string> reasons;
    if (verdict.max_ms > bound_.max_lateness_ms) {
        reasons.push_back(verdict.worst_device + " emitted " + fixed(verdict.max_ms, 1) +
                          " ms after its deadline at t = " + fixed(ns_to_seconds(verdict.worst_deadline_ns), 3) +
                          " s (bound realtime.max_lateness_ms: " + shortest(bound_.max_lateness_ms) + " ms)");
    }
    if (verdict.late_pct > bound_.max_late_pct) {
        reasons.push_back(std::to_string(late_) + " of " + std::to_string(emissions_) + " emissions (" +
                          fixed(verdict.late_pct, 2) + " %) left more than " + shortest(bound_.late_after_ms) +
                          " ms late, the first from " + first_late_device_ + " at t = " +
                          fixed(ns_to_seconds(first_late_deadline_ns_), 3) + " s (bound realtime.max_late_pct: " +
                          shortest(bound_.max_late_pct) + " %)");
    }
    for (const std::string& reason : reasons) verdict.overloaded += (verdict.overloaded.empty() ? "" : "; ") + reason;
    return verdict;
}

}  // namespace rig
