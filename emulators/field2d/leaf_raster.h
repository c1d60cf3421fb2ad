#pragma once
// The crop truth's leaves on its 1 mm raster (emulators/field2d/crop_cover_map.h):
// a cell is plant when its centre lies within half the leaf's width of the
// leaf's mid-line. draw_leaf() marks those cells row by row as runs: a cell
// or two at each end of a row's run takes the exact distance test, the cells
// between are surely inside and filled at once. The cells it marks are the
// cells the exact test passes, cell for cell (tests/crop_cover_map_test.cpp).
#include <cstdint>

namespace rig::field2d {

// The raster's cell, 1 mm, and the value a plant cell holds in a block (soil
// is 0): CropCoverMap::kCellM and kPlantCell are these.
inline constexpr double kRasterCellM = 0.001;
inline constexpr std::uint8_t kRasterPlantCell = 255;

// The centre of raster cell i along an axis, in metres (cell i spans i to i + 1 mm).
double cell_centre_m(std::int64_t i);

enum class CentrePast { at_or_right, strictly_right };

// The first cell index in [first, end] whose centre lies at or right of x_m
// (or strictly right of it); end if none. Centres grow with the index, so the
// cells before it are exactly those a cell-by-cell comparison with
// cell_centre_m() puts on the other side.
std::int64_t first_centre_past(double x_m, std::int64_t first, std::int64_t end, CentrePast rule);

// A leaf seen from above: the points within half_width_m of the segment from
// its base to its tip, in metres from the south-west corner of a block of cells.
struct LeafStrip {
    double base_x_m;
    double base_y_m;
    double tip_x_m;
    double tip_y_m;
    double half_width_m;
};

// True where the centre of cell (i, j) of the block lies on the leaf: the exact test.
bool cell_on_leaf(const LeafStrip& leaf, std::int64_t i, std::int64_t j);

// Sets to 255 the cells of a side x side block (row-major from its south-west
// cell) whose centres lie on the leaf; leaves the others as they are.
void draw_leaf(std::uint8_t* cells, int side, const LeafStrip& leaf);

}  // namespace rig::field2d
