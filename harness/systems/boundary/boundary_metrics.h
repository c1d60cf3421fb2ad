#pragma once
// Seed 001's boundary and flow metrics (Sec. 5.3, Tables 7, 8; Table 3), as
// pure functions of plain data, so the judge can compute them from a recorded
// trace (the deposition raster and the plant's delivered volumes) and tests can
// hand them rasters with a known answer. No DDS.
//
// Wet edge. Along a boundary edge, at stations every 0.5 m (the paper measured
// "every 0.5 m"), the ground is probed along the edge's outward normal; the
// station's excess is the signed distance of the outermost wet point from the
// edge, positive outside the area (spray past the boundary), negative when the
// spray stops short of it. The probe runs across the whole judged ground (the
// raster: the case's judge.ground), inside and outside, in steps of a quarter
// cell; the edge is taken halfway between the outermost wet probe and the dry
// one beyond it. Where the ground ends the probe ends: a station wet up to the
// ground's outer end has no measured excess, only "at least" the distance of
// that end (docs/metrics.md "Windows and ends").
// The same measure gives, on different runs,
//   boundary_overrun_*   driving along the edge (Table 7; Table 8 "along");
//   drive_out_excess_*   driving out of the area across the edge (Table 8);
//   drive_in_excess_*    driving into the area across the edge (Table 8).
// Summaries are mean and sample SD (n - 1), as the paper's, in metres.
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "emulators/field2d/deposition_grid2d.h"
#include "emulators/field2d/nozzle_flow_table.h"
#include "emulators/field2d/polygon.h"

