#pragma once
// Spray on the ground (plant truth) as a 2-D grid of square cells in the field's
// local east-north frame, one layer per nozzle, so the judge can tell which
// nozzle wetted the ground past an area's edge (seed 001 Tables 7, 8).
//
// A nozzle's 110 deg flat fan (Table 1) lands as a band across the boom,
// 2 H tan(55 deg) wide at boom height H (1.428 m at the paper's 0.5 m) and
// `thickness_m` along the travel direction, centred under the nozzle and turned
// with the vehicle's heading. The volume of one deposit is spread evenly over a
// lattice of sample points inside the band (spacing half a cell), each sample
// booked to the cell it falls in; what falls outside the grid is counted, not
// lost silently. Uniform across the fan is a simplification (a real flat fan
// thins toward its edges); the wet edge it gives is the geometric one.
//
// Dose is volume per area in uL/cm^2 (1 uL/cm^2 = 100 L/ha).
#include <cstddef>
#include <vector>

#include "emulators/field2d/vec2.h"
#include "rig/papers/seed001.h"

namespace rig::field2d {

// Width across of a flat fan at height H: 2 H tan(angle / 2).
double fan_width_m(double height_m, double fan_angle_deg);

struct DepositionGrid2dParams {
    double east_min_m = -10.0;    // grid extent, local frame; east_min < east_max
    double north_min_m = -10.0;
    double east_max_m = 10.0;
    double north_max_m = 10.0;
    double cell_m = 0.02;         // (0, 1]; 2 cm: a wet edge is located to within a cell
    int nozzle_count = papers::seed001::kNozzleCount;  // 1..32
    // Guard against a grid that would not fit in memory (8 bytes per cell and nozzle).
    std::size_t max_cells_total = 40'000'000;
};

class DepositionGrid2d {
public:
    // Throws std::invalid_argument naming the parameter for an empty extent, a
    // cell size outside (0, 1] m, a bad nozzle count, or a grid larger than
    // max_cells_total (cells x nozzles).
    explicit DepositionGrid2d(const DepositionGrid2dParams& params);

    // Adds `volume_l` from `nozzle` as a band width_m across (perpendicular to
    // heading_deg) by thickness_m along, centred at `centre`. A volume <= 0 is
    // ignored. Throws std::invalid_argument for a bad nozzle or non-positive or
    // non-finite sizes.
    void deposit_band(int nozzle, Vec2 centre, double heading_deg, double width_m, double thickness_m, double volume_l);

    std::size_t nx() const { return nx_; }  // columns, east
    std::size_t ny() const { return ny_; }  // rows, north
    double cell_m() const { return params_.cell_m; }
    Vec2 origin() const { return {params_.east_min_m, params_.north_min_m}; }  // corner of cell (0, 0)
    Vec2 cell_centre(std::size_t ix, std::size_t iy) const;
    int nozzle_count() const { return params_.nozzle_count; }
    double dose_ul_cm2(int nozzle, std::size_t ix, std::size_t iy) const;
    double total_dose_ul_cm2(std::size_t ix, std::size_t iy) const;
    // Row-major (iy * nx + ix) dose of one nozzle, uL/cm^2.
    std::vector<double> dose_layer_ul_cm2(int nozzle) const;
    // Volume that landed outside the grid, and all volume deposited, L.
    double volume_off_grid_l() const { return off_grid_l_; }
    double total_volume_l() const { return total_l_; }
    double nozzle_volume_l(int nozzle) const;
    const DepositionGrid2dParams& params() const { return params_; }

private:
    DepositionGrid2dParams params_;
    std::size_t nx_ = 0;
    std::size_t ny_ = 0;
    double cell_area_cm2_ = 0.0;
    std::vector<std::vector<double>> litres_;  // [nozzle][iy * nx + ix]
    std::vector<double> nozzle_l_;
    double off_grid_l_ = 0.0;
    double total_l_ = 0.0;
};

}  // namespace rig::field2d
