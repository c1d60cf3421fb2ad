// The controller's own breakpoint math (seed 000 Eq. 4-7): Eq. 4 against the
// WGS84 geodesic, the others against values worked out by hand.
#include <gtest/gtest.h>

#include <GeographicLib/Constants.hpp>
#include <GeographicLib/Geodesic.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "controller/breakpoint_equations.h"

namespace {

using namespace rig::controller;

// The paper's field: Xiaotangshan National Precision Agriculture Research and
// Demonstration Base, Beijing.
constexpr double kFieldLat_deg = 40.18;
constexpr double kFieldLon_deg = 116.44;

// Worst relative error of a sphere of radius R against the ellipsoid for a short
// line at latitude phi. Locally the ellipsoid's line element is
//   ds^2 = M^2 dphi^2 + N^2 cos^2(phi) dlambda^2
// (M meridian, N prime-vertical radius of curvature) and the sphere's, with the
// same latitude and longitude, R^2 (dphi^2 + cos^2(phi) dlambda^2). So the ratio
// sphere/ellipsoid lies between R/M (north-south) and R/N (east-west), and the
// relative error is at most max(|R/M - 1|, |R/N - 1|), for every azimuth.
double sphere_vs_ellipsoid_bound(double lat_deg) {
    const double a = GeographicLib::Constants::WGS84_a();
    const double f = GeographicLib::Constants::WGS84_f();
    const double e2 = f * (2.0 - f);
    const double sin_phi = std::sin(lat_deg * std::numbers::pi / 180.0);
    const double w2 = 1.0 - e2 * sin_phi * sin_phi;
    const double meridian_radius_m = a * (1.0 - e2) / (w2 * std::sqrt(w2));
    const double prime_vertical_radius_m = a / std::sqrt(w2);
    return std::max(std::abs(kMeanEarthRadius_m / meridian_radius_m - 1.0),
                    std::abs(kMeanEarthRadius_m / prime_vertical_radius_m - 1.0));
}

TEST(Eq4Haversine, MatchesWgs84GeodesicWithinTheSphereBoundAtThePapersField) {
    const GeographicLib::Geodesic& geodesic = GeographicLib::Geodesic::WGS84();
    // At 40.18 deg N: M = 6 362 014 m, N = 6 387 043 m, so R/M - 1 = +0.141 % and
    // R/N - 1 = -0.251 %: the bound is 0.251 %. (It is 0.56 % at the equator, where
    // M is smallest: the "up to ~0.5 %" usually quoted for a spherical Earth.)
    const double bound = sphere_vs_ellipsoid_bound(kFieldLat_deg);
    ASSERT_GT(bound, 0.0024);
    ASSERT_LT(bound, 0.0026);
    // Plus a little for rounding and for M and N changing along a 1 km line (~1e-7).
    const double allowed_relative = bound + 1e-6;

    const std::vector<double> baselines_m = {1.0, 5.0, 10.0, 50.0, 100.0, 500.0, 1000.0};
    std::printf("Eq. 4 (sphere R = %.1f m) vs WGS84 geodesic at %.2f N, azimuths 0..345 step 15 deg\n",
                kMeanEarthRadius_m, kFieldLat_deg);
    std::printf("  %9s  %14s  %14s  %12s\n", "baseline", "worst rel", "worst abs", "at azimuth");
    for (const double baseline_m : baselines_m) {
        double worst_relative = 0.0;
        double worst_absolute_m = 0.0;
        double worst_azimuth_deg = 0.0;
        for (int step = 0; step < 24; ++step) {
            const double azimuth_deg = 15.0 * step;
            double lat_deg = 0.0;
            double lon_deg = 0.0;
            geodesic.Direct(kFieldLat_deg, kFieldLon_deg, azimuth_deg, baseline_m, lat_deg, lon_deg);
            double geodesic_m = 0.0;
            geodesic.Inverse(kFieldLat_deg, kFieldLon_deg, lat_deg, lon_deg, geodesic_m);
            const double sphere_m = haversine_distance_m(kFieldLat_deg, kFieldLon_deg, lat_deg, lon_deg);
            const double absolute_m = std::abs(sphere_m - geodesic_m);
            const double relative = absolute_m / geodesic_m;
            EXPECT_LE(relative, allowed_relative) << baseline_m << " m at azimuth " << azimuth_deg;
            if (relative > worst_relative) {
                worst_relative = relative;
                worst_azimuth_deg = azimuth_deg;
            }
            worst_absolute_m = std::max(worst_absolute_m, absolute_m);
        }
        std::printf("  %7.0f m  %12.4f %%  %11.6f m  %9.0f deg\n", baseline_m, 100.0 * worst_relative,
                    worst_absolute_m, worst_azimuth_deg);
        // The error is a scale error, so it must not vanish: a sphere is not the ellipsoid.
        EXPECT_GT(worst_relative, 0.002) << baseline_m;
    }
}

TEST(Eq4Haversine, HandWorkedValues) {
    // 1 deg of latitude on the sphere: R pi / 180 = 6371008.8 x 0.0174532925 = 111195.080 m.
    EXPECT_NEAR(haversine_distance_m(40.0, 116.44, 41.0, 116.44), 111195.0802, 1e-3);
    // 1 deg of longitude on the equator is the same arc.
    EXPECT_NEAR(haversine_distance_m(0.0, 10.0, 0.0, 11.0), 111195.0802, 1e-3);
    // ... and at 40.18 deg N it is shortened by cos(40.18 deg) = 0.764171 (to within
    // 1e-6 relative: the haversine arc is the great circle, not the parallel).
    EXPECT_NEAR(haversine_distance_m(kFieldLat_deg, 116.0, kFieldLat_deg, 117.0) / 111195.0802,
                std::cos(kFieldLat_deg * std::numbers::pi / 180.0), 1e-4);
    EXPECT_EQ(haversine_distance_m(kFieldLat_deg, kFieldLon_deg, kFieldLat_deg, kFieldLon_deg), 0.0);
    // Across the antimeridian: 1 deg, not 359.
    EXPECT_NEAR(haversine_distance_m(0.0, 179.5, 0.0, -179.5), 111195.0802, 1e-3);
    // Symmetric.
    EXPECT_DOUBLE_EQ(haversine_distance_m(40.18, 116.44, 40.181, 116.443),
                     haversine_distance_m(40.181, 116.443, 40.18, 116.44));
}

TEST(Eq4Haversine, ThePrintedSymbolOrderWouldStretchEastWestDistances) {
    // Eq. 4 as printed: sin^2(dLambda/2) + sin^2(dPhi/2) cos(lambda0) cos(lambda1).
    // For a due-east 100 m line the dPhi term vanishes and the cos(phi) factor on
    // dLambda is lost, so it reads 1 / cos(40.18 deg) = 1.31 times too long.
    const GeographicLib::Geodesic& geodesic = GeographicLib::Geodesic::WGS84();
    double lat_deg = 0.0;
    double lon_deg = 0.0;
    geodesic.Direct(kFieldLat_deg, kFieldLon_deg, 90.0, 100.0, lat_deg, lon_deg);
    const double to_rad = std::numbers::pi / 180.0;
    const double dlambda = (lon_deg - kFieldLon_deg) * to_rad;
    const double dphi = (lat_deg - kFieldLat_deg) * to_rad;
    const double printed_haversine =
        std::pow(std::sin(dlambda / 2.0), 2) +
        std::pow(std::sin(dphi / 2.0), 2) * std::cos(kFieldLon_deg * to_rad) * std::cos(lon_deg * to_rad);
    const double printed_m = 2.0 * kMeanEarthRadius_m * std::asin(std::sqrt(printed_haversine));
    EXPECT_GT(printed_m, 130.0);
    EXPECT_NEAR(haversine_distance_m(kFieldLat_deg, kFieldLon_deg, lat_deg, lon_deg), 100.0, 0.3);
}

TEST(Eq5Speed, HandWorkedValues) {
    // D = 1.0 m, k = 100 pulses in t1 = 0.2 s, n = 1000:
    // 3.6 x pi x 1.0 x 100 / (1000 x 0.2) = 360 pi / 200 = 1.8 pi = 5.654867 km/h
    // (100 pulses = 0.314159 m of wheel in 0.2 s = 1.570796 m/s).
    EXPECT_NEAR(speed_km_h_from_pulses(1.0, 100, 1000, 0.2), 5.654867, 1e-6);
    // Near the paper's 6 km/h: D = 0.6 m, k = 177, n = 1000, t1 = 0.2 s:
    // 3.6 x pi x 0.6 x 177 / 200 = 382.32 pi / 200 = 1.9116 pi = 6.005469 km/h.
    EXPECT_NEAR(speed_km_h_from_pulses(0.6, 177, 1000, 0.2), 6.005469, 1e-6);
    EXPECT_EQ(speed_km_h_from_pulses(1.0, 0, 1000, 0.2), 0.0);
    EXPECT_THROW(speed_km_h_from_pulses(1.0, 10, 0, 0.2), std::invalid_argument);
    EXPECT_THROW(speed_km_h_from_pulses(1.0, 10, 1000, 0.0), std::invalid_argument);
}

TEST(Eq5Speed, PulsesToDistance) {
    // One revolution of a 1 m wheel: pi m; 250 pulses of a 0.6 m wheel at 1000 p/rev:
    // 0.25 x 0.6 pi = 0.471239 m.
    EXPECT_DOUBLE_EQ(pulses_to_distance_m(1000, 1000, 1.0), std::numbers::pi);
    EXPECT_NEAR(pulses_to_distance_m(250, 1000, 0.6), 0.471239, 1e-6);
    // A full 32-bit count does not overflow anything (it is converted to double).
    EXPECT_NEAR(pulses_to_distance_m(4294967295u, 1000, 1.0), 4294967.295 * std::numbers::pi, 1e-3);
    EXPECT_THROW(pulses_to_distance_m(1, 0, 1.0), std::invalid_argument);
}

TEST(Eq6AntennaToNozzle, HandWorkedValues) {
    // L1 = 0.50, L2 = 0.80, L3 = 0.45, h = 0.50:
    // h / L2 = 0.625; atan(0.625) = 0.558599 rad (32.005 deg); cos = 0.847998;
    // x L2 = 0.678399; L4 = 0.50 + 0.678399 + 0.45 = 1.628399 m, the paper's
    // "1.63 m at 0.5 m boom height" (sec. 2.2.3).
    EXPECT_NEAR(antenna_to_nozzle_m(0.50, 0.80, 0.45, 0.50), 1.628399, 1e-6);
    EXPECT_NEAR(antenna_to_nozzle_m(0.50, 0.80, 0.45, 0.50), 1.63, 0.005);
    // Linkage level (h = 0): cos(0) = 1, L4 = L1 + L2 + L3 = 1.75 m.
    EXPECT_DOUBLE_EQ(antenna_to_nozzle_m(0.50, 0.80, 0.45, 0.0), 1.75);
    // Raising the boom shortens L4 (the linkage swings up).
    EXPECT_LT(antenna_to_nozzle_m(0.50, 0.80, 0.45, 0.60), antenna_to_nozzle_m(0.50, 0.80, 0.45, 0.50));
}

TEST(Eq7NozzleOpenMileage, HandWorkedValue) {
    // s_b = 4.80 m (first fix inside the 5 m threshold), L4 = 1.628399 m,
    // v = 6 km/h = 1.666667 m/s, t2 = 1.359 s (Table 2 mean), t3 = 0.267 s (Table 1):
    // v (t2 + t3) = 1.666667 x 1.626 = 2.710 m (the paper's "2.71 m at 6 km/h",
    // sec. 3.2.1); s = 4.80 + 1.628399 - 2.710 = 3.718399 m.
    const double l4_m = antenna_to_nozzle_m(0.50, 0.80, 0.45, 0.50);
    EXPECT_NEAR(nozzle_open_mileage_m(4.80, l4_m, 6.0 / 3.6, 1.359, 0.267), 3.718399, 1e-6);
    // Standing still there is nothing to lead: s = s_b + L4.
    EXPECT_DOUBLE_EQ(nozzle_open_mileage_m(4.80, l4_m, 0.0, 1.359, 0.267), 4.80 + l4_m);
}

// A point `distance_m` from the field origin at `azimuth_deg`, `right_m` to the
// right of that direction, on the WGS84 ellipsoid (independent of the code under test).
std::pair<double, double> field_point(double azimuth_deg, double distance_m, double right_m = 0.0) {
    const GeographicLib::Geodesic& geodesic = GeographicLib::Geodesic::WGS84();
    double lat_deg = 0.0;
    double lon_deg = 0.0;
    geodesic.Direct(kFieldLat_deg, kFieldLon_deg, azimuth_deg, distance_m, lat_deg, lon_deg);
    if (right_m != 0.0) {
        double shifted_lat_deg = 0.0;
        double shifted_lon_deg = 0.0;
        geodesic.Direct(lat_deg, lon_deg, azimuth_deg + 90.0, right_m, shifted_lat_deg, shifted_lon_deg);
        return {shifted_lat_deg, shifted_lon_deg};
    }
    return {lat_deg, lon_deg};
}

double ahead_of_origin_m(double course_deg, std::pair<double, double> target) {
    return signed_distance_ahead_m(kFieldLat_deg, kFieldLon_deg, course_deg, target.first, target.second);
}

TEST(SignedDistanceAhead, PositiveAheadNegativeBehind) {
    // Driving east: a target 10 m east is ahead, 10 m west is behind (|S| within
    // the 0.25 % sphere error).
    EXPECT_NEAR(ahead_of_origin_m(90.0, field_point(90.0, 10.0)), 10.0, 0.03);
    EXPECT_NEAR(ahead_of_origin_m(90.0, field_point(270.0, 10.0)), -10.0, 0.03);
    // Driving north, across the 0/360 wrap of the course.
    EXPECT_GT(ahead_of_origin_m(359.0, field_point(1.0, 5.0)), 0.0);
    EXPECT_LT(ahead_of_origin_m(1.0, field_point(181.0, 5.0)), 0.0);
    // A few centimetres of cross-track (guidance) error do not change the sign
    // until the target is abeam: 2 cm ahead with 5 cm to the side is still ahead,
    // 2 cm behind is behind, and |S| includes the sideways part.
    EXPECT_GT(ahead_of_origin_m(90.0, field_point(90.0, 0.02, 0.05)), 0.0);
    EXPECT_LT(ahead_of_origin_m(90.0, field_point(90.0, -0.02, 0.05)), 0.0);
    EXPECT_NEAR(std::abs(ahead_of_origin_m(90.0, field_point(90.0, 0.02, 0.05))), std::hypot(0.02, 0.05), 1e-4);
    // Coincident points: no bearing, distance 0.
    EXPECT_EQ(signed_distance_ahead_m(kFieldLat_deg, kFieldLon_deg, 90.0, kFieldLat_deg, kFieldLon_deg), 0.0);
}

TEST(SignedDistanceAhead, SignFlipsWhereTheTargetPassesAbeam) {
    // Approach a target along course 90 in 1 cm steps from 1 m before to 1 m past:
    // the sign changes exactly once, between -1 cm and +1 cm.
    int sign_changes = 0;
    double previous = 0.0;
    for (int step = -100; step <= 100; ++step) {
        if (step == 0) continue;
        // The vehicle at along = step cm; the target at the origin.
        const auto vehicle = field_point(90.0, step / 100.0);
        const double ahead_m =
            signed_distance_ahead_m(vehicle.first, vehicle.second, 90.0, kFieldLat_deg, kFieldLon_deg);
        EXPECT_EQ(ahead_m > 0.0, step < 0) << step;
        if (previous != 0.0 && (previous > 0.0) != (ahead_m > 0.0)) ++sign_changes;
        previous = ahead_m;
    }
    EXPECT_EQ(sign_changes, 1);
}

TEST(OffsetPosition, IsTheInverseOfEq4OnTheSameSphere) {
    for (const double bearing_deg : {0.0, 45.0, 90.0, 200.0, 270.0, 359.0}) {
        for (const double distance_m : {0.5, 1.628399, 10.0, 1000.0}) {
            const auto [lat_deg, lon_deg] = offset_position_deg(kFieldLat_deg, kFieldLon_deg, bearing_deg, distance_m);
            EXPECT_NEAR(haversine_distance_m(kFieldLat_deg, kFieldLon_deg, lat_deg, lon_deg), distance_m, 1e-6);
            EXPECT_NEAR(std::remainder(initial_bearing_deg(kFieldLat_deg, kFieldLon_deg, lat_deg, lon_deg) -
                                           bearing_deg,
                                       360.0),
                        0.0, 1e-5)
                << bearing_deg << " " << distance_m;
        }
    }
    // Longitude comes back wrapped into [-180, 180).
    const auto [lat_deg, lon_deg] = offset_position_deg(0.0, 179.9999, 90.0, 100.0);
    EXPECT_NEAR(lat_deg, 0.0, 1e-9);
    EXPECT_LT(lon_deg, -179.99);
}

}  // namespace
