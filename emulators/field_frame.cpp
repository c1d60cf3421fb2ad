#include "emulators/field_frame.h"

#include <cmath>
#include <stdexcept>

#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/Math.hpp>

namespace rig::emulators {

FieldFrame::FieldFrame(double origin_lat_deg, double origin_lon_deg, double origin_height_m, double heading_deg)
    : origin_{origin_lat_deg, origin_lon_deg, origin_height_m},
      heading_deg_(heading_deg),
      sin_heading_(0.0),
      cos_heading_(1.0),
      tangent_plane_(GeographicLib::Geocentric::WGS84()) {
    if (!std::isfinite(origin_lat_deg) || !std::isfinite(origin_lon_deg) || !std::isfinite(origin_height_m) ||
        !std::isfinite(heading_deg)) {
        throw std::invalid_argument("FieldFrame: origin and heading must be finite");
    }
    if (std::abs(origin_lat_deg) > 90.0) throw std::invalid_argument("FieldFrame: origin latitude outside [-90, 90]");
    tangent_plane_.Reset(origin_lat_deg, origin_lon_deg, origin_height_m);
    GeographicLib::Math::sincosd(heading_deg, sin_heading_, cos_heading_);
}

GeoPoint FieldFrame::to_geodetic(double along_m, double cross_m, double up_m) const {
    // Unit vectors in (east, north): along = (sin h, cos h); right of it = (cos h, -sin h).
    const double east_m = along_m * sin_heading_ + cross_m * cos_heading_;
    const double north_m = along_m * cos_heading_ - cross_m * sin_heading_;
    GeoPoint point;
    tangent_plane_.Reverse(east_m, north_m, up_m, point.lat_deg, point.lon_deg, point.height_m);
    return point;
}

std::pair<double, double> FieldFrame::to_line(const GeoPoint& point) const {
    double east_m = 0.0;
    double north_m = 0.0;
    double up_m = 0.0;
    tangent_plane_.Forward(point.lat_deg, point.lon_deg, point.height_m, east_m, north_m, up_m);
    // The rotation above is its own inverse (symmetric and orthogonal).
    const double along_m = east_m * sin_heading_ + north_m * cos_heading_;
    const double cross_m = east_m * cos_heading_ - north_m * sin_heading_;
    return {along_m, cross_m};
}

}  // namespace rig::emulators
