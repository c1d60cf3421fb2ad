#include "controller/boundary/boundary_equations.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <GeographicLib/Math.hpp>

namespace rig::controller::boundary {

double eq14_theoretical_duty_pct(const BoundaryControllerConfig& c, double density, double speed_m_s) {
    const double q_l_min = c.eq12_coefficient_l_min_per_m_s * density * speed_m_s / c.k_max_cover;  // Eq. 12
    return (q_l_min - c.eq13_intercept_l_min) / c.eq13_slope_l_min_per_pct;          // Eq. 13 solved for s
}

int spray_level(const BoundaryControllerConfig& c, double s_pct) {
    if (!(s_pct > c.level0_max_pct)) return 0;  // NaN too: no spraying on a nonsense input
    if (s_pct <= c.level1_max_pct) return 1;
    return 2;
}

double level_duty_pct(const BoundaryControllerConfig& c, int level) {
    switch (level) {
        case 0: return 0.0;
        case 1: return c.level1_duty_pct;
        case 2: return c.level2_duty_pct;
        default: throw std::invalid_argument("spray level must be 0, 1 or 2, got " + std::to_string(level));
    }
}

double eq18_boom_offset_m(const BoundaryControllerConfig& c, double h_m) {
    const double drop_m = c.lift_hinge_height_m - h_m;
    if (!std::isfinite(h_m) || std::abs(drop_m) > c.lift_rod_length_m) {
        throw std::invalid_argument("Eq. 18: boom height " + std::to_string(h_m) + " m is out of the lift's reach");
    }
    return std::sqrt(c.lift_rod_length_m * c.lift_rod_length_m - drop_m * drop_m) -
           (c.antenna_to_o_m - c.hinge_to_boom_centre_m);
}

GridPoint eq19_body_to_grid(GridPoint antenna, double bearing_deg, double x_m, double y_m) {
    double s = 0.0;
    double co = 1.0;
    GeographicLib::Math::sincosd(bearing_deg, s, co);  // exact at multiples of 90 deg
    return {co * x_m + s * y_m + antenna.x_m, -s * x_m + co * y_m + antenna.y_m};
}

}  // namespace rig::controller::boundary
