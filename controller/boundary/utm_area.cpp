#include "controller/boundary/utm_area.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <GeographicLib/Constants.hpp>
#include <GeographicLib/UTMUPS.hpp>

namespace rig::controller::boundary {
namespace {

double cross(GridPoint o, GridPoint a, GridPoint b) {
    return (a.x_m - o.x_m) * (b.y_m - o.y_m) - (a.y_m - o.y_m) * (b.x_m - o.x_m);
}

double distance_to_segment(GridPoint p, GridPoint a, GridPoint b) {
    const double dx = b.x_m - a.x_m;
    const double dy = b.y_m - a.y_m;
    const double len2 = dx * dx + dy * dy;
    double t = len2 > 0.0 ? ((p.x_m - a.x_m) * dx + (p.y_m - a.y_m) * dy) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    return std::hypot(p.x_m - (a.x_m + t * dx), p.y_m - (a.y_m + t * dy));
}

bool segments_cross(GridPoint a, GridPoint b, GridPoint c, GridPoint d) {
    const auto sign = [](double v) { return (v > 0.0) - (v < 0.0); };
    const int d1 = sign(cross(a, b, c));
    const int d2 = sign(cross(a, b, d));
    const int d3 = sign(cross(c, d, a));
    const int d4 = sign(cross(c, d, b));
    if (d1 != d2 && d3 != d4) return true;
    // Touching or collinear overlap.
    return (d1 == 0 && distance_to_segment(c, a, b) == 0.0) || (d2 == 0 && distance_to_segment(d, a, b) == 0.0) ||
           (d3 == 0 && distance_to_segment(a, c, d) == 0.0) || (d4 == 0 && distance_to_segment(b, c, d) == 0.0);
}

}  // namespace

UtmProjection::UtmProjection(const std::vector<TargetAreaConfig>& areas) {
    double lat_sum = 0.0;
    double lon_sum = 0.0;
    int count = 0;
    for (const TargetAreaConfig& area : areas) {
        for (const GeoCorner& corner : area.corners) {
            lat_sum += corner.lat_deg;
            lon_sum += corner.lon_deg;
            ++count;
        }
    }
    if (count == 0) throw std::invalid_argument("UTM: no area corners to choose the zone from");
    const double lat = lat_sum / count;
    const double lon = lon_sum / count;
    try {
        zone_ = GeographicLib::UTMUPS::StandardZone(lat, lon);
    } catch (const GeographicLib::GeographicErr& error) {
        throw std::invalid_argument(std::string("UTM: no zone for the areas' mean corner: ") + error.what());
    }
    if (zone_ == GeographicLib::UTMUPS::UPS) {
        throw std::invalid_argument("UTM: the areas lie in a polar (UPS) region, which the controller does not handle");
    }
    north_ = lat >= 0.0;
}

UtmProjection::UtmProjection(int zone, bool north) : zone_(zone), north_(north) {
    if (zone < 1 || zone > 60) throw std::invalid_argument("UTM: zone must be 1..60, got " + std::to_string(zone));
}

GridPoint UtmProjection::forward(double lat_deg, double lon_deg) const {
    double convergence_deg = 0.0;
    return forward(lat_deg, lon_deg, convergence_deg);
}

GridPoint UtmProjection::forward(double lat_deg, double lon_deg, double& convergence_deg) const {
    int zone = 0;
    bool north = true;
    GridPoint p;
    double scale = 1.0;
    try {
        GeographicLib::UTMUPS::Forward(lat_deg, lon_deg, zone, north, p.x_m, p.y_m, convergence_deg, scale, zone_);
    } catch (const GeographicLib::GeographicErr& error) {
        throw std::invalid_argument("UTM: cannot project (" + std::to_string(lat_deg) + ", " + std::to_string(lon_deg) +
                                    ") in zone " + std::to_string(zone_) + ": " + error.what());
    }
    // A point south of the equator in a northern-hemisphere run (or the reverse)
    // gets the other hemisphere's false northing; keep the run's.
    if (north != north_) p.y_m += north_ ? -GeographicLib::UTMUPS::UTMShift() : GeographicLib::UTMUPS::UTMShift();
    return p;
}

UtmArea::UtmArea(std::string name, std::vector<GridPoint> corners, double density)
    : name_(std::move(name)), corners_(std::move(corners)), density_(density) {
    const std::size_t n = corners_.size();
    const std::string who = "area '" + name_ + "'";
    if (n < 3) throw std::invalid_argument(who + ": needs at least 3 corners, got " + std::to_string(n));
    for (std::size_t i = 0; i < n; ++i) {
        const GridPoint a = corners_[i];
        const GridPoint b = corners_[(i + 1) % n];
        if (!std::isfinite(a.x_m) || !std::isfinite(a.y_m)) {
            throw std::invalid_argument(who + ": corner " + std::to_string(i) + " is not finite");
        }
        if (std::hypot(b.x_m - a.x_m, b.y_m - a.y_m) < 1e-3) {
            throw std::invalid_argument(who + ": corners " + std::to_string(i) + " and " + std::to_string((i + 1) % n) +
                                        " are the same point");
        }
    }
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t k = i + 2; k < n; ++k) {
            if (i == 0 && k == n - 1) continue;  // adjacent through the closing edge
            if (segments_cross(corners_[i], corners_[(i + 1) % n], corners_[k], corners_[(k + 1) % n])) {
                throw std::invalid_argument(who + ": edges " + std::to_string(i) + " and " + std::to_string(k) +
                                            " cross (corners out of order around the area?)");
            }
        }
    }
    double twice_area = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        twice_area += corners_[i].x_m * corners_[(i + 1) % n].y_m - corners_[(i + 1) % n].x_m * corners_[i].y_m;
    }
    if (std::abs(twice_area) * 0.5 < 1e-2) {
        throw std::invalid_argument(who + ": degenerate, area " + std::to_string(std::abs(twice_area) * 0.5) +
                                    " m^2 (corners collinear?)");
    }
}

UtmArea UtmArea::project(const TargetAreaConfig& config, const UtmProjection& projection) {
    std::vector<GridPoint> corners;
    for (std::size_t i = 0; i < config.corners.size(); ++i) {
        try {
            corners.push_back(projection.forward(config.corners[i].lat_deg, config.corners[i].lon_deg));
        } catch (const std::invalid_argument& error) {
            throw std::invalid_argument("area '" + config.name + "': corner " + std::to_string(i) + ": " + error.what());
        }
    }
    return UtmArea(config.name, std::move(corners), config.density);
}

bool UtmArea::contains(GridPoint p) const {
    const std::size_t n = corners_.size();
    for (std::size_t i = 0; i < n; ++i) {
        if (distance_to_segment(p, corners_[i], corners_[(i + 1) % n]) <= 1e-9) return true;
    }
    bool inside = false;
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
        const GridPoint a = corners_[i];
        const GridPoint b = corners_[j];
        if ((a.y_m > p.y_m) != (b.y_m > p.y_m)) {
            const double x_at = a.x_m + (p.y_m - a.y_m) * (b.x_m - a.x_m) / (b.y_m - a.y_m);
            if (p.x_m < x_at) inside = !inside;
        }
    }
    return inside;
}

}  // namespace rig::controller::boundary
