#include "emulators/field2d/leaf_raster.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

namespace rig::field2d {

namespace {

constexpr double kCellM = kRasterCellM;
// draw_leaf()'s margin between a leaf's surely-inside and surely-outside cells
// (rounding is some 1e-16 m here, away from kFlat).
constexpr double kSureM = 1e-9;
// A leaf within this (as a slope) of square to an axis has that condition of
// its rectangle independent of x (its bounds would be past 1e9 m).
constexpr double kFlat = 1e-12;
// 1 / kCellM, written out: a multiplication by it, where the code has one,
// is not the same rounding as a division by kCellM.
constexpr double kCellsPerM = 1000.0;
static_assert(kCellsPerM * kCellM == 1.0);
constexpr std::uint8_t kPlantCell = kRasterPlantCell;

// floor() of a value held within [low, high] first (so it fits an int, and
// truncation and a correction give the floor without a libm call on the
// baseline x86-64 target): std::floor(value) clamped to the range.
int floor_within(double value, int low, int high) {
    const double held = std::clamp(value, static_cast<double>(low), static_cast<double>(high));
    const int truncated = static_cast<int>(held);
    return static_cast<double>(truncated) > held ? truncated - 1 : truncated;
}

int ceil_within(double value, int low, int high) { return -floor_within(-value, -high, -low); }

// A cell index within a block's row (first_centre_past() keeps it in [first, end]).
int within_row(std::int64_t index) { return static_cast<int>(index); }

// Squared distance from p to the segment a-b.
double segment_distance_sq(double px, double py, double ax, double ay, double bx, double by) {
    const double dx = bx - ax;
    const double dy = by - ay;
    const double length_sq = dx * dx + dy * dy;
    double t = length_sq > 0.0 ? ((px - ax) * dx + (py - ay) * dy) / length_sq : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const double ex = px - (ax + t * dx);
    const double ey = py - (ay + t * dy);
    return ex * ex + ey * ey;
}

// The x extent, at height y, of the points within `radius` of the segment a-b
// (a capsule: convex, so its slice is one interval, the union of the slices of
// its two end discs and its middle rectangle). Empty (low > high) if none.
struct Span {
    double low = 1e300;
    double high = -1e300;
    void cover(double from, double to) {
        if (from > to) return;
        low = std::min(low, from);
        high = std::max(high, to);
    }
    void cover_disc(double centre, double half) { cover(centre - half, centre + half); }
};

// A leaf: the points within some radius of the segment a-b. Seen along a
// row y, each of its parts (the two end discs, the rectangle between them)
// covers one interval of x, and so does their union (a capsule is convex).
struct Capsule {
    double ax, ay, bx, by;
    double ux, uy, length;  // unit vector a -> b and the segment's length
    // The rectangle 0 <= (p - a).u <= length, |(p - a).n| <= radius (n square
    // to u) is linear in x along a row: x times a slope plus an offset
    // linear in y, for each of the two conditions; their reciprocal slopes
    // (0 where a condition does not depend on x).
    double along_inverse = 0.0;
    double across_inverse = 0.0;

    Capsule(double from_x, double from_y, double to_x, double to_y)
        : ax(from_x), ay(from_y), bx(to_x), by(to_y), length(std::hypot(to_x - from_x, to_y - from_y)) {
        ux = length > 0.0 ? (bx - ax) / length : 0.0;
        uy = length > 0.0 ? (by - ay) / length : 0.0;
        if (std::abs(ux) >= kFlat) along_inverse = 1.0 / ux;
        if (std::abs(uy) >= kFlat) across_inverse = -1.0 / uy;
    }

