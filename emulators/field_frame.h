#pragma once
// The field's local tangent plane (east-north-up at the origin, WGS84, via
// GeographicLib::LocalCartesian) rotated onto the A-B guidance line:
//   along_m  distance along the line in its heading direction,
//   cross_m  distance to the right of the line (seen facing the heading),
//   up_m     height above the origin's tangent plane.
// Heading is a compass bearing: 0 = north, clockwise (seed 001's convention and
// the NMEA course), so along = north at heading 0 and along = east at heading 90.
//
// This is the plant's truth geometry: exact on the ellipsoid, unlike the
// controller's spherical Eq. 4 (controller/breakpoint_equations.h).
#include <utility>

#include <GeographicLib/LocalCartesian.hpp>

namespace rig::emulators {

struct GeoPoint {
    double lat_deg = 0.0;
    double lon_deg = 0.0;
    double height_m = 0.0;  // above the WGS84 ellipsoid
};

class FieldFrame {
public:
    // Throws std::invalid_argument for a latitude outside [-90, 90] or a
    // non-finite argument.
    FieldFrame(double origin_lat_deg, double origin_lon_deg, double origin_height_m, double heading_deg);

    GeoPoint to_geodetic(double along_m, double cross_m, double up_m = 0.0) const;
    // (along_m, cross_m) of a point: its east and north in the tangent plane,
    // rotated onto the line; the up component is dropped.
    std::pair<double, double> to_line(const GeoPoint& point) const;

    double heading_deg() const { return heading_deg_; }
    GeoPoint origin() const { return origin_; }

private:
    GeoPoint origin_;
    double heading_deg_;
    // sin / cos of the heading, exact for multiples of 90 deg (Math::sincosd), so
    // an east-west line has no spurious north component.
    double sin_heading_;
    double cos_heading_;
    GeographicLib::LocalCartesian tangent_plane_;
};

}  // namespace rig::emulators
