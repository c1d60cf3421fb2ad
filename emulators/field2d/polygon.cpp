#include "emulators/field2d/polygon.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace rig::field2d {
namespace {

constexpr double kMinEdgeLength_m = 1e-3;   // corners recorded by RTK: closer is the same corner twice
constexpr double kMinArea_m2 = 1e-2;        // a 10 cm x 10 cm area is already no spraying target
constexpr double kOnEdge_m = 1e-9;          // rounding of the projection, far below any cell

double segment_distance_m(Vec2 p, Vec2 a, Vec2 b) {
    const Vec2 ab = b - a;
    const double length2 = dot(ab, ab);
    double t = length2 > 0.0 ? dot(p - a, ab) / length2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    return norm(p - (a + t * ab));
}

// Proper or touching intersection of segments ab and cd.
bool segments_intersect(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
    const auto orient = [](Vec2 p, Vec2 q, Vec2 r) {
        const double v = cross(q - p, r - p);
        return (v > 0.0) - (v < 0.0);
    };
    const auto on_segment = [](Vec2 p, Vec2 q, Vec2 r) {  // r on pq, given collinear
        return std::min(p.east_m, q.east_m) <= r.east_m && r.east_m <= std::max(p.east_m, q.east_m) &&
               std::min(p.north_m, q.north_m) <= r.north_m && r.north_m <= std::max(p.north_m, q.north_m);
    };
    const int o1 = orient(a, b, c);
    const int o2 = orient(a, b, d);
    const int o3 = orient(c, d, a);
    const int o4 = orient(c, d, b);
    if (o1 != o2 && o3 != o4) return true;
    if (o1 == 0 && on_segment(a, b, c)) return true;
    if (o2 == 0 && on_segment(a, b, d)) return true;
    if (o3 == 0 && on_segment(c, d, a)) return true;
    if (o4 == 0 && on_segment(c, d, b)) return true;
    return false;
}

}  // namespace

Polygon::Polygon(std::vector<Vec2> vertices, std::string name) : vertices_(std::move(vertices)), name_(std::move(name)) {
    const std::size_t n = vertices_.size();
    if (n < 3) {
        throw std::invalid_argument("polygon '" + name_ + "': needs at least 3 corners, got " + std::to_string(n));
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (!std::isfinite(vertices_[i].east_m) || !std::isfinite(vertices_[i].north_m)) {
            throw std::invalid_argument("polygon '" + name_ + "': corner " + std::to_string(i) + " is not finite");
        }
    }
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t j = (i + 1) % n;
        if (norm(vertices_[j] - vertices_[i]) < kMinEdgeLength_m) {
            throw std::invalid_argument("polygon '" + name_ + "': corners " + std::to_string(i) + " and " +
                                        std::to_string(j) + " are the same point (closer than 1 mm)");
        }
    }
    // Non-adjacent edges must not meet: the corners go around the area once.
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t k = i + 1; k < n; ++k) {
            const bool adjacent = k == i + 1 || (i == 0 && k == n - 1);
            if (adjacent) continue;
            if (segments_intersect(vertices_[i], vertices_[(i + 1) % n], vertices_[k], vertices_[(k + 1) % n])) {
                throw std::invalid_argument("polygon '" + name_ + "': edges " + std::to_string(i) + " and " +
                                            std::to_string(k) +
                                            " cross (corners not given in order around the area?)");
            }
        }
    }
    double twice_area = 0.0;  // shoelace
    for (std::size_t i = 0; i < n; ++i) twice_area += cross(vertices_[i], vertices_[(i + 1) % n]);
    if (std::abs(twice_area) * 0.5 < kMinArea_m2) {
        throw std::invalid_argument("polygon '" + name_ + "': degenerate, area " +
                                    std::to_string(std::abs(twice_area) * 0.5) + " m^2 (corners collinear?)");
    }
    if (twice_area < 0.0) std::reverse(vertices_.begin(), vertices_.end());
    area_m2_ = std::abs(twice_area) * 0.5;
}

Polygon Polygon::from_geodetic(const LocalFrame& frame, const std::vector<GeodeticPoint>& corners, std::string name) {
    std::vector<Vec2> local;
    local.reserve(corners.size());
    for (std::size_t i = 0; i < corners.size(); ++i) {
        try {
            local.push_back(frame.to_local(GeodeticPoint{corners[i].lat_deg, corners[i].lon_deg, frame.origin().height_m}));
        } catch (const std::invalid_argument& error) {
            throw std::invalid_argument("polygon '" + name + "': corner " + std::to_string(i) + ": " + error.what());
        }
    }
    return Polygon(std::move(local), std::move(name));
}

double Polygon::distance_to_boundary_m(Vec2 p) const {
    double best = std::numeric_limits<double>::infinity();
    const std::size_t n = vertices_.size();
    for (std::size_t i = 0; i < n; ++i) best = std::min(best, segment_distance_m(p, vertices_[i], vertices_[(i + 1) % n]));
    return best;
}

bool Polygon::contains(Vec2 p) const {
    const std::size_t n = vertices_.size();
    // On an edge (within rounding) counts as inside.
    for (std::size_t i = 0; i < n; ++i) {
        if (segment_distance_m(p, vertices_[i], vertices_[(i + 1) % n]) <= kOnEdge_m) return true;
    }
    // Crossing number with the half-open rule on the north coordinate, so a ray
    // through a vertex is counted once.
    bool inside = false;
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
        const Vec2 a = vertices_[i];
        const Vec2 b = vertices_[j];
        if ((a.north_m > p.north_m) != (b.north_m > p.north_m)) {
            const double east_at =
                a.east_m + (p.north_m - a.north_m) * (b.east_m - a.east_m) / (b.north_m - a.north_m);
            if (p.east_m < east_at) inside = !inside;
        }
    }
    return inside;
}

double Polygon::signed_distance_m(Vec2 p) const {
    const double d = distance_to_boundary_m(p);
    return contains(p) ? -d : d;
}

}  // namespace rig::field2d
