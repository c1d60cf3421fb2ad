#include "emulators/field2d/nozzle_flow_table.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace rig::field2d {

NozzleFlowTable::NozzleFlowTable(std::vector<std::vector<FlowPoint>> per_nozzle) : points_(std::move(per_nozzle)) {
    if (points_.empty()) throw std::invalid_argument("flow table: no nozzles");
    for (std::size_t n = 0; n < points_.size(); ++n) {
        auto& pts = points_[n];
        const std::string where = "flow table: nozzle " + std::to_string(n);
        if (pts.size() < 2) throw std::invalid_argument(where + ": needs at least 2 points");
        for (std::size_t i = 0; i < pts.size(); ++i) {
            if (!std::isfinite(pts[i].duty_pct) || pts[i].duty_pct <= 0.0 || pts[i].duty_pct > 100.0) {
                throw std::invalid_argument(where + ", point " + std::to_string(i) + ": duty must be in (0, 100] %, got " +
                                            std::to_string(pts[i].duty_pct));
            }
            if (!std::isfinite(pts[i].flow_ml_min) || pts[i].flow_ml_min < 0.0) {
                throw std::invalid_argument(where + ", point " + std::to_string(i) +
                                            ": flow must be finite and >= 0 mL/min, got " +
                                            std::to_string(pts[i].flow_ml_min));
            }
        }
        std::sort(pts.begin(), pts.end(), [](const FlowPoint& a, const FlowPoint& b) { return a.duty_pct < b.duty_pct; });
        for (std::size_t i = 1; i < pts.size(); ++i) {
            if (pts[i].duty_pct == pts[i - 1].duty_pct) {
                throw std::invalid_argument(where + ": duty " + std::to_string(pts[i].duty_pct) + " % given twice");
            }
        }
    }
}

NozzleFlowTable NozzleFlowTable::paper_table3() {
    // Seed 001 Table 3, mL/min; columns 100, 90, 80, 70, 60, 50, 40, 30 % duty.
    constexpr double kDuty[8] = {100, 90, 80, 70, 60, 50, 40, 30};
    constexpr double kFlow[6][8] = {
        {610, 600, 550, 495, 480, 430, 390, 350},
        {610, 610, 590, 540, 500, 470, 435, 400},
        {615, 610, 580, 550, 500, 475, 430, 395},
        {630, 640, 630, 600, 565, 520, 470, 435},
        {620, 620, 610, 600, 555, 520, 500, 440},
        {600, 600, 600, 580, 540, 490, 460, 420},
    };
    std::vector<std::vector<FlowPoint>> table(6);
    for (int n = 0; n < 6; ++n) {
        for (int c = 0; c < 8; ++c) table[static_cast<std::size_t>(n)].push_back(FlowPoint{kDuty[c], kFlow[n][c]});
    }
    return NozzleFlowTable(std::move(table));
}

const std::vector<FlowPoint>& NozzleFlowTable::checked(int nozzle) const {
    if (nozzle < 0 || nozzle >= nozzle_count()) {
        throw std::out_of_range("flow table: no nozzle " + std::to_string(nozzle) + " (table has " +
                                std::to_string(nozzle_count()) + ")");
    }
    return points_[static_cast<std::size_t>(nozzle)];
}

const std::vector<FlowPoint>& NozzleFlowTable::points(int nozzle) const { return checked(nozzle); }
double NozzleFlowTable::min_duty_pct(int nozzle) const { return checked(nozzle).front().duty_pct; }
double NozzleFlowTable::max_duty_pct(int nozzle) const { return checked(nozzle).back().duty_pct; }

double NozzleFlowTable::flow_ml_min(int nozzle, double duty_pct) const {
    const auto& pts = checked(nozzle);
    if (!(duty_pct >= pts.front().duty_pct && duty_pct <= pts.back().duty_pct)) {
        throw std::out_of_range("flow table: nozzle " + std::to_string(nozzle) + ": duty " + std::to_string(duty_pct) +
                                " % outside the measured range [" + std::to_string(pts.front().duty_pct) + ", " +
                                std::to_string(pts.back().duty_pct) + "] %");
    }
    const auto upper = std::lower_bound(pts.begin(), pts.end(), duty_pct,
                                        [](const FlowPoint& p, double d) { return p.duty_pct < d; });
    if (upper->duty_pct == duty_pct) return upper->flow_ml_min;
    const auto lower = upper - 1;
    const double f = (duty_pct - lower->duty_pct) / (upper->duty_pct - lower->duty_pct);
    return lower->flow_ml_min + f * (upper->flow_ml_min - lower->flow_ml_min);
}

}  // namespace rig::field2d
