#pragma once
// Seed 001's crop truth: which ground points are wheat and which are soil
// (plant truth, local east-north frame of local_frame.h). The paper sprays
// wheat "40-80 mm" tall (Sec. 5.1, November, early growth), classes areas as
// sparse (computed cover D < 40 %) or normal (> 40 %) (Sec. 5.2) and sprays
// nothing where there are no plants (Sec. 1.1); it describes no plant layout.
//
// The model: drilled rows at a fixed spacing and bearing; along each row,
// plants at the positions of a Poisson process (seeds scattered a little
// across the row); each plant a few leaves, each a straight strip ("capsule")
// from the plant's base outwards at a random azimuth, as a seedling looks from
// above. How many plants a metre of row holds depends on the cover class of
// the ground under the plant: bare soil (none), sparse or normal; patches of
// each are polygons laid over a default class.
//
// Truth is a raster of 1 mm cells: a cell is plant when its centre lies on a
// leaf. is_plant() reads that raster, cover_fraction() counts its cells and
// copy_cells() hands a block of it to the camera renderer, so all three agree
// exactly; 1 mm is an eighth of a leaf's width and a third of a
// camera pixel's footprint on the ground (about 2.5 mm at 1280 x 720 from
// 1.5 m), fine enough to be ground truth for both.
//
// Reproducible: every plant is drawn from a counter-based hash of (seed, row,
// row cell), so the field is the same whatever order it is looked at in and
// needs no storage up front; the raster is built in tiles on first use and
// cached (the class is therefore not safe to share between threads; maps
// made by sharing_tiles() share the tiles safely).
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "emulators/field2d/leaf_raster.h"
#include "emulators/field2d/polygon.h"
#include "emulators/field2d/vec2.h"

namespace rig::field2d {

enum class CoverClass { bare, sparse, normal };
const char* cover_class_name(CoverClass cover);

struct CoverPatch {
    Polygon area;
    CoverClass cover = CoverClass::normal;
};

struct CropCoverParams {
    // Rows. The paper gives no row spacing: 0.20 m assumed (a common drill
    // spacing for winter wheat on the North China Plain, 15-25 cm).
    double row_spacing_m = 0.20;             // [0.05, 1.0] m
    double row_bearing_deg = 0.0;            // [0, 360) deg, compass; assumed: rows run north (a case sets it)
    double row_offset_m = 0.0;               // [-row_spacing_m, row_spacing_m] m: row 0's distance right of the origin
    double row_scatter_m = 0.015;            // [0, 0.1] m: seeds land up to this far either side of the row (assumed)
    // Plants per metre of row, by class (assumed: 100 / m at 0.20 m is 500
    // plants / m^2, a dense winter-wheat stand; 30 / m for sparse). With the
    // leaf sizes below they give a true cover of about 56 % (51-61 % per
    // 60 x 40 cm ROI) and 27 % (16-33 %), either side of Sec. 5.2's 40 %
    // sparse/normal split (docs/seed001-vision.md).
    double normal_plants_per_m = 100.0;      // [0, 1000] 1/m
    double sparse_plants_per_m = 30.0;       // [0, 1000] 1/m
    // Plant height (Sec. 5.1: wheat 40-80 mm), uniform between the two.
    double plant_height_min_m = 0.040;       // (0, 1] m
    double plant_height_max_m = 0.080;       // [min, 1] m
    // Leaves (assumed; two- to three-leaf seedlings): their number uniform in
    // [min, max], their length seen from above a uniform multiple of the
    // plant's height (seedling blades arch over, so they reach further than
    // the plant stands tall), their width constant.
    int leaves_min = 3;                      // [1, 20]
    int leaves_max = 5;                      // [leaves_min, 20]
    double leaf_length_per_height_min = 1.0; // (0, 5]
    double leaf_length_per_height_max = 1.5; // [min, 5]
    double leaf_width_m = 0.008;             // [0.001, 0.05] m
    CoverClass default_cover = CoverClass::normal;  // outside every patch
    std::vector<CoverPatch> patches;         // a later patch wins where two overlap
};

// Throws std::invalid_argument "crop.<field>: <what>".
void validate(const CropCoverParams& params);

class CropCoverMap {
public:
    // The truth raster's cell size (emulators/field2d/leaf_raster.h).
    static constexpr double kCellM = kRasterCellM;
    // A plant cell's value in copy_cells() (soil is 0): full scale of an
    // 8-bit cover image, so a bilinear sample of it reads as cover x 255.
    static constexpr std::uint8_t kPlantCell = kRasterPlantCell;