    // The x extents at height y of the points within inner_radius and within
    // outer_radius (empty, low > high, if none), both at once: they share
    // all but the radius.
    std::pair<Span, Span> slices(double y, double inner_radius, double outer_radius) const {
        std::pair<Span, Span> spans;
        for (const auto& [cx, cy] : {std::pair{ax, ay}, std::pair{bx, by}}) {
            const double dy = y - cy;
            if (std::abs(dy) <= outer_radius) spans.second.cover_disc(cx, std::sqrt(outer_radius * outer_radius - dy * dy));
            if (std::abs(dy) <= inner_radius) spans.first.cover_disc(cx, std::sqrt(inner_radius * inner_radius - dy * dy));
        }
        if (length <= 0.0) return spans;
        double low = -1e300;
        double high = 1e300;
        // Along: 0 <= (x - ax) ux + (y - ay) uy <= length.
        const double along_offset = -ax * ux + (y - ay) * uy;
        if (along_inverse == 0.0) {
            if (along_offset < 0.0 || along_offset > length) return spans;
        } else {
            const double x1 = -along_offset * along_inverse;
            const double x2 = (length - along_offset) * along_inverse;
            low = std::min(x1, x2);
            high = std::max(x1, x2);
        }
        // Across: -radius <= -(x - ax) uy + (y - ay) ux <= radius.
        const double across_offset = ax * uy + (y - ay) * ux;
        auto across = [&](double radius, Span& span) {
            if (across_inverse == 0.0) {
                if (across_offset >= -radius && across_offset <= radius) span.cover(low, high);
                return;
            }
            const double x1 = (-radius - across_offset) * across_inverse;
            const double x2 = (radius - across_offset) * across_inverse;
            span.cover(std::max(low, std::min(x1, x2)), std::min(high, std::max(x1, x2)));
        };
        across(inner_radius, spans.first);
        across(outer_radius, spans.second);
        return spans;
    }
};

}  // namespace

double cell_centre_m(std::int64_t i) { return (static_cast<double>(i) + 0.5) * kCellM; }

std::int64_t first_centre_past(double x_m, std::int64_t first, std::int64_t end, CentrePast rule) {
    // A guess only, from a product and a truncation (no floor, a libm call on
    // the baseline x86-64 target; draw_leaf() asks this per row): at most a
    // cell off, and the walk below ends on the first centre past x_m from
    // wherever it starts in [first, end].
    const double scaled = std::clamp(x_m * kCellsPerM - 0.5, static_cast<double>(first), static_cast<double>(end));
    auto i = static_cast<std::int64_t>(scaled);
    auto past = [&](std::int64_t k) { return rule == CentrePast::strictly_right ? cell_centre_m(k) > x_m : cell_centre_m(k) >= x_m; };
    while (i > first && past(i - 1)) --i;
    while (i < end && !past(i)) ++i;
    return i;
}

bool cell_on_leaf(const LeafStrip& leaf, std::int64_t i, std::int64_t j) {
    return segment_distance_sq(cell_centre_m(i), cell_centre_m(j), leaf.base_x_m, leaf.base_y_m, leaf.tip_x_m, leaf.tip_y_m) <=
           leaf.half_width_m * leaf.half_width_m;
}

void draw_leaf(std::uint8_t* cells, int side, const LeafStrip& leaf) {
    const double bx = leaf.base_x_m;
    const double by = leaf.base_y_m;
    const double tx = leaf.tip_x_m;
    const double ty = leaf.tip_y_m;
    const double half_width = leaf.half_width_m;
    const double side_m = side * kCellM;
    const Capsule leaf_shape(bx, by, tx, ty);
    const int j_first = std::max(0, static_cast<int>(std::floor((std::min(by, ty) - half_width) / kCellM)));
    const int j_last = std::min(side - 1, static_cast<int>(std::floor((std::max(by, ty) + half_width) / kCellM)));
    for (int j = j_first; j <= j_last; ++j) {
        const double cy = cell_centre_m(j);
        // Centres within the slice narrowed by kSureM are surely on the leaf
        // and centres outside the one widened by it surely not; only those
        // between (a band 2 nm wide at each end of the row's run, so rarely
        // any) take the exact test.
        const auto [sure, maybe] = leaf_shape.slices(cy, half_width - kSureM, half_width + kSureM);
        if (maybe.low > maybe.high || maybe.high < 0.0 || maybe.low > side_m) continue;
        const int i_first = floor_within(maybe.low / kCellM - 0.5, 0, side);
        const int i_end = ceil_within(maybe.high / kCellM - 0.5, -1, side - 1) + 1;
        if (i_first >= i_end) continue;
        std::uint8_t* row = cells + static_cast<std::size_t>(j) * static_cast<std::size_t>(side);
        auto exact = [&](int from, int to) {
            for (int i = from; i < to; ++i) {
                if (cell_on_leaf(leaf, i, j)) row[i] = kPlantCell;
            }
        };
        // The run's ends among the cells: maybe.low <= centre, then sure.low <
        // centre < sure.high, then centre <= maybe.high.
        const int maybe_first = within_row(first_centre_past(maybe.low, i_first, i_end, CentrePast::at_or_right));
        const int maybe_end = std::max(maybe_first, within_row(first_centre_past(maybe.high, i_first, i_end, CentrePast::strictly_right)));
        if (!(sure.low < sure.high)) {
            exact(maybe_first, maybe_end);
            continue;
        }
        // Mostly the sure run starts and ends where the maybe run does: its
        // first cell's centre is right of sure.low (so no centre from
        // i_first on is first past it later) and its last one's left of
        // sure.high (so none before maybe_end reaches it); only else walk.
        const bool starts_sure = maybe_first == i_end || cell_centre_m(maybe_first) > sure.low;
        const int sure_first =
            starts_sure ? maybe_first : std::max(maybe_first, within_row(first_centre_past(sure.low, i_first, i_end, CentrePast::strictly_right)));
        const bool ends_sure = maybe_end > sure_first && cell_centre_m(maybe_end - 1) < sure.high;
        const int sure_end = ends_sure ? maybe_end
                                       : std::min(maybe_end, std::max(sure_first, within_row(first_centre_past(sure.high, i_first, i_end, CentrePast::at_or_right))));
        exact(maybe_first, sure_first);
        if (sure_end > sure_first) std::memset(row + sure_first, kPlantCell, static_cast<std::size_t>(sure_end - sure_first));
        exact(sure_end, maybe_end);
    }
}

}  // namespace rig::field2d
