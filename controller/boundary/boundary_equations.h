#pragma once
// Seed 001's equations as the controller computes them (its own code: the
// plant's truth in emulators/field2d/ is deliberately not shared, so a case can
// give the controller a wrong belief and the rig sees the consequence).
//
//   Eq. 12   q = c D v / k                     nozzle flow wanted, L/min (c = 0.40968)
//   Eq. 13   q = A s + b                       flow at duty s (%), from Table 3
//   Eq. 14   s = (c D v / k - b) / A           theoretical duty, %
//            level 0 (closed) for s <= s0, level 1 (40 %) for s0 < s <= s1,
//            level 2 (100 %) above (Sec. 3.2.2; s0 = -55 %, s1 = 5 %)
//   Eq. 18   Y1 = sqrt(I^2 - (Hp - H)^2) - (M - L)
//   Eq. 19   [X; Y] = [cos b  sin b; -sin b  cos b] [x; y] + [X1; Y1]
//            (x right, y forward of the antenna; X east, Y north; b the course)
#include "controller/boundary/boundary_config.h"

namespace rig::controller::boundary {

// Eq. 14's theoretical duty for plant cover D (0..1) at speed v (m/s), %.
double eq14_theoretical_duty_pct(const BoundaryControllerConfig& config, double density, double speed_m_s);
// Sec. 3.2.2's level (0, 1, 2) of a theoretical duty.
int spray_level(const BoundaryControllerConfig& config, double theoretical_duty_pct);
// The PWM duty of a level: 0, level1_duty_pct, level2_duty_pct.
double level_duty_pct(const BoundaryControllerConfig& config, int level);

// Eq. 18. Throws std::invalid_argument when |Hp - H| > I or H is not finite.
double eq18_boom_offset_m(const BoundaryControllerConfig& config, double boom_height_m);

struct GridPoint {
    double x_m = 0.0;  // UTM easting (or any east-north grid)
    double y_m = 0.0;  // UTM northing
};
// Eq. 19 for one body point: x_m right and y_m forward of the antenna at
// `antenna`, the body turned by bearing_deg (clockwise from grid north).
GridPoint eq19_body_to_grid(GridPoint antenna, double bearing_deg, double x_m, double y_m);

}  // namespace rig::controller::boundary
