#include "emulators/field2d/crop_cover_map.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <deque>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "emulators/field2d/counter_hash.h"
#include "emulators/field2d/leaf_raster.h"
#include "rig/camera/parameter_check.h"

namespace rig::field2d {

namespace {

// Tiles of 256 x 256 cells (0.256 m): a camera's view (about 2.6 x 0.9 m of
// ground) touches some 40 of them.
constexpr int kTileShift = 8;
constexpr int kTileCells = 1 << kTileShift;
// A tile's row as bits: four 64-bit words.
constexpr int kWordShift = 6;
constexpr int kTileWords = kTileCells >> kWordShift;
static_assert(CropCoverMap::kCellsPerWord == 1 << kWordShift);
constexpr double kTileM = kTileCells * CropCoverMap::kCellM;
// At this many cached tiles (72 KiB each) the older half is dropped: tiles
// are pure functions of the seed, so dropping them changes nothing but time,
// and the oldest are those a boom driving on has left behind (dropping them
// all rebuilt the two cameras' and the judge's current views, some 100
// tiles, once every 1024).
constexpr std::size_t kMaxCachedTiles = 1024;
// Plants are drawn per row cell of this length along the row.
constexpr double kRowCellM = 0.25;
// Added to a plant's reach before asking whether it reaches a tile, so that
// rounding (some 1e-18 m here) can never leave out a plant that touches it.
constexpr double kSureM = 1e-9;

// Poisson by inversion of its CDF (mean at most 250 here, so exp(-mean) stays a normal double).
int poisson(HashStream& stream, double mean) {
    const double u = stream.uniform01();
    double probability = std::exp(-mean);
    double cumulative = probability;
    int count = 0;
    while (u > cumulative) {
        ++count;
        probability *= mean / count;
        cumulative += probability;
        if (probability < 1e-300 && count > mean) break;  // the tail is exhausted (rounding left u above 1 - eps)
    }
    return count;
}

std::int64_t floor_to_int(double value) {
    const auto truncated = static_cast<std::int64_t>(value);
    return static_cast<double>(truncated) > value ? truncated - 1 : truncated;
}

// Cells within 1000 km of the origin (is_plant's bound): far inside int64, and
// a tile index fits the 32 bits tile_key gives it.
constexpr std::int64_t kMaxCellIndex = 1'000'000'000;

std::uint64_t next_map_identity() {
    static std::atomic<std::uint64_t> count{0};
    return ++count;
}

std::uint64_t tile_key(std::int64_t east, std::int64_t north) {
    return (static_cast<std::uint64_t>(east) << 32) ^ (static_cast<std::uint64_t>(north) & 0xffffffffULL);
}

// The crop's parameters are checked like the cameras' (one message shape).
void require(bool ok, const char* field, double value, const char* bounds) {
    rig::camera::require_parameter(ok, "crop", field, value, bounds);
}
using rig::camera::finite_within;

bool segments_cross(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
    const double d1 = cross(b - a, c - a);
    const double d2 = cross(b - a, d - a);
    const double d3 = cross(d - c, a - c);
    const double d4 = cross(d - c, b - c);
    return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
}

// The plant cells of a row's bits from cell `from` up to (not including) `to`.
int plant_bits_in(const std::uint64_t* words, int from, int to) {
    int plant = 0;
    while (from < to) {
        const int word = from >> kWordShift;
        const int low = from & 63;
        const int high = std::min(to - (word << kWordShift), 64);  // one past the last bit counted
        const std::uint64_t below_high = high == 64 ? ~0ULL : (1ULL << high) - 1ULL;
        plant += std::popcount(words[word] & below_high & (~0ULL << low));
        from = (word << kWordShift) + high;
    }
    return plant;
}

// The tile's bytes as bits (bit k of a word is the byte at k: 8 bytes at a
// time, each 0 or kPlantCell, their top bits gathered by one multiply).
void pack_bits(const std::uint8_t* cells, std::uint64_t* words, int count) {
    for (int w = 0; w < count / 64; ++w) {
        std::uint64_t word = 0;
        for (int k = 0; k < 8; ++k) {
            std::uint64_t eight = 0;
            std::memcpy(&eight, cells + 64 * w + 8 * k, sizeof eight);
            // Byte b's top bit (bit 8b + 7) lands at bit 56 + b; no two products overlap below it.
            const std::uint64_t byte_bits = ((eight & 0x8080808080808080ULL) * 0x0002040810204081ULL) >> 56;
            word |= byte_bits << (8 * k);
        }
        words[w] = word;
    }
}

// One row of one tile's part of a block of cells: where it lies in the
// block (row, first column) and in the tile, and how many cells it has.
struct TileRow {
    std::size_t block_row;
    std::size_t block_col;
    std::size_t tile_row;
    std::size_t tile_col;
    std::size_t cells;
};

// Each tile's rows within the block of cols x rows cells from (east_cell,
// north_cell), the tile from tile_at(tile_east, tile_north).
template <typename TileAt, typename EachRow>
void for_each_tile_row(std::int64_t east_cell, std::int64_t north_cell, std::int64_t cols, std::int64_t rows, const TileAt& tile_at,
                       const EachRow& each_row) {
    const std::int64_t east_end = east_cell + cols;
    const std::int64_t north_end = north_cell + rows;
    for (std::int64_t tile_north = north_cell >> kTileShift; tile_north * kTileCells < north_end; ++tile_north) {
        const std::int64_t j_first = std::max(north_cell, tile_north * kTileCells);
        const std::int64_t j_end = std::min(north_end, (tile_north + 1) * kTileCells);
        for (std::int64_t tile_east = east_cell >> kTileShift; tile_east * kTileCells < east_end; ++tile_east) {
            const std::int64_t i_first = std::max(east_cell, tile_east * kTileCells);
            const std::int64_t i_end = std::min(east_end, (tile_east + 1) * kTileCells);
            const auto& tile = tile_at(tile_east, tile_north);
            for (std::int64_t j = j_first; j < j_end; ++j) {
                each_row(tile, TileRow{static_cast<std::size_t>(j - north_cell), static_cast<std::size_t>(i_first - east_cell),
                                       static_cast<std::size_t>(j - tile_north * kTileCells),
                                       static_cast<std::size_t>(i_first - tile_east * kTileCells), static_cast<std::size_t>(i_end - i_first)});
            }
        }
    }
}

}  // namespace

struct CropCoverMap::Tile {
    // kPlantCell or 0 per cell, row-major from the tile's south-west cell.
    std::vector<std::uint8_t> plant = std::vector<std::uint8_t>(static_cast<std::size_t>(kTileCells) * kTileCells, 0);
    // The same, a bit a cell (kTileWords words a row), for cover counts and copy_cell_bits().
    std::vector<std::uint64_t> bits = std::vector<std::uint64_t>(static_cast<std::size_t>(kTileWords) * kTileCells, 0);
};

// Built tiles by key, at most kMaxCachedTiles, the older half dropped when full.
class CropCoverMap::TileCache {
public:
    const Tile* find(std::uint64_t key) const {
        const auto found = tiles_.find(key);
        return found == tiles_.end() ? nullptr : found->second.get();
    }
    // The tile stored under `key`: `tile` unless one was there already.
    // Makes room first, so pointers find() gave before may dangle.
    const Tile* insert(std::uint64_t key, std::shared_ptr<const Tile> tile) {
        if (const Tile* held = find(key)) return held;
        if (tiles_.size() >= kMaxCachedTiles) {
            const std::size_t dropped = order_.size() / 2;
            for (std::size_t k = 0; k < dropped; ++k) tiles_.erase(order_[k]);
            order_.erase(order_.begin(), order_.begin() + static_cast<std::ptrdiff_t>(dropped));
        }
        order_.push_back(key);
        return tiles_.emplace(key, std::move(tile)).first->second.get();
    }
    // The shared pointer stored under `key` (one find() has found).
    std::shared_ptr<const Tile> share(std::uint64_t key) const { return tiles_.at(key); }
    std::size_t size() const { return tiles_.size(); }

private:
    std::unordered_map<std::uint64_t, std::shared_ptr<const Tile>> tiles_;
    std::deque<std::uint64_t> order_;  // tiles_'s keys, oldest first
};

struct CropCoverMap::SharedTiles {
    std::mutex mutex;
    TileCache tiles;
};

const char* cover_class_name(CoverClass cover) {
    switch (cover) {
        case CoverClass::bare: return "bare";
        case CoverClass::sparse: return "sparse";
        case CoverClass::normal: return "normal";
    }
    return "unknown";
}

void validate(const CropCoverParams& p) {
    require(finite_within(p.row_spacing_m, 0.05, 1.0), "row_spacing_m", p.row_spacing_m, "[0.05, 1.0] m");
    require(finite_within(p.row_bearing_deg, 0.0, 360.0) && p.row_bearing_deg < 360.0, "row_bearing_deg", p.row_bearing_deg, "[0, 360) deg");
    require(finite_within(p.row_offset_m, -p.row_spacing_m, p.row_spacing_m), "row_offset_m", p.row_offset_m, "[-row_spacing_m, row_spacing_m]");
    require(finite_within(p.row_scatter_m, 0.0, 0.1), "row_scatter_m", p.row_scatter_m, "[0, 0.1] m");
    require(finite_within(p.normal_plants_per_m, 0.0, 1000.0), "normal_plants_per_m", p.normal_plants_per_m, "[0, 1000] 1/m");
    require(finite_within(p.sparse_plants_per_m, 0.0, 1000.0), "sparse_plants_per_m", p.sparse_plants_per_m, "[0, 1000] 1/m");
    require(finite_within(p.plant_height_min_m, 1e-9, 1.0), "plant_height_min_m", p.plant_height_min_m, "(0, 1] m");
    require(finite_within(p.plant_height_max_m, p.plant_height_min_m, 1.0), "plant_height_max_m", p.plant_height_max_m, "[plant_height_min_m, 1] m");
    require(p.leaves_min >= 1 && p.leaves_min <= 20, "leaves_min", p.leaves_min, "[1, 20]");
    require(p.leaves_max >= p.leaves_min && p.leaves_max <= 20, "leaves_max", p.leaves_max, "[leaves_min, 20]");
    require(finite_within(p.leaf_length_per_height_min, 1e-9, 5.0), "leaf_length_per_height_min", p.leaf_length_per_height_min, "(0, 5]");
    require(finite_within(p.leaf_length_per_height_max, p.leaf_length_per_height_min, 5.0), "leaf_length_per_height_max",
            p.leaf_length_per_height_max, "[leaf_length_per_height_min, 5]");
    require(finite_within(p.leaf_width_m, 0.001, 0.05), "leaf_width_m", p.leaf_width_m, "[0.001, 0.05] m");
}

CropCoverMap::CropCoverMap(CropCoverParams params, std::uint64_t seed)
    : params_(std::move(params)),
      seed_(seed),
      identity_(next_map_identity()),
      shared_(std::make_shared<SharedTiles>()),
      tiles_(std::make_unique<TileCache>()) {
    validate(params_);
}

CropCoverMap::CropCoverMap(const CropCoverMap& other, std::shared_ptr<SharedTiles> shared)
    : params_(other.params_),
      seed_(other.seed_),
      identity_(next_map_identity()),
      shared_(std::move(shared)),
      tiles_(std::make_unique<TileCache>()) {}

CropCoverMap CropCoverMap::sharing_tiles() const { return CropCoverMap(*this, shared_); }
CropCoverMap::~CropCoverMap() = default;
CropCoverMap::CropCoverMap(CropCoverMap&&) noexcept = default;
CropCoverMap& CropCoverMap::operator=(CropCoverMap&&) noexcept = default;

CoverClass CropCoverMap::cover_class_at(Vec2 ground) const {
    for (auto patch = params_.patches.rbegin(); patch != params_.patches.rend(); ++patch) {
        if (patch->area.contains(ground)) return patch->cover;
    }
    return params_.default_cover;
}

bool CropCoverMap::is_plant(Vec2 ground) const {
    // The renderer asks this four times a pixel: std::floor is a libm call on
    // the baseline x86-64 target, so the floors are done by truncation.
    // (Within 1000 km of the origin: a field, and far inside int64 cells.)
    if (!(std::abs(ground.east_m) < 1e6 && std::abs(ground.north_m) < 1e6)) {
        throw std::invalid_argument("crop is_plant: (" + std::to_string(ground.east_m) + ", " + std::to_string(ground.north_m) +
                                    ") m is not a ground point within 1000 km of the origin");
    }
    const std::int64_t east = floor_to_int(ground.east_m / kCellM);
    const std::int64_t north = floor_to_int(ground.north_m / kCellM);
    // Floor division into tiles (an arithmetic shift: kTileCells is 2^8) and cells within them.
    const std::int64_t tile_east = east >> kTileShift;
    const std::int64_t tile_north = north >> kTileShift;
    const Tile& t = tile(tile_east, tile_north);
    const auto i = static_cast<std::size_t>(east - tile_east * kTileCells);
    const auto j = static_cast<std::size_t>(north - tile_north * kTileCells);
    return t.plant[j * kTileCells + i] != 0;
}

std::size_t CropCoverMap::cached_tile_count() const { return tiles_->size(); }

const CropCoverMap::Tile& CropCoverMap::tile(std::int64_t tile_east, std::int64_t tile_north) const {
    const std::uint64_t key = tile_key(tile_east, tile_north);
    if (last_tile_ != nullptr && key == last_key_) return *last_tile_;
    const Tile* found = tiles_->find(key);
    if (found == nullptr) {
        std::shared_ptr<const Tile> shared;
        {
            const std::lock_guard lock(shared_->mutex);
            if (shared_->tiles.find(key) != nullptr) shared = shared_->tiles.share(key);
        }
        if (!shared) {
            // Built outside the lock (another map's thread may build the same
            // tile meanwhile: the same cells, and the first one stored is kept).
            auto fresh = std::make_shared<Tile>();
            rasterise(*fresh, tile_east, tile_north);
            pack_bits(fresh->plant.data(), fresh->bits.data(), kTileCells * kTileCells);
            const std::lock_guard lock(shared_->mutex);
            shared_->tiles.insert(key, std::move(fresh));
            shared = shared_->tiles.share(key);
        }
        found = tiles_->insert(key, std::move(shared));
    }
    last_tile_ = found;
    last_key_ = key;
    return *last_tile_;
}

void CropCoverMap::rasterise(Tile& tile, std::int64_t tile_east, std::int64_t tile_north) const {
    const CropCoverParams& p = params_;
    const Vec2 along_axis = forward_of(p.row_bearing_deg);
    const Vec2 across_axis = right_of(p.row_bearing_deg);
    const double east0 = static_cast<double>(tile_east) * kTileM;
    const double north0 = static_cast<double>(tile_north) * kTileM;
    // How far from its row cell and row line a leaf can reach.
    const double reach = p.plant_height_max_m * p.leaf_length_per_height_max + p.leaf_width_m + p.row_scatter_m;

    double across_min = 1e300, across_max = -1e300, along_min = 1e300, along_max = -1e300;
    for (const Vec2 corner : {Vec2{east0, north0}, Vec2{east0 + kTileM, north0}, Vec2{east0, north0 + kTileM},
                              Vec2{east0 + kTileM, north0 + kTileM}}) {
        const double across = dot(corner, across_axis) - p.row_offset_m;
        const double along = dot(corner, along_axis);
        across_min = std::min(across_min, across);
        across_max = std::max(across_max, across);
        along_min = std::min(along_min, along);
        along_max = std::max(along_max, along);
    }
    const auto row_first = static_cast<std::int64_t>(std::floor((across_min - reach) / p.row_spacing_m));
    const auto row_last = static_cast<std::int64_t>(std::ceil((across_max + reach) / p.row_spacing_m));
    const auto cell_first = static_cast<std::int64_t>(std::floor((along_min - reach) / kRowCellM));
    const auto cell_last = static_cast<std::int64_t>(std::floor((along_max + reach) / kRowCellM));

    // Every class's plants are drawn at the densest rate and thinned by the
    // class under each plant, so a patch edge cuts the row where it lies.
    const double densest = std::max(p.normal_plants_per_m, p.sparse_plants_per_m);
    const double half_width = 0.5 * p.leaf_width_m;
    for (std::int64_t row = row_first; row <= row_last; ++row) {
        for (std::int64_t cell = cell_first; cell <= cell_last; ++cell) {
            HashStream stream(hash_key(seed_, static_cast<std::uint64_t>(row), static_cast<std::uint64_t>(cell)));
            const int candidates = poisson(stream, densest * kRowCellM);
            for (int plant = 0; plant < candidates; ++plant) {
                // Draw every number of a plant whether it is kept or not, so a
                // patch changes only its own plants.
                const double along = (static_cast<double>(cell) + stream.uniform01()) * kRowCellM;
                const double across = static_cast<double>(row) * p.row_spacing_m + p.row_offset_m +
                                      (2.0 * stream.uniform01() - 1.0) * p.row_scatter_m;
                const double keep = stream.uniform01();
                const double height = p.plant_height_min_m + stream.uniform01() * (p.plant_height_max_m - p.plant_height_min_m);
                const int leaves = p.leaves_min + std::min(p.leaves_max - p.leaves_min,
                                                           static_cast<int>(stream.uniform01() * (p.leaves_max - p.leaves_min + 1)));
                const Vec2 base = along * along_axis + across * across_axis;
                const double bx = base.east_m - east0;
                const double by = base.north_m - north0;
                // A plant whose longest leaf cannot reach the tile draws nothing
                // on it: its class and leaves are not worked out (their numbers
                // are still drawn, above and below, so the stream stays in step).
                const double plant_reach = height * p.leaf_length_per_height_max + half_width + kSureM;
                const bool near_tile = bx + plant_reach >= 0.0 && bx - plant_reach <= kTileM && by + plant_reach >= 0.0 &&
                                       by - plant_reach <= kTileM;
                bool kept = false;
                if (near_tile) {
                    double rate = 0.0;
                    switch (cover_class_at(base)) {
                        case CoverClass::bare: rate = 0.0; break;
                        case CoverClass::sparse: rate = p.sparse_plants_per_m; break;
                        case CoverClass::normal: rate = p.normal_plants_per_m; break;
                    }
                    kept = densest > 0.0 && keep < rate / densest;
                }
                for (int leaf = 0; leaf < leaves; ++leaf) {
                    const double azimuth = 2.0 * std::numbers::pi * stream.uniform01();
                    const double length = height * (p.leaf_length_per_height_min +
                                                    stream.uniform01() * (p.leaf_length_per_height_max - p.leaf_length_per_height_min));
                    if (!kept) continue;
                    const double tx = bx + length * std::cos(azimuth);
                    const double ty = by + length * std::sin(azimuth);
                    if (std::max(bx, tx) + half_width < 0.0 || std::min(bx, tx) - half_width > kTileM) continue;  // beside the tile
                    if (std::max(by, ty) + half_width < 0.0 || std::min(by, ty) - half_width > kTileM) continue;  // above or below it
                    draw_leaf(tile.plant.data(), kTileCells, LeafStrip{bx, by, tx, ty, half_width});
                }
            }
        }
    }
}

double CropCoverMap::cover_fraction(const std::array<Vec2, 4>& corners) const {
    double east_min = 1e300, east_max = -1e300, north_min = 1e300, north_max = -1e300;
    for (std::size_t i = 0; i < 4; ++i) {
        if (!std::isfinite(corners[i].east_m) || !std::isfinite(corners[i].north_m)) {
            throw std::invalid_argument("crop cover_fraction: corner " + std::to_string(i) + " is not finite");
        }
        east_min = std::min(east_min, corners[i].east_m);
        east_max = std::max(east_max, corners[i].east_m);
        north_min = std::min(north_min, corners[i].north_m);
        north_max = std::max(north_max, corners[i].north_m);
    }
    if (segments_cross(corners[0], corners[1], corners[2], corners[3]) ||
        segments_cross(corners[1], corners[2], corners[3], corners[0])) {
        throw std::invalid_argument("crop cover_fraction: the quadrilateral's edges cross (corners out of order)");
    }
    if ((east_max - east_min) * (north_max - north_min) > 100.0) {
        throw std::invalid_argument("crop cover_fraction: the quadrilateral spans more than 100 m^2 (an ROI is 0.24 m^2)");
    }
    if (!(std::abs(east_min) < 1e6 && std::abs(east_max) < 1e6 && std::abs(north_min) < 1e6 && std::abs(north_max) < 1e6)) {
        throw std::invalid_argument("crop cover_fraction: the quadrilateral reaches 1000 km or more from the origin");
    }
    const auto i_first = static_cast<std::int64_t>(std::floor(east_min / kCellM));
    const auto i_last = static_cast<std::int64_t>(std::floor(east_max / kCellM));
    const auto j_first = static_cast<std::int64_t>(std::floor(north_min / kCellM));
    const auto j_last = static_cast<std::int64_t>(std::floor(north_max / kCellM));
    // A cell is inside when its centre is, by the crossing-number rule: an
    // odd number of the quadrilateral's edges cross its row right of it (a
    // centre on an edge may fall either way; a 1 mm cell on the edge of a
    // 0.24 m^2 ROI is noise). Along a row the centres only grow, so each
    // crossing splits the row at one cell, found by the same comparison a
    // cell-by-cell test makes; the cells between splits are counted in runs.
    std::int64_t inside = 0;
    std::int64_t plant = 0;
    for (std::int64_t j = j_first; j <= j_last; ++j) {
        const double y = (static_cast<double>(j) + 0.5) * kCellM;
        std::array<std::int64_t, 4> splits{};
        std::size_t crossings = 0;
        for (std::size_t i = 0, k = 3; i < 4; k = i++) {
            const Vec2 a = corners[i];
            const Vec2 b = corners[k];
            if ((a.north_m > y) != (b.north_m > y)) {
                const double x_at = a.east_m + (y - a.north_m) * (b.east_m - a.east_m) / (b.north_m - a.north_m);
                splits[crossings++] = first_centre_past(x_at, i_first, i_last + 1, CentrePast::at_or_right);
            }
        }
        for (std::size_t k = 1; k < crossings; ++k) {  // into order (at most four)
            for (std::size_t m = k; m > 0 && splits[m - 1] > splits[m]; --m) std::swap(splits[m - 1], splits[m]);
        }
        // Cells from splits[k - 1] to splits[k] have crossings - k crossings right of them.
        for (std::size_t k = 0; k <= crossings; ++k) {
            if ((crossings - k) % 2 == 0) continue;
            const std::int64_t from = k == 0 ? i_first : splits[k - 1];
            const std::int64_t to = k == crossings ? i_last + 1 : splits[k];
            if (to <= from) continue;
            inside += to - from;
            plant += plant_cells_in_row(j, from, to);
        }
    }
    if (inside == 0) throw std::invalid_argument("crop cover_fraction: the quadrilateral holds no 1 mm cell centre");
    return static_cast<double>(plant) / static_cast<double>(inside);
}

std::int64_t CropCoverMap::plant_cells_in_row(std::int64_t north_cell, std::int64_t east_first, std::int64_t east_end) const {
    const std::int64_t tile_north = north_cell >> kTileShift;
    const auto j = static_cast<std::size_t>(north_cell - tile_north * kTileCells);
    std::int64_t plant = 0;
    for (std::int64_t tile_east = east_first >> kTileShift; tile_east * kTileCells < east_end; ++tile_east) {
        const std::int64_t from = std::max(east_first, tile_east * kTileCells);
        const std::int64_t to = std::min(east_end, (tile_east + 1) * kTileCells);
        const Tile& t = tile(tile_east, tile_north);
        plant += plant_bits_in(t.bits.data() + j * kTileWords, static_cast<int>(from - tile_east * kTileCells),
                               static_cast<int>(to - tile_east * kTileCells));
    }
    return plant;
}

void CropCoverMap::copy_cells(std::int64_t east_cell, std::int64_t north_cell, int cols, int rows, std::uint8_t* out,
                              std::size_t stride) const {
    const auto far = [](std::int64_t first, int count) {
        return first <= -kMaxCellIndex || first + count >= kMaxCellIndex;
    };
    if (cols <= 0 || rows <= 0 || far(east_cell, cols) || far(north_cell, rows)) {
        throw std::invalid_argument("crop copy_cells: " + std::to_string(cols) + " x " + std::to_string(rows) + " cells from (" +
                                    std::to_string(east_cell) + ", " + std::to_string(north_cell) +
                                    ") mm is empty or reaches 1000 km or more from the origin");
    }
    for_each_tile_row(east_cell, north_cell, cols, rows, [this](std::int64_t east, std::int64_t north) -> const Tile& { return tile(east, north); },
                      [&](const Tile& t, const TileRow& row) {
                          std::memcpy(out + row.block_row * stride + row.block_col, t.plant.data() + row.tile_row * kTileCells + row.tile_col,
                                      row.cells);
                      });
}

void CropCoverMap::copy_cell_bits(std::int64_t east_cell, std::int64_t north_cell, int words_per_row, int rows, std::uint64_t* out,
                                  std::size_t stride_words) const {
    const std::int64_t cols = static_cast<std::int64_t>(words_per_row) * kCellsPerWord;
    if (words_per_row <= 0 || rows <= 0 || east_cell % kCellsPerWord != 0 || east_cell <= -kMaxCellIndex ||
        east_cell + cols >= kMaxCellIndex || north_cell <= -kMaxCellIndex || north_cell + rows >= kMaxCellIndex) {
        throw std::invalid_argument("crop copy_cell_bits: " + std::to_string(words_per_row) + " words x " + std::to_string(rows) +
                                    " rows of cells from (" + std::to_string(east_cell) + ", " + std::to_string(north_cell) +
                                    ") mm is empty, reaches 1000 km or more from the origin or starts off a multiple of 64 cells east");
    }
    // Whole words: east_cell and the tiles' edges are multiples of 64.
    for_each_tile_row(east_cell, north_cell, cols, rows, [this](std::int64_t east, std::int64_t north) -> const Tile& { return tile(east, north); },
                      [&](const Tile& t, const TileRow& row) {
                          std::memcpy(out + row.block_row * stride_words + (row.block_col >> kWordShift),
                                      t.bits.data() + row.tile_row * kTileWords + (row.tile_col >> kWordShift),
                                      (row.cells >> kWordShift) * sizeof(std::uint64_t));
                      });
}

std::array<Vec2, 4> nozzle_roi_ground(Vec2 boom_centre_ground, double heading_deg, double nozzle_right_m, double width_m,
                                      double near_m, double depth_m) {
    auto at = [&](double right, double ahead) { return body_to_field(boom_centre_ground, heading_deg, right, ahead); };
    const double half = 0.5 * width_m;
    return {at(nozzle_right_m - half, near_m), at(nozzle_right_m + half, near_m), at(nozzle_right_m + half, near_m + depth_m),
            at(nozzle_right_m - half, near_m + depth_m)};
}

}  // namespace rig::field2d
