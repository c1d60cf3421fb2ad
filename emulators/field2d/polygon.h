#pragma once
// Target areas (seed 001 Sec. 4.2: "record the area's latitude and longitude,
// choose 4 coordinate points") as simple polygons in the field's local
// east-north frame. This is the plant's (and the judge's) truth geometry; the
// controller has its own, in UTM (controller/boundary/), on purpose.
#include <string>
#include <vector>

#include "emulators/field2d/local_frame.h"
#include "emulators/field2d/vec2.h"

namespace rig::field2d {

class Polygon {
public:
    // Throws std::invalid_argument, naming `name` and the vertex or edge, for
    // fewer than 3 vertices, a non-finite coordinate, two consecutive vertices
    // closer than 1 mm (a repeated corner), edges that cross (e.g. four corners
    // given in "bow-tie" order), or an area under 0.01 m^2 (collinear corners).
    explicit Polygon(std::vector<Vec2> vertices, std::string name = "polygon");

    // Four (or more) recorded corners, in order around the area, projected into
    // `frame`. Same checks as above, plus the latitude/longitude ranges.
    static Polygon from_geodetic(const LocalFrame& frame, const std::vector<GeodeticPoint>& corners,
                                 std::string name = "polygon");

    // Closed set: a point exactly on an edge is inside.
    bool contains(Vec2 p) const;
    // Distance to the boundary, negative inside, positive outside.
    double signed_distance_m(Vec2 p) const;
    // Vertices counter-clockwise (seen from above, east right, north up).
    const std::vector<Vec2>& vertices() const { return vertices_; }
    double area_m2() const { return area_m2_; }
    const std::string& name() const { return name_; }
    // Edge i runs from vertex i to vertex i+1 (mod n).
    std::size_t edge_count() const { return vertices_.size(); }

private:
    double distance_to_boundary_m(Vec2 p) const;
    std::vector<Vec2> vertices_;
    std::string name_;
    double area_m2_ = 0.0;
};

}  // namespace rig::field2d
