#pragma once
// The controller's target areas in UTM (seed 001 Sec. 4.2.2: "the UTM
// projection gives the antenna's projected coordinates"), with GeographicLib.
// One zone for the whole run: the standard zone of the mean of all areas'
// corners (Wuzhi, Henan, 35.1 N 113.3 E: zone 49N), forced for every point so
// that an area straddling a zone line stays one polygon.
#include <string>
#include <vector>

#include "controller/boundary/boundary_config.h"
#include "controller/boundary/boundary_equations.h"

namespace rig::controller::boundary {

class UtmProjection {
public:
    // Zone and hemisphere from the mean corner of `areas`. Throws
    // std::invalid_argument when there is no corner.
    explicit UtmProjection(const std::vector<TargetAreaConfig>& areas);
    UtmProjection(int zone, bool north);

    int zone() const { return zone_; }
    bool north() const { return north_; }
    // Easting/northing in the run's zone. Throws std::invalid_argument for a
    // point the zone cannot project (GeographicLib's limits).
    GridPoint forward(double lat_deg, double lon_deg) const;
    // Same, and the meridian convergence there: the bearing of grid north
    // measured clockwise from true north, degrees.
    GridPoint forward(double lat_deg, double lon_deg, double& convergence_deg) const;

private:
    int zone_ = 0;
    bool north_ = true;
};

// A target area's polygon in the grid, with its density. Its own point-in-polygon
// (crossing number; a point on an edge counts as inside).
class UtmArea {
public:
    // Throws std::invalid_argument naming the area and corner for a repeated
    // corner (closer than 1 mm), crossing edges, or an area under 0.01 m^2.
    UtmArea(std::string name, std::vector<GridPoint> corners, double density);
    static UtmArea project(const TargetAreaConfig& config, const UtmProjection& projection);

    bool contains(GridPoint p) const;
    const std::string& name() const { return name_; }
    double density() const { return density_; }
    const std::vector<GridPoint>& corners() const { return corners_; }

private:
    std::string name_;
    std::vector<GridPoint> corners_;
    double density_ = 0.0;
};

}  // namespace rig::controller::boundary
