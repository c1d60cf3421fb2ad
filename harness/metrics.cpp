#include "harness/metrics.h"

#include <cmath>

#include "idl/topics.h"

namespace rig::harness {

std::map<std::string, double> breakpoint_metrics(const TraceRecorder& trace, const emulators::Plant& plant,
                                                 double breakpoint_along_m) {
    std::map<std::string, double> metrics;
    int reached = 0;
    for (const auto& [t, event] : trace.samples(topics::kBreakpointEvent)) {
        const std::string kind = event.at("kind");
        if (kind == "stored" && !metrics.count("breakpoint_store_error_m")) {
            const emulators::GeoPoint stored{event.at("lat_deg"), event.at("lon_deg"), 0.0};
            const auto [along_m, cross_m] = plant.field().to_line(stored);
            metrics["breakpoint_store_error_m"] = std::hypot(along_m - breakpoint_along_m, cross_m);
        }
        if (kind == "reached") {
            if (++reached == 1) {
                // Truth at the instant the controller decided (its sample time).
                const double nozzle_along_m = plant.truth_at(t).nozzle_line_along_m();
                metrics["breakpoint_error_signed_m"] = nozzle_along_m - breakpoint_along_m;
                metrics["breakpoint_error_m"] = std::abs(nozzle_along_m - breakpoint_along_m);
                metrics["breakpoint_reached_at_s"] = ns_to_seconds(t);
            }
        }
    }
    metrics["breakpoint_reached_count"] = reached;
    return metrics;
}

}  // namespace rig::harness
