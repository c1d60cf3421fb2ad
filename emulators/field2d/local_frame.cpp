#include "emulators/field2d/local_frame.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <GeographicLib/Geocentric.hpp>

namespace rig::field2d {
namespace {

void check_geodetic(const char* what, double lat_deg, double lon_deg, double height_m) {
    if (!std::isfinite(lat_deg) || std::abs(lat_deg) > 90.0) {
        throw std::invalid_argument(std::string(what) + ": latitude must be in [-90, 90] deg, got " +
                                    std::to_string(lat_deg));
    }
    if (!std::isfinite(lon_deg) || std::abs(lon_deg) > 180.0) {
        throw std::invalid_argument(std::string(what) + ": longitude must be in [-180, 180] deg, got " +
                                    std::to_string(lon_deg));
    }
    if (!std::isfinite(height_m)) throw std::invalid_argument(std::string(what) + ": height must be finite");
}

}  // namespace

LocalFrame::LocalFrame(double origin_lat_deg, double origin_lon_deg, double origin_height_m)
    : origin_{origin_lat_deg, origin_lon_deg, origin_height_m},
      tangent_plane_(GeographicLib::Geocentric::WGS84()) {
    check_geodetic("local frame origin", origin_lat_deg, origin_lon_deg, origin_height_m);
    tangent_plane_.Reset(origin_lat_deg, origin_lon_deg, origin_height_m);
}

GeodeticPoint LocalFrame::to_geodetic(Vec2 en, double up_m) const {
    GeodeticPoint point;
    tangent_plane_.Reverse(en.east_m, en.north_m, up_m, point.lat_deg, point.lon_deg, point.height_m);
    return point;
}

Vec2 LocalFrame::to_local(const GeodeticPoint& point) const {
    check_geodetic("local frame point", point.lat_deg, point.lon_deg, point.height_m);
    double east_m = 0.0;
    double north_m = 0.0;
    double up_m = 0.0;
    tangent_plane_.Forward(point.lat_deg, point.lon_deg, point.height_m, east_m, north_m, up_m);
    return {east_m, north_m};
}

}  // namespace rig::field2d