    // Throws std::invalid_argument as validate() does.
    CropCoverMap(CropCoverParams params, std::uint64_t seed);
    ~CropCoverMap();
    CropCoverMap(CropCoverMap&&) noexcept;
    CropCoverMap& operator=(CropCoverMap&&) noexcept;

    // True where the 1 mm cell holding `ground` is plant. Throws
    // std::invalid_argument for a non-finite point or one 1000 km or more away.
    bool is_plant(Vec2 ground) const;
    // The class of the ground at a point (the last patch holding it, else the default).
    CoverClass cover_class_at(Vec2 ground) const;
    // True cover D (0..1) of a ground quadrilateral (corners in order around
    // it, either sense): the share of the 1 mm cells whose centres lie inside
    // that are plant. Throws std::invalid_argument for a non-finite corner,
    // edges that cross, or a quadrilateral holding no cell centre.
    double cover_fraction(const std::array<Vec2, 4>& corners) const;
    // The block of cells east_cell .. east_cell + cols - 1 by north_cell ..
    // north_cell + rows - 1 (cell (i, j) is the ground from i to i + 1 mm east
    // and j to j + 1 mm north) into `out`, row r (the cells north_cell + r)
    // starting at out + r * stride: kPlantCell where plant, 0 where soil.
    // Throws std::invalid_argument for an empty block or one reaching 1000 km
    // or more from the origin.
    void copy_cells(std::int64_t east_cell, std::int64_t north_cell, int cols, int rows, std::uint8_t* out,
                    std::size_t stride) const;
    // Cells a word holds in copy_cell_bits().
    static constexpr int kCellsPerWord = 64;
    // The same block as copy_cells() gives, one bit a cell (an eighth of the
    // bytes, so a renderer's window of it stays in cache from frame to frame):
    // words_per_row x kCellsPerWord cells from east_cell, whose bit k of word
    // w in row r is cell (east_cell + 64 w + k, north_cell + r), 1 where
    // plant; row r starts at out + r * stride_words. Throws
    // std::invalid_argument for an empty block, one reaching 1000 km or more
    // from the origin, or an east_cell that is not a multiple of 64 (the
    // tiles' words start there).
    void copy_cell_bits(std::int64_t east_cell, std::int64_t north_cell, int words_per_row, int rows, std::uint64_t* out,
                        std::size_t stride_words) const;

    const CropCoverParams& params() const { return params_; }
    std::uint64_t seed() const { return seed_; }
    std::size_t cached_tile_count() const;
    // A number no other map built in this process has (a move hands it on):
    // a renderer keeps a copy of some cells and must know whose they are.
    std::uint64_t identity() const { return identity_; }

    // Another map of the same field that shares this one's built tiles: each
    // of the two may be used on its own thread (the tiles they share are
    // built once, under a lock; the rest of each map is its own), so two
    // cameras over the same ground draw its leaves once.
    CropCoverMap sharing_tiles() const;

private:
    struct Tile;
    class TileCache;
    struct SharedTiles;
    CropCoverMap(const CropCoverMap& other, std::shared_ptr<SharedTiles> shared);
    const Tile& tile(std::int64_t tile_east, std::int64_t tile_north) const;
    void rasterise(Tile& tile, std::int64_t tile_east, std::int64_t tile_north) const;
    // The plant cells of row north_cell from east_first up to (not including) east_end.
    std::int64_t plant_cells_in_row(std::int64_t north_cell, std::int64_t east_first, std::int64_t east_end) const;

    CropCoverParams params_;
    std::uint64_t seed_;
    std::uint64_t identity_;
    std::shared_ptr<SharedTiles> shared_;     // with the maps sharing_tiles() made
    mutable std::unique_ptr<TileCache> tiles_;  // this map's own look-up of them
    mutable const Tile* last_tile_ = nullptr;
    mutable std::uint64_t last_key_ = 0;
};

// Sec. 2.1's ground ROI of a nozzle, from the plant's truth: w across centred
// on the nozzle, from `near_m` to `near_m + depth_m` ahead of its ground point,
// square to the boom; corners near-left, near-right, far-right, far-left (the
// order of cover_fraction and of the controller's NozzleRoi). Defaults: Sec.
// 2.1's w = 600 mm, h1 = 200 mm, h2 = 400 mm.
std::array<Vec2, 4> nozzle_roi_ground(Vec2 boom_centre_ground, double heading_deg, double nozzle_right_m,
                                      double width_m = 0.600, double near_m = 0.200, double depth_m = 0.400);

}  // namespace rig::field2d
