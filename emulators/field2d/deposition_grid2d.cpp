#include "emulators/field2d/deposition_grid2d.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rig::field2d {

double fan_width_m(double height_m, double fan_angle_deg) {
    if (!std::isfinite(height_m) || height_m < 0.0 || !std::isfinite(fan_angle_deg) || fan_angle_deg <= 0.0 ||
        fan_angle_deg >= 180.0) {
        throw std::invalid_argument("fan width: needs height >= 0 m and an angle in (0, 180) deg, got " +
                                    std::to_string(height_m) + " m, " + std::to_string(fan_angle_deg) + " deg");
    }
    return 2.0 * height_m * std::tan(0.5 * fan_angle_deg * M_PI / 180.0);
}

DepositionGrid2d::DepositionGrid2d(const DepositionGrid2dParams& params) : params_(params) {
    const auto finite = [](double v) { return std::isfinite(v); };
    if (!finite(params.east_min_m) || !finite(params.east_max_m) || !(params.east_max_m > params.east_min_m)) {
        throw std::invalid_argument("deposition grid: east_min_m < east_max_m required (finite)");
    }
    if (!finite(params.north_min_m) || !finite(params.north_max_m) || !(params.north_max_m > params.north_min_m)) {
        throw std::invalid_argument("deposition grid: north_min_m < north_max_m required (finite)");
    }
    if (!(params.cell_m > 0.0) || params.cell_m > 1.0) {
        throw std::invalid_argument("deposition grid: cell_m must be in (0, 1] m, got " + std::to_string(params.cell_m));
    }
    if (params.nozzle_count < 1 || params.nozzle_count > 32) {
        throw std::invalid_argument("deposition grid: nozzle_count must be in [1, 32], got " +
                                    std::to_string(params.nozzle_count));
    }
    const double nx = std::ceil((params.east_max_m - params.east_min_m) / params.cell_m);
    const double ny = std::ceil((params.north_max_m - params.north_min_m) / params.cell_m);
    const double cells = nx * ny * params.nozzle_count;
    if (cells > static_cast<double>(params.max_cells_total)) {
        throw std::invalid_argument("deposition grid: " + std::to_string(nx) + " x " + std::to_string(ny) + " cells x " +
                                    std::to_string(params.nozzle_count) + " nozzles exceeds max_cells_total " +
                                    std::to_string(params.max_cells_total) + " (shrink the extent or grow cell_m)");
    }
    nx_ = static_cast<std::size_t>(nx);
    ny_ = static_cast<std::size_t>(ny);
    cell_area_cm2_ = params.cell_m * params.cell_m * 1e4;
    litres_.assign(static_cast<std::size_t>(params.nozzle_count), std::vector<double>(nx_ * ny_, 0.0));
    nozzle_l_.assign(static_cast<std::size_t>(params.nozzle_count), 0.0);
}

void DepositionGrid2d::deposit_band(int nozzle, Vec2 centre, double heading_deg, double width_m, double thickness_m,
                                    double volume_l) {
    if (nozzle < 0 || nozzle >= params_.nozzle_count) {
        throw std::invalid_argument("deposition grid: nozzle " + std::to_string(nozzle) + " out of range");
    }
    if (!(width_m > 0.0) || !(thickness_m > 0.0) || !std::isfinite(width_m) || !std::isfinite(thickness_m) ||
        !std::isfinite(centre.east_m) || !std::isfinite(centre.north_m) || !std::isfinite(heading_deg)) {
        throw std::invalid_argument("deposition grid: band needs finite position and heading and sizes > 0");
    }
    if (!(volume_l > 0.0)) return;
    total_l_ += volume_l;
    nozzle_l_[static_cast<std::size_t>(nozzle)] += volume_l;
    // Sample lattice at half-cell spacing (at least one sample per direction).
    const double spacing = 0.5 * params_.cell_m;
    const int across = std::max(1, static_cast<int>(std::ceil(width_m / spacing)));
    const int along = std::max(1, static_cast<int>(std::ceil(thickness_m / spacing)));
    const double per_sample = volume_l / (static_cast<double>(across) * along);
    const Vec2 right = right_of(heading_deg);
    const Vec2 fwd = forward_of(heading_deg);
    std::vector<double>& cells = litres_[static_cast<std::size_t>(nozzle)];
    double off = 0.0;
    for (int j = 0; j < along; ++j) {
        const double v = -0.5 * thickness_m + (j + 0.5) * thickness_m / along;
        const Vec2 row = centre + v * fwd;
        for (int i = 0; i < across; ++i) {
            const double u = -0.5 * width_m + (i + 0.5) * width_m / across;
            const Vec2 p = row + u * right;
            const double fx = std::floor((p.east_m - params_.east_min_m) / params_.cell_m);
            const double fy = std::floor((p.north_m - params_.north_min_m) / params_.cell_m);
            if (fx < 0.0 || fy < 0.0 || fx >= static_cast<double>(nx_) || fy >= static_cast<double>(ny_)) {
                off += per_sample;
                continue;
            }
            cells[static_cast<std::size_t>(fy) * nx_ + static_cast<std::size_t>(fx)] += per_sample;
        }
    }
    off_grid_l_ += off;
}

Vec2 DepositionGrid2d::cell_centre(std::size_t ix, std::size_t iy) const {
    return {params_.east_min_m + (static_cast<double>(ix) + 0.5) * params_.cell_m,
            params_.north_min_m + (static_cast<double>(iy) + 0.5) * params_.cell_m};
}

double DepositionGrid2d::dose_ul_cm2(int nozzle, std::size_t ix, std::size_t iy) const {
    if (nozzle < 0 || nozzle >= params_.nozzle_count || ix >= nx_ || iy >= ny_) {
        throw std::out_of_range("deposition grid: no cell (" + std::to_string(ix) + ", " + std::to_string(iy) +
                                ") of nozzle " + std::to_string(nozzle));
    }
    return litres_[static_cast<std::size_t>(nozzle)][iy * nx_ + ix] * 1e6 / cell_area_cm2_;
}

double DepositionGrid2d::total_dose_ul_cm2(std::size_t ix, std::size_t iy) const {
    double sum = 0.0;
    for (int n = 0; n < params_.nozzle_count; ++n) sum += dose_ul_cm2(n, ix, iy);
    return sum;
}

std::vector<double> DepositionGrid2d::dose_layer_ul_cm2(int nozzle) const {
    if (nozzle < 0 || nozzle >= params_.nozzle_count) {
        throw std::out_of_range("deposition grid: no nozzle " + std::to_string(nozzle));
    }
    std::vector<double> dose = litres_[static_cast<std::size_t>(nozzle)];
    for (double& d : dose) d *= 1e6 / cell_area_cm2_;
    return dose;
}

double DepositionGrid2d::nozzle_volume_l(int nozzle) const {
    if (nozzle < 0 || nozzle >= params_.nozzle_count) {
        throw std::out_of_range("deposition grid: no nozzle " + std::to_string(nozzle));
    }
    return nozzle_l_[static_cast<std::size_t>(nozzle)];
}

}  // namespace rig::field2d
