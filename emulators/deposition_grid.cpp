#include "emulators/deposition_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rig::emulators {

DepositionGrid::DepositionGrid(const DepositionGridParams& params) : params_(params) {
    if (!(params.to_along_m > params.from_along_m) || !(params.cell_along_m > 0.0) || params.nozzle_count <= 0 ||
        !(params.nozzle_spacing_m > 0.0) || !(params.footprint_along_m > 0.0)) {
        throw std::invalid_argument("deposition grid: empty range or non-positive cell, nozzle or footprint size");
    }
    rows_ = static_cast<std::size_t>(std::ceil((params.to_along_m - params.from_along_m) / params.cell_along_m));
    cell_area_cm2_ = params.cell_along_m * params.nozzle_spacing_m * 1e4;
}

std::vector<double>& DepositionGrid::layer(int pass) {
    if (pass < 0) throw std::invalid_argument("deposition grid: negative pass");
    while (static_cast<int>(layers_.size()) <= pass) {
        layers_.emplace_back(rows_ * static_cast<std::size_t>(params_.nozzle_count), 0.0);
    }
    return layers_[static_cast<std::size_t>(pass)];
}

void DepositionGrid::deposit(int pass, int nozzle, double centre_along_m, double volume_l) {
    if (volume_l <= 0.0) return;
    if (nozzle < 0 || nozzle >= params_.nozzle_count) throw std::invalid_argument("deposition grid: nozzle out of range");
    total_l_ += volume_l;
    std::vector<double>& cells = layer(pass);
    const double half = 0.5 * params_.footprint_along_m;
    const double from_m = centre_along_m - half;
    const double to_m = centre_along_m + half;
    const double per_m = volume_l / params_.footprint_along_m;
    // Cells overlapped by [from_m, to_m), each getting its share of the band.
    const double first_cell = std::floor((from_m - params_.from_along_m) / params_.cell_along_m);
    const double last_cell = std::floor((to_m - params_.from_along_m) / params_.cell_along_m);
    double landed_l = 0.0;
    for (double cell = std::max(first_cell, 0.0); cell <= last_cell && cell < static_cast<double>(rows_); cell += 1.0) {
        const double cell_from = params_.from_along_m + cell * params_.cell_along_m;
        const double overlap = std::min(to_m, cell_from + params_.cell_along_m) - std::max(from_m, cell_from);
        if (overlap <= 0.0) continue;
        const auto row = static_cast<std::size_t>(cell);
        cells[row * static_cast<std::size_t>(params_.nozzle_count) + static_cast<std::size_t>(nozzle)] += overlap * per_m;
        landed_l += overlap * per_m;
    }
    off_grid_l_ += std::max(0.0, volume_l - landed_l);
}

double DepositionGrid::row_centre_m(std::size_t row) const {
    return params_.from_along_m + (static_cast<double>(row) + 0.5) * params_.cell_along_m;
}

double DepositionGrid::dose_ul_cm2(int pass, std::size_t row, int nozzle) const {
    if (pass < 0 || pass >= pass_count() || row >= rows_ || nozzle < 0 || nozzle >= params_.nozzle_count) return 0.0;
    const double litres =
        layers_[static_cast<std::size_t>(pass)][row * static_cast<std::size_t>(params_.nozzle_count) +
                                                 static_cast<std::size_t>(nozzle)];
    return litres * 1e6 / cell_area_cm2_;
}

std::vector<double> DepositionGrid::row_mean_dose_ul_cm2(int pass) const {
    std::vector<double> profile(rows_, 0.0);
    if (pass < 0 || pass >= pass_count()) return profile;
    for (std::size_t row = 0; row < rows_; ++row) {
        double sum = 0.0;
        for (int nozzle = 0; nozzle < params_.nozzle_count; ++nozzle) sum += dose_ul_cm2(pass, row, nozzle);
        profile[row] = sum / params_.nozzle_count;
    }
    return profile;
}

}  // namespace rig::emulators
