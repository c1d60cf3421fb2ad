#pragma once
// Plane vectors in the field's local east-north frame (metres), and the body
// axes of a vehicle with a compass heading (0 = north, clockwise, as the NMEA
// course and seed 001 Sec. 4.2 use it):
//   forward(h) = (sin h, cos h)     right(h) = (cos h, -sin h)
// A point x metres right and y metres forward of a body origin lies at
//   origin + x right(h) + y forward(h),
// which is the rotation of seed 001 Eq. 19 (X = x cos b + y sin b, Y = -x sin b + y cos b).
#include <cmath>

#include <GeographicLib/Math.hpp>

namespace rig::field2d {

struct Vec2 {
    double east_m = 0.0;
    double north_m = 0.0;

    friend Vec2 operator+(Vec2 a, Vec2 b) { return {a.east_m + b.east_m, a.north_m + b.north_m}; }
    friend Vec2 operator-(Vec2 a, Vec2 b) { return {a.east_m - b.east_m, a.north_m - b.north_m}; }
    friend Vec2 operator*(double k, Vec2 a) { return {k * a.east_m, k * a.north_m}; }
    friend bool operator==(const Vec2&, const Vec2&) = default;
};

inline double dot(Vec2 a, Vec2 b) { return a.east_m * b.east_m + a.north_m * b.north_m; }
// z component of a x b: > 0 when b is counter-clockwise of a (seen from above).
inline double cross(Vec2 a, Vec2 b) { return a.east_m * b.north_m - a.north_m * b.east_m; }
inline double norm(Vec2 a) { return std::hypot(a.east_m, a.north_m); }

// Unit vectors of a compass heading. sincosd is exact at multiples of 90 deg, so
// a vehicle heading due east has no spurious north component.
inline Vec2 forward_of(double heading_deg) {
    double s = 0.0;
    double c = 1.0;
    GeographicLib::Math::sincosd(heading_deg, s, c);
    return {s, c};
}
inline Vec2 right_of(double heading_deg) {
    double s = 0.0;
    double c = 1.0;
    GeographicLib::Math::sincosd(heading_deg, s, c);
    return {c, -s};
}
// Body point (right_m, forward_m) of a body at `origin` facing `heading_deg`.
inline Vec2 body_to_field(Vec2 origin, double heading_deg, double right_m, double forward_m) {
    return origin + right_m * right_of(heading_deg) + forward_m * forward_of(heading_deg);
}
// A compass heading brought into [0, 360). std::fmod is exact; adding 360
// to a negative remainder may round up to 360 itself, which is 0.
inline double heading_0_360_deg(double deg) {
    double wrapped = std::fmod(deg, 360.0);
    if (wrapped < 0.0) wrapped += 360.0;
    if (wrapped >= 360.0) wrapped -= 360.0;
    return wrapped;
}
// The turn from heading b to heading a, in (-180, 180] (exact: std::remainder).
inline double heading_difference_deg(double a_deg, double b_deg) {
    const double wrapped = std::remainder(a_deg - b_deg, 360.0);
    return wrapped == -180.0 ? 180.0 : wrapped;
}
// Compass bearing of a direction, in [0, 360).
inline double bearing_deg(Vec2 direction) {
    double deg = std::atan2(direction.east_m, direction.north_m) * 180.0 / M_PI;
    if (deg < 0.0) deg += 360.0;
    if (deg >= 360.0) deg -= 360.0;
    return deg;
}

}  // namespace rig::field2d
