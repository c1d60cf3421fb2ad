#include "controller/breakpoint_equations.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace rig::controller {

namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

double to_rad(double deg) { return deg * kRadPerDeg; }
double to_deg(double rad) { return rad / kRadPerDeg; }

// Wraps an angle to [0, 360).
double wrap_360_deg(double deg) {
    const double wrapped = std::fmod(deg, 360.0);
    return wrapped < 0.0 ? wrapped + 360.0 : wrapped;
}

// Wraps an angle to [-180, 180).
double wrap_180_deg(double deg) { return wrap_360_deg(deg + 180.0) - 180.0; }

}  // namespace

double haversine_distance_m(double lat0_deg, double lon0_deg, double lat1_deg, double lon1_deg,
                            double earth_radius_m) {
    // Eq. 4 (standard form; see the header for the paper's swapped symbols).
    const double phi0 = to_rad(lat0_deg);
    const double phi1 = to_rad(lat1_deg);
    const double sin_half_dphi = std::sin((phi1 - phi0) / 2.0);
    // Wrapping dLambda keeps a pair straddling the antimeridian short.
    const double sin_half_dlambda = std::sin(to_rad(wrap_180_deg(lon1_deg - lon0_deg)) / 2.0);
    const double haversine =
        sin_half_dphi * sin_half_dphi + std::cos(phi0) * std::cos(phi1) * sin_half_dlambda * sin_half_dlambda;
    // Rounding can push the argument a hair above 1 for antipodal points.
    return 2.0 * earth_radius_m * std::asin(std::sqrt(std::clamp(haversine, 0.0, 1.0)));
}

double initial_bearing_deg(double lat0_deg, double lon0_deg, double lat1_deg, double lon1_deg) {
    const double phi0 = to_rad(lat0_deg);
    const double phi1 = to_rad(lat1_deg);
    const double dlambda = to_rad(wrap_180_deg(lon1_deg - lon0_deg));
    const double east = std::sin(dlambda) * std::cos(phi1);
    const double north = std::cos(phi0) * std::sin(phi1) - std::sin(phi0) * std::cos(phi1) * std::cos(dlambda);
    return wrap_360_deg(to_deg(std::atan2(east, north)));
}

double signed_distance_ahead_m(double lat_deg, double lon_deg, double course_deg, double target_lat_deg,
                               double target_lon_deg) {
    const double distance_m = haversine_distance_m(lat_deg, lon_deg, target_lat_deg, target_lon_deg);
    if (distance_m == 0.0) return 0.0;
    const double bearing_deg = initial_bearing_deg(lat_deg, lon_deg, target_lat_deg, target_lon_deg);
    // Ahead when the along-track component S*cos(bearing - course) is >= 0.
    const bool ahead = std::cos(to_rad(bearing_deg - course_deg)) >= 0.0;
    return ahead ? distance_m : -distance_m;
}

std::pair<double, double> offset_position_deg(double lat_deg, double lon_deg, double bearing_deg, double distance_m,
                                              double earth_radius_m) {
    // Destination point on the sphere of Eq. 4 (spherical law of cosines form).
    const double phi0 = to_rad(lat_deg);
    const double theta = to_rad(bearing_deg);
    const double delta = distance_m / earth_radius_m;  // central angle
    const double sin_phi1 =
        std::clamp(std::sin(phi0) * std::cos(delta) + std::cos(phi0) * std::sin(delta) * std::cos(theta), -1.0, 1.0);
    const double phi1 = std::asin(sin_phi1);
    const double dlambda =
        std::atan2(std::sin(theta) * std::sin(delta) * std::cos(phi0), std::cos(delta) - std::sin(phi0) * sin_phi1);
    return {to_deg(phi1), wrap_180_deg(lon_deg + to_deg(dlambda))};
}

double speed_km_h_from_pulses(double wheel_diameter_m, std::uint32_t pulses, std::uint32_t pulses_per_rev,
                              double interval_s) {
    if (pulses_per_rev == 0) throw std::invalid_argument("speed_km_h_from_pulses: pulses_per_rev must be > 0");
    if (!(interval_s > 0.0)) throw std::invalid_argument("speed_km_h_from_pulses: interval_s must be > 0");
    // Eq. 5: v = 3.6 pi D k / (n t1); 3.6 converts m/s to km/h.
    return 3.6 * std::numbers::pi * wheel_diameter_m * static_cast<double>(pulses) /
           (static_cast<double>(pulses_per_rev) * interval_s);
}

double antenna_to_nozzle_m(double l1_m, double l2_m, double l3_m, double linkage_rise_m) {
    // Eq. 6: L4 = L1 + cos(atan(h / L2)) L2 + L3. atan2 keeps L2 = 0 defined (L4 = L1 + L3).
    return l1_m + std::cos(std::atan2(linkage_rise_m, l2_m)) * l2_m + l3_m;
}

double nozzle_open_mileage_m(double mileage_base_m, double l4_m, double speed_m_s, double flow_adjust_s,
                             double nozzle_open_s) {
    // Eq. 7: s = s_b + L4 - v (t2 + t3).
    return mileage_base_m + l4_m - speed_m_s * (flow_adjust_s + nozzle_open_s);
}

double pulses_to_distance_m(std::uint32_t pulses, std::uint32_t pulses_per_rev, double wheel_diameter_m) {
    if (pulses_per_rev == 0) throw std::invalid_argument("pulses_to_distance_m: pulses_per_rev must be > 0");
    // One revolution rolls the circumference pi D (Eq. 5 without the division by t1).
    return std::numbers::pi * wheel_diameter_m * static_cast<double>(pulses) / static_cast<double>(pulses_per_rev);
}

}  // namespace rig::controller
