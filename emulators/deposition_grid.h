#pragma once
// Spray deposited on the ground (plant truth): a grid of cells along the A-B line
// (cell_along_m long) by nozzle columns across the boom, one layer per pass, so
// the first pass up to the breakpoint and the continuation pass each leave their
// own dose and the harness can tell overlap from missed strips (docs/metrics.md).
// A nozzle's flat fan lands as a uniform band
// footprint_along_m long centred under the nozzle; what falls outside the grid is
// counted, not lost silently.
//
// Dose is volume per area in uL/cm^2 (1 uL/cm^2 = 100 L/ha): 20 L/min over a
// 12.2 m boom at 6 km/h is 1.64 uL/cm^2 (164 L/ha, sec. 2.5.2).
#include <cstddef>
#include <vector>

namespace rig::emulators {

struct DepositionGridParams {
    double from_along_m = -50.0;
    double to_along_m = 50.0;
    double cell_along_m = 0.05;
    int nozzle_count = 22;
    double nozzle_spacing_m = 12.2 / 22.0;
    double footprint_along_m = 0.15;
};

class DepositionGrid {
public:
    // Throws std::invalid_argument for an empty range or non-positive sizes.
    explicit DepositionGrid(const DepositionGridParams& params);

    // Adds `volume_l` sprayed by `nozzle` in `pass`, centred at `centre_along_m`.
    void deposit(int pass, int nozzle, double centre_along_m, double volume_l);

    int pass_count() const { return static_cast<int>(layers_.size()); }
    std::size_t row_count() const { return rows_; }
    double row_centre_m(std::size_t row) const;
    double dose_ul_cm2(int pass, std::size_t row, int nozzle) const;
    // Per row: the dose averaged across the boom (all nozzle columns), uL/cm^2.
    std::vector<double> row_mean_dose_ul_cm2(int pass) const;
    // Volume that landed outside [from_along_m, to_along_m], L.
    double volume_off_grid_l() const { return off_grid_l_; }
    double total_volume_l() const { return total_l_; }
    const DepositionGridParams& params() const { return params_; }

private:
    std::vector<double>& layer(int pass);
    DepositionGridParams params_;
    std::size_t rows_;
    double cell_area_cm2_;
    std::vector<std::vector<double>> layers_;  // [pass][row * nozzle_count + nozzle], litres
    double off_grid_l_ = 0.0;
    double total_l_ = 0.0;
};

}  // namespace rig::emulators
