#pragma once
// Per-nozzle flow against PWM duty at constant pressure: seed 001 Table 3
// (0.6 MPa, 9 Hz, measured with a cylinder over 1 min per point, mL/min). This is
// a plant INPUT: the emulated valves deliver these flows (interpolated linearly
// between the measured duties), and only the controller's fit of Eq. 13
// (q = A s + b) can be checked against them, never the table against itself.
#include <string>
#include <vector>

namespace rig::field2d {

struct FlowPoint {
    double duty_pct = 0.0;       // (0, 100]
    double flow_ml_min = 0.0;    // >= 0
};

class NozzleFlowTable {
public:
    // One list of points per nozzle (index = nozzle number), in any order.
    // Throws std::invalid_argument naming the nozzle and point for no nozzles,
    // fewer than 2 points, a duty outside (0, 100], a repeated duty, or a
    // negative or non-finite flow.
    explicit NozzleFlowTable(std::vector<std::vector<FlowPoint>> per_nozzle);

    // Table 3 exactly as printed: nozzles 0-5 at 100, 90, ..., 30 % duty.
    static NozzleFlowTable paper_table3();

    int nozzle_count() const { return static_cast<int>(points_.size()); }
    double min_duty_pct(int nozzle) const;
    double max_duty_pct(int nozzle) const;
    // Linear interpolation between the measured duties. Throws std::out_of_range
    // naming the nozzle and the table's range for a duty outside it or a
    // nozzle that does not exist.
    double flow_ml_min(int nozzle, double duty_pct) const;
    // Sorted by duty, ascending.
    const std::vector<FlowPoint>& points(int nozzle) const;

private:
    const std::vector<FlowPoint>& checked(int nozzle) const;
    std::vector<std::vector<FlowPoint>> points_;
};

}  // namespace rig::field2d
