#pragma once
// The field's local tangent plane: east / north / up metres from a geodetic
// origin on the WGS84 ellipsoid (GeographicLib::LocalCartesian). The seed-001
// plant keeps all its truth here, not in UTM, so that the controller's UTM
// projection (and the grid convergence the paper ignores, about 1.4 deg at
// Wuzhi) is an error the rig can show rather than share.
#include <GeographicLib/LocalCartesian.hpp>

#include "emulators/field2d/vec2.h"

namespace rig::field2d {

struct GeodeticPoint {
    double lat_deg = 0.0;
    double lon_deg = 0.0;
    double height_m = 0.0;  // above the WGS84 ellipsoid
};

class LocalFrame {
public:
    // Throws std::invalid_argument naming the bad value for a latitude outside
    // [-90, 90], a longitude outside [-180, 180] or a non-finite argument.
    LocalFrame(double origin_lat_deg, double origin_lon_deg, double origin_height_m = 0.0);

    GeodeticPoint to_geodetic(Vec2 en, double up_m = 0.0) const;
    // East/north of a point (its height above the tangent plane is dropped).
    // Throws std::invalid_argument for a latitude/longitude out of range.
    Vec2 to_local(const GeodeticPoint& point) const;
    Vec2 to_local(double lat_deg, double lon_deg) const { return to_local(GeodeticPoint{lat_deg, lon_deg, origin_.height_m}); }

    const GeodeticPoint& origin() const { return origin_; }

private:
    GeodeticPoint origin_;
    GeographicLib::LocalCartesian tangent_plane_;
};

}  // namespace rig::field2d
