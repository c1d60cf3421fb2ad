#include "emulators/flow_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rig::emulators {

std::vector<OpeningFlowLine> paper_opening_flow_lines() {
    // Fig. 11 / Table 2 constraints at 31.1 L/min pump flow (see flow_map.h).
    return {{87.0, 0.35, 3.315}, {90.0, 0.38, 4.182}, {93.0, 0.42, 5.938}, {94.0, 0.46, 7.694}, {95.0, 0.50, 9.95}};
}

FlowMap::FlowMap(FlowMapParams params) : params_(std::move(params)) {
    const auto& lines = params_.lines;
    if (lines.size() < 2) throw std::invalid_argument("flow map: at least two calibrated openings are needed");
    for (std::size_t i = 1; i < lines.size(); ++i) {
        if (!(lines[i].opening_pct > lines[i - 1].opening_pct)) {
            throw std::invalid_argument("flow map: openings must rise strictly (line " + std::to_string(i) + ")");
        }
        for (double pump : {30.0, 81.0}) {
            const double lower = lines[i - 1].slope * pump + lines[i - 1].intercept_l_min;
            const double upper = lines[i].slope * pump + lines[i].intercept_l_min;
            if (!(upper > lower)) {
                throw std::invalid_argument("flow map: flow must rise with opening between " +
                                            std::to_string(lines[i - 1].opening_pct) + " and " +
                                            std::to_string(lines[i].opening_pct) + " %");
            }
        }
    }
    if (!(params_.zero_flow_opening_pct < lines.front().opening_pct)) {
        throw std::invalid_argument("flow map: zero_flow_opening_pct must be below the lowest calibrated opening");
    }
    // The bulge must not bend the curve back down: a valve whose flow falls as it
    // opens would make every controller's search diverge, and no real one does.
    for (double pump : {30.0, 55.0, 81.0}) {
        double previous = calibrated_line_l_min(lines.front().opening_pct, pump);
        for (double opening = lines.front().opening_pct + 0.05; opening <= lines.back().opening_pct; opening += 0.05) {
            const double flow = calibrated_line_l_min(opening, pump);
            if (flow < previous) {
                throw std::invalid_argument("flow map: interpolation_bulge_pct " +
                                            std::to_string(params_.interpolation_bulge_pct) +
                                            " makes the flow fall with opening near " + std::to_string(opening) +
                                            " % at " + std::to_string(pump) + " L/min pump flow");
            }
            previous = flow;
        }
    }
}

double FlowMap::calibrated_line_l_min(double opening_pct, double pump_flow_l_min) const {
    const auto& lines = params_.lines;
    auto flow_of = [pump_flow_l_min](const OpeningFlowLine& line) {
        return line.slope * pump_flow_l_min + line.intercept_l_min;
    };
    if (opening_pct <= lines.front().opening_pct) {
        const double lowest = flow_of(lines.front());
        const double fraction = (opening_pct - params_.zero_flow_opening_pct) /
                                (lines.front().opening_pct - params_.zero_flow_opening_pct);
        return lowest * std::clamp(fraction, 0.0, 1.0);
    }
    if (opening_pct >= lines.back().opening_pct) {
        const OpeningFlowLine& last = lines.back();
        const OpeningFlowLine& before = lines[lines.size() - 2];
        const double per_pct = (flow_of(last) - flow_of(before)) / (last.opening_pct - before.opening_pct);
        return flow_of(last) + per_pct * (opening_pct - last.opening_pct);
    }
    const auto upper = std::upper_bound(lines.begin(), lines.end(), opening_pct,
                                        [](double value, const OpeningFlowLine& line) { return value < line.opening_pct; });
    const OpeningFlowLine& high = *upper;
    const OpeningFlowLine& low = *std::prev(upper);
    const double fraction = (opening_pct - low.opening_pct) / (high.opening_pct - low.opening_pct);
    const double straight = flow_of(low) + fraction * (flow_of(high) - flow_of(low));
    // The ball valve's own curve: away from the straight line, most at mid-interval.
    return straight * (1.0 + params_.interpolation_bulge_pct / 100.0 * std::sin(M_PI * fraction));
}

double FlowMap::main_flow_l_min(double opening_pct, double pump_flow_l_min) const {
    const double flow = calibrated_line_l_min(opening_pct, pump_flow_l_min) * (1.0 + params_.calibration_drift_pct / 100.0);
    return std::clamp(flow, 0.0, params_.max_fraction_of_pump * pump_flow_l_min);
}

}  // namespace rig::emulators