namespace rig::harness {

// Dose on square cells of the local east-north frame, row-major (iy * nx + ix).
struct DoseRaster {
    double east0_m = 0.0;   // corner of cell (0, 0)
    double north0_m = 0.0;
    double cell_m = 0.02;   // > 0
    std::size_t nx = 0;
    std::size_t ny = 0;
    std::vector<double> dose_ul_cm2;  // nx * ny values
};

// One nozzle's layer of a deposition grid (the plant's, or the judge's rebuilt one) as a raster.
DoseRaster raster_of(const field2d::DepositionGrid2d& grid, int nozzle);

// Cell-wise sum (all nozzles' layers into the ground's total). Throws
// std::invalid_argument when the rasters differ in geometry.
DoseRaster sum_rasters(const std::vector<DoseRaster>& layers);

// A straight boundary edge from `from` to `to` (east/north, m). The area lies
// to its LEFT, the outside to its right: the edges of a counter-clockwise
// polygon (emulators/field2d/polygon.h keeps its vertices so).
struct BoundaryEdge {
    double from_east_m = 0.0;
    double from_north_m = 0.0;
    double to_east_m = 0.0;
    double to_north_m = 0.0;
};

struct EdgeProbe {
    double from_m = 0.0;              // first station, along the edge from `from`, >= 0
    double to_m = -1.0;               // last station at or before this; < 0: the edge's length
    double spacing_m = 0.5;           // > 0; Table 7 / 8: every 0.5 m
    // Wet: a dose at or above this. Assumed: 0.05 uL/cm^2 (5 L/ha), a tenth of
    // what one nozzle leaves in one pass at 1.5 m/s (0.61 L/min over a 1.43 m fan).
    double wet_threshold_ul_cm2 = 0.05;
};

// What one station's probe found on the judged ground.
enum class StationFinding {
    wet_edge,           // the wet ground ends on the ground: excess_m holds where
    dry,                // nothing wet on the ground along the probe (the boom never sprayed there)
    wet_to_ground_end,  // wet up to the ground's outer end: the edge lies beyond it, at_least_m says how far at least
    off_ground,         // the probe's line does not cross the judged ground
};

struct EdgeProfile {
    std::vector<double> station_m;             // along the edge
    std::vector<double> excess_m;              // signed, + outside; NaN unless the finding is wet_edge
    std::vector<StationFinding> finding;
    std::vector<double> at_least_m;            // wet_to_ground_end: the last wet probe (signed, + outside); NaN otherwise
};

// Throws std::invalid_argument for a bad raster (size, cell), a zero-length
// edge or a bad probe, naming which.
EdgeProfile wet_edge_profile(const DoseRaster& raster, const BoundaryEdge& edge, const EdgeProbe& probe = {});

struct Summary {
    std::size_t n = 0;   // finite values used
    double mean = 0.0;   // NaN when n = 0
    double sd = 0.0;     // sample SD (n - 1); NaN when n < 2
    double min = 0.0;
    double max = 0.0;
};
// NaN values are skipped.
Summary summarize(const std::vector<double>& values);

// prefix_mean_m, prefix_sd_m, prefix_min_m, prefix_max_m, prefix_stations (n
// measured), prefix_stations_dry (dry stations). With no wet station the
// mean/sd/min/max are absent, and mean and sd not measured ("no wet ground").
// A station wet to the ground's end or off it has no value: then the mean, sd
// and max are not measured, naming how many and how far at least (a mean over
// the other stations would pass a bound off as the edge's value), and the min
// only where a measured station lies at or below every such bound. Metrics
// without a value go to `not_measured` with why.
std::map<std::string, double> excess_metrics(const std::string& prefix, const EdgeProfile& profile,
                                             std::map<std::string, std::string>& not_measured);
// Per nozzle: prefix_nozzle<i>_mean_m, _sd_m, _max_m, _stations, from each
// nozzle's own layer's profile (index = nozzle number); a nozzle's stations
// wet to the ground's end or off it leave its mean, sd and max not measured.
std::map<std::string, double> per_nozzle_excess_metrics(const std::string& prefix, const std::vector<EdgeProfile>& per_nozzle,
                                                        std::map<std::string, std::string>& not_measured);

// ---------------------------------------------------------------- the boom-centre rule (Sec. 4.2, Table 8 "along")

// Sec. 4.2's second rule: while the boom centre is outside the target area,
// every nozzle is off (spraying environment 2, running along the headland).
// Judged from truth: the boom centre (the nozzles' midpoint, where the L4 sits)
// against the area, and the volume the plant delivered. A controller that
// obeys the rule stops all delivery within its loop delay (next RMC epoch, RMC
// latency, PWM latch, valve stroke) after the centre leaves the area and
// delivers nothing while it stays out.
struct CentreRuleSample {
    double t_s = 0.0;              // in time order
    field2d::Vec2 centre;          // truth, local frame
    double volume_l = 0.0;         // all nozzles, delivered since the previous sample (>= 0)
};

// centre_out_crossings: times the centre left the area (the start counts when
// it starts outside); centre_out_spray_ml: volume delivered while it was out;
// centre_out_close_s / centre_out_close_m: over the spells outside, the
// longest time, and the centre's travel over it, from leaving the area to the
// last sample that delivered anything (0 when nothing was delivered outside);
// not measured when the centre never left the area (the rule was never put to
// the test: 0 would read as a rule obeyed); centre_out_samples: samples with
// the centre outside. Throws std::invalid_argument naming the sample for a
// non-finite value, a negative volume or time going back.
std::map<std::string, double> centre_rule_metrics(const std::vector<CentreRuleSample>& samples, const field2d::Polygon& area,
                                                  std::map<std::string, std::string>& not_measured);

// ---------------------------------------------------------------- flow per duty (Table 3)

// What the plant delivered while one nozzle held one duty.
struct FlowRecord {
    int nozzle = 0;
    double duty_pct = 0.0;
    double volume_l = 0.0;     // >= 0
    double duration_s = 0.0;   // > 0 (the paper: 1 min per point)
};

struct FlowCheckRow {
    int nozzle = 0;
    double duty_pct = 0.0;
    double delivered_ml_min = 0.0;
    double table_ml_min = 0.0;   // Table 3 (interpolated), NaN outside its range
    double error_ml_min = 0.0;   // delivered - table
    double error_pct = 0.0;      // of the table value
};

// Throws std::invalid_argument naming the record for a bad nozzle, duty,
// volume or duration.
std::vector<FlowCheckRow> flow_against_table(const std::vector<FlowRecord>& records,
                                             const field2d::NozzleFlowTable& table);
// flow_table_points, flow_table_max_abs_error_pct, flow_table_mean_abs_error_pct
// (rows outside the table's range are not counted).
std::map<std::string, double> flow_table_metrics(const std::vector<FlowCheckRow>& rows);

struct LineFit {
    double slope = 0.0;
    double intercept = 0.0;
    double r2 = 0.0;
    std::size_t n = 0;
};
// Ordinary least squares y = slope x + intercept. Throws std::invalid_argument
// for fewer than 2 points, different lengths or all x equal.
LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y);
// Eq. 13 as the paper fitted it: the mean over nozzles of the delivered flow
// at each duty in [from_pct, to_pct] (Table 3's "mean" row, 30-80 %), fitted
// q = A s + b with q in L/min and s in %:
//   eq13_slope_l_min_per_pct, eq13_intercept_l_min, eq13_r2, eq13_points.
std::map<std::string, double> eq13_fit_metrics(const std::vector<FlowCheckRow>& rows, double from_pct = 30.0,
                                               double to_pct = 80.0);

}  // namespace rig::harness
