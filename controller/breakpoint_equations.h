#pragma once
// The controller's own breakpoint math (Li et al. 2023, Agriculture 13, 2203,
// sec. 2.2.3, Eq. 4-7), written as the firmware on the STM32 board would write
// it: plain doubles, a spherical Earth, no geodesy library. The rig's plant uses
// GeographicLib on the WGS84 ellipsoid instead, so the difference between the
// two is part of what a case measures, exactly as on a real field.
//
// Angles are in degrees at the interface (that is what NMEA delivers), lengths
// in metres, speeds as named.
#include <cstdint>
#include <utility>

namespace rig::controller {

// IUGG mean Earth radius R1 = (2a + b) / 3 of WGS84, in metres. The paper only
// says "the radius of the Earth"; with the mean radius a short Eq. 4 distance is
// within about 0.56 % of the WGS84 geodesic anywhere (0.25 % at the paper's
// 40.18 deg N; tests/breakpoint_equations_test.cpp measures it).
inline constexpr double kMeanEarthRadius_m = 6371008.8;

// Eq. 4: great-circle distance S between two points on a sphere (haversine).
// The paper prints sin^2(dLambda/2) + sin^2(dPhi/2) cos(lambda0) cos(lambda1),
// i.e. with latitude and longitude swapped; taken literally it would use the
// cosine of the *longitude* (116 deg at the paper's field) and stretch every
// east-west distance. Implemented here is the standard haversine:
//   S = 2 R asin( sqrt( sin^2(dPhi/2) + cos(phi0) cos(phi1) sin^2(dLambda/2) ) ).
double haversine_distance_m(double lat0_deg, double lon0_deg, double lat1_deg, double lon1_deg,
                            double earth_radius_m = kMeanEarthRadius_m);

// Initial great-circle bearing from point 0 to point 1, degrees in [0, 360),
// 0 = north, clockwise (the convention of the NMEA RMC course). Not in the paper;
// it is what decides whether S of Eq. 4 lies ahead of or behind the sprayer.
double initial_bearing_deg(double lat0_deg, double lon0_deg, double lat1_deg, double lon1_deg);

// Eq. 4 with a sign: S is positive while the target lies ahead of the sprayer's
// course and negative once it is behind. "Ahead" means the initial bearing to the
// target is within +-90 deg of the course: the sign of the along-track component
// S*cos(bearing - course). For the few metres that matter here the great circle
// and the A-B line are the same straight line, and a cross-track offset of a few
// centimetres (guidance error) swings the bearing by 90 deg only when the target
// is already within those centimetres of abeam, so the sign flips where the
// target passes the antenna's abeam line, as a breakpoint crossing needs.
// Returns 0 when the two points coincide (the bearing is undefined there).
double signed_distance_ahead_m(double lat_deg, double lon_deg, double course_deg, double target_lat_deg,
                               double target_lon_deg);

// The point `distance_m` from (lat, lon) along the great circle leaving at
// `bearing_deg`, on the same sphere as Eq. 4 (its inverse: Eq. 4 between the two
// points gives `distance_m` back). Returns (lat_deg, lon_deg), lon in [-180, 180).
// The controller uses it to store the breakpoint where the nozzle line is, L4
// (Eq. 6) behind the antenna.
std::pair<double, double> offset_position_deg(double lat_deg, double lon_deg, double bearing_deg, double distance_m,
                                              double earth_radius_m = kMeanEarthRadius_m);

// Eq. 5: travel speed from the land-wheel encoder, v = 3.6 pi D k / (n t1) km/h,
// with D the wheel diameter (m), k the pulses counted in t1 (s), n the encoder's
// pulses per revolution (the paper's ZSP5208: 1000). Throws std::invalid_argument
// when n is 0 or t1 is not > 0 (a configuration error, not a measurement).
double speed_km_h_from_pulses(double wheel_diameter_m, std::uint32_t pulses, std::uint32_t pulses_per_rev,
                              double interval_s);

// Eq. 6: antenna-to-nozzle distance L4 = L1 + cos(atan(h / L2)) L2 + L3, with L1
// antenna to four-bar linkage, L2 linkage length, h the linkage rise read by the
// pull-wire sensor, L3 linkage to nozzles. 1.63 m at the paper's 0.5 m boom height.
// Implemented as printed. (A link of length L2 whose far end rises h projects
// sqrt(L2^2 - h^2) horizontally; the paper's cos(atan(h/L2)) L2 = L2^2 / sqrt(L2^2 + h^2)
// is a different expression, but it is the firmware's, and the rig tests the firmware.)
double antenna_to_nozzle_m(double l1_m, double l2_m, double l3_m, double linkage_rise_m);

// Eq. 7: odometer mileage at which the nozzles must be opened,
// s = s_b + L4 - v (t2 + t3): the mileage base s_b (the first Eq. 4 distance at or
// inside the odometer threshold), plus L4 because the nozzles trail the antenna,
// minus the distance covered while the flow settles (t2) and the nozzles open (t3),
// so that spraying is established when the nozzle line reaches the breakpoint.
double nozzle_open_mileage_m(double mileage_base_m, double l4_m, double speed_m_s, double flow_adjust_s,
                             double nozzle_open_s);

// Distance rolled by the land wheel for `pulses` encoder pulses: pi D k / n
// (the distance part of Eq. 5). Throws std::invalid_argument when n is 0.
double pulses_to_distance_m(std::uint32_t pulses, std::uint32_t pulses_per_rev, double wheel_diameter_m);

}  // namespace rig::controller
