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
    if (late_ms > bound_.limits_of(device).late_after_ms) {
        if (mine.late++ == 0) mine.first_late_deadline_ns = deadline_ns;
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
    // The devices without limits of their own share the case's bound; each
    // device with its own is judged alone.
    struct Group {
        const LatenessLimits* limits = nullptr;
        std::string bound_key;      // as the case file spells it
        std::size_t emissions = 0;
        std::size_t late = 0;
        double max_ms = 0.0;
        std::string worst_device;
        TimeNs worst_deadline_ns = 0;
        std::string first_late_device;
        TimeNs first_late_deadline_ns = kNever;
    };
    std::map<std::string, Group> groups;  // "" for the shared bound
    for (const auto& [device, mine] : devices_) {
        const bool own = bound_.devices.count(device) != 0;
        const std::string key = own ? device : std::string();
        Group& group = groups[key];
        group.limits = &bound_.limits_of(device);
        group.bound_key = own ? "realtime.devices." + device + "." : "realtime.";
        group.emissions += mine.emissions;
        group.late += mine.late;
        if (group.worst_device.empty() || mine.max_ms > group.max_ms) {
            group.max_ms = mine.max_ms;
            group.worst_device = device;
            group.worst_deadline_ns = mine.max_deadline_ns;
        }
        if (mine.late > 0 && mine.first_late_deadline_ns < group.first_late_deadline_ns) {
            group.first_late_device = device;
            group.first_late_deadline_ns = mine.first_late_deadline_ns;
        }
    }
    for (const auto& [key, group] : groups) {
        const LatenessLimits& limits = *group.limits;
        if (group.max_ms > limits.max_lateness_ms) {
            reasons.push_back(group.worst_device + " emitted " + fixed(group.max_ms, 1) +
                              " ms after its deadline at t = " + fixed(ns_to_seconds(group.worst_deadline_ns), 3) +
                              " s (bound " + group.bound_key + "max_lateness_ms: " + shortest(limits.max_lateness_ms) +
                              " ms)");
        }
        const double late_pct =
            group.emissions == 0 ? 0.0 : 100.0 * static_cast<double>(group.late) / static_cast<double>(group.emissions);
        if (late_pct > limits.max_late_pct) {
            reasons.push_back(std::to_string(group.late) + " of " + std::to_string(group.emissions) +
                              (key.empty() ? " emissions (" : " emissions of " + key + " (") + fixed(late_pct, 2) +
                              " %) left more than " + shortest(limits.late_after_ms) + " ms late, the first from " +
                              group.first_late_device + " at t = " +
                              fixed(ns_to_seconds(group.first_late_deadline_ns), 3) + " s (bound " + group.bound_key +
                              "max_late_pct: " + shortest(limits.max_late_pct) + " %)");
        }
    }
    for (const std::string& reason : reasons) verdict.overloaded += (verdict.overloaded.empty() ? "" : "; ") + reason;
    return verdict;
}

}  // namespace rig
