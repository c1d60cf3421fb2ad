#include "emulators/boundary_spray_plant.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace rig::emulators {

BoundarySprayPlant::BoundarySprayPlant(const field2d::SprayerKinematics& kinematics, PwmNozzleValves valves,
                                       field2d::DepositionGrid2d grid, SprayDepositionParams params)
    : kinematics_(kinematics), valves_(std::move(valves)), grid_(std::move(grid)), params_(params) {
    if (!std::isfinite(params_.fan_angle_deg) || params_.fan_angle_deg <= 0.0 || params_.fan_angle_deg >= 180.0) {
        throw std::invalid_argument("spray deposition: fan_angle_deg must be in (0, 180), got " +
                                    std::to_string(params_.fan_angle_deg));
    }
    if (!std::isfinite(params_.band_thickness_m) || params_.band_thickness_m <= 0.0 || params_.band_thickness_m > 1.0) {
        throw std::invalid_argument("spray deposition: band_thickness_m must be in (0, 1] m, got " +
                                    std::to_string(params_.band_thickness_m));
    }
    if (!std::isfinite(params_.step_s) || params_.step_s <= 0.0 || params_.step_s > 0.05) {
        throw std::invalid_argument("spray deposition: step_s must be in (0, 0.05] s, got " +
                                    std::to_string(params_.step_s));
    }
    step_ns_ = seconds_to_ns(params_.step_s);
    const int boom = kinematics_.mounting().nozzle_count;
    if (valves_.nozzle_count() != boom || grid_.nozzle_count() != boom) {
        throw std::invalid_argument("spray deposition: the boom has " + std::to_string(boom) + " nozzles, the valves " +
                                    std::to_string(valves_.nozzle_count()) + ", the grid " +
                                    std::to_string(grid_.nozzle_count()));
    }
    if (valves_.now_ns() != 0) throw std::invalid_argument("spray deposition: the valves must start at t = 0");
}

void BoundarySprayPlant::command_duty(int nozzle, double duty_pct, TimeNs at_ns) {
    valves_.command(nozzle, duty_pct, at_ns);
}

void BoundarySprayPlant::advance_to(TimeNs t_ns) {
    while (valves_.now_ns() + step_ns_ <= t_ns) {
        const TimeNs from = valves_.now_ns();
        const std::vector<double> litres = valves_.advance(from + step_ns_);
        bool any = false;
        for (double l : litres) any = any || l > 0.0;
        if (!any) continue;
        const double mid_s = ns_to_seconds(from) + 0.5 * params_.step_s;
        const field2d::SprayerTruth truth = kinematics_.truth_at(mid_s);
        const double width_m = field2d::fan_width_m(truth.boom_height_m, params_.fan_angle_deg);
        for (std::size_t n = 0; n < litres.size(); ++n) {
            grid_.deposit_band(static_cast<int>(n), truth.nozzles[n], truth.pose.heading_deg, width_m,
                               params_.band_thickness_m, litres[n]);
        }
    }
}

}  // namespace rig::emulators
