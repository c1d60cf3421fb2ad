#include "harness/systems/boundary/boundary_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rig::harness {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void check_raster(const DoseRaster& r, const char* who) {
    if (r.nx == 0 || r.ny == 0 || r.dose_ul_cm2.size() != r.nx * r.ny) {
        throw std::invalid_argument(std::string(who) + ": raster holds " + std::to_string(r.dose_ul_cm2.size()) +
                                    " values for " + std::to_string(r.nx) + " x " + std::to_string(r.ny) + " cells");
    }
    if (!(r.cell_m > 0.0) || !std::isfinite(r.cell_m) || !std::isfinite(r.east0_m) || !std::isfinite(r.north0_m)) {
        throw std::invalid_argument(std::string(who) + ": raster needs a finite origin and a cell size > 0");
    }
}

}  // namespace

DoseRaster raster_of(const field2d::DepositionGrid2d& grid, int nozzle) {
    DoseRaster r;
    r.east0_m = grid.origin().east_m;
    r.north0_m = grid.origin().north_m;
    r.cell_m = grid.cell_m();
    r.nx = grid.nx();
    r.ny = grid.ny();
    r.dose_ul_cm2 = grid.dose_layer_ul_cm2(nozzle);
    return r;
}


DoseRaster sum_rasters(const std::vector<DoseRaster>& layers) {
    if (layers.empty()) throw std::invalid_argument("sum_rasters: no layers");
    DoseRaster sum = layers.front();
    check_raster(sum, "sum_rasters");
    for (std::size_t i = 1; i < layers.size(); ++i) {
        const DoseRaster& r = layers[i];
        check_raster(r, "sum_rasters");
        if (r.nx != sum.nx || r.ny != sum.ny || r.cell_m != sum.cell_m || r.east0_m != sum.east0_m ||
            r.north0_m != sum.north0_m) {
            throw std::invalid_argument("sum_rasters: layer " + std::to_string(i) + " has another geometry");
        }
        for (std::size_t k = 0; k < sum.dose_ul_cm2.size(); ++k) sum.dose_ul_cm2[k] += r.dose_ul_cm2[k];
    }
    return sum;
}

EdgeProfile wet_edge_profile(const DoseRaster& raster, const BoundaryEdge& edge, const EdgeProbe& probe) {
    check_raster(raster, "wet_edge_profile");
    const double de = edge.to_east_m - edge.from_east_m;
    const double dn = edge.to_north_m - edge.from_north_m;
    const double length = std::hypot(de, dn);
    if (!std::isfinite(length) || length < 1e-6) {
        throw std::invalid_argument("wet_edge_profile: the edge has no length (from == to) or is not finite");
    }
    if (!(probe.spacing_m > 0.0) || !(probe.from_m >= 0.0) || !(probe.search_inside_m >= 0.0) ||
        !(probe.search_outside_m >= 0.0) || !(probe.wet_threshold_ul_cm2 > 0.0) || !std::isfinite(probe.to_m)) {
        throw std::invalid_argument(
            "wet_edge_profile: probe needs spacing_m > 0, from_m >= 0, search distances >= 0, a wet threshold > 0 and a finite to_m");
    }
    const double to_m = probe.to_m < 0.0 ? length : probe.to_m;
    // Along the edge u; the outside (right of u) n.
    const double ue = de / length;
    const double un = dn / length;
    const double ne = un;
    const double nn = -ue;
    const double step = raster.cell_m / 4.0;
    const auto wet = [&](double e, double n) {
        const double fx = std::floor((e - raster.east0_m) / raster.cell_m);
        const double fy = std::floor((n - raster.north0_m) / raster.cell_m);
        if (fx < 0.0 || fy < 0.0 || fx >= static_cast<double>(raster.nx) || fy >= static_cast<double>(raster.ny)) {
            return false;
        }
        return raster.dose_ul_cm2[static_cast<std::size_t>(fy) * raster.nx + static_cast<std::size_t>(fx)] >=
               probe.wet_threshold_ul_cm2;
    };
    EdgeProfile profile;
    if (to_m < probe.from_m) return profile;
    const auto stations = static_cast<std::size_t>(std::floor((to_m - probe.from_m) / probe.spacing_m + 1e-9)) + 1;
    const auto probes = static_cast<std::size_t>(std::ceil((probe.search_inside_m + probe.search_outside_m) / step));
    for (std::size_t k = 0; k < stations; ++k) {
        const double s = probe.from_m + static_cast<double>(k) * probe.spacing_m;
        const double pe = edge.from_east_m + s * ue;
        const double pn = edge.from_north_m + s * un;
        double excess = kNaN;
        // From the outer end inward: the first wet point is the outermost. The
        // wet edge lies between it and the dry probe before it: take the middle
        // (within step / 2 = an eighth of a cell of the edge along the probe).
        for (std::size_t j = 0; j <= probes; ++j) {
            const double d = std::max(-probe.search_inside_m, probe.search_outside_m - static_cast<double>(j) * step);
            if (wet(pe + d * ne, pn + d * nn)) {
                excess = j == 0 ? d : d + 0.5 * step;
                break;
            }
        }
        profile.station_m.push_back(s);
        profile.excess_m.push_back(excess);
    }
    return profile;
}

Summary summarize(const std::vector<double>& values) {
    Summary s;
    double sum = 0.0;
    s.min = std::numeric_limits<double>::infinity();
    s.max = -std::numeric_limits<double>::infinity();
    for (double v : values) {
        if (!std::isfinite(v)) continue;
        ++s.n;
        sum += v;
        s.min = std::min(s.min, v);
        s.max = std::max(s.max, v);
    }
    if (s.n == 0) {
        s.mean = s.sd = s.min = s.max = kNaN;
        return s;
    }
    s.mean = sum / static_cast<double>(s.n);
    if (s.n < 2) {
        s.sd = kNaN;
        return s;
    }
    double ss = 0.0;
    for (double v : values) {
        if (std::isfinite(v)) ss += (v - s.mean) * (v - s.mean);
    }
    s.sd = std::sqrt(ss / static_cast<double>(s.n - 1));
    return s;
}

std::map<std::string, double> excess_metrics(const std::string& prefix, const EdgeProfile& profile) {
    std::map<std::string, double> m;
    const Summary s = summarize(profile.excess_m);
    m[prefix + "_stations"] = static_cast<double>(s.n);
    m[prefix + "_stations_dry"] = static_cast<double>(profile.excess_m.size() - s.n);
    if (s.n > 0) {
        m[prefix + "_mean_m"] = s.mean;
        m[prefix + "_min_m"] = s.min;
        m[prefix + "_max_m"] = s.max;
    }
    if (s.n > 1) m[prefix + "_sd_m"] = s.sd;
    return m;
}

std::map<std::string, double> per_nozzle_excess_metrics(const std::string& prefix,
                                                        const std::vector<EdgeProfile>& per_nozzle) {
    std::map<std::string, double> m;
    for (std::size_t i = 0; i < per_nozzle.size(); ++i) {
        const std::string p = prefix + "_nozzle" + std::to_string(i);
        const Summary s = summarize(per_nozzle[i].excess_m);
        m[p + "_stations"] = static_cast<double>(s.n);
        if (s.n > 0) {
            m[p + "_mean_m"] = s.mean;
            m[p + "_max_m"] = s.max;
        }
        if (s.n > 1) m[p + "_sd_m"] = s.sd;
    }
    return m;
}

std::vector<FlowCheckRow> flow_against_table(const std::vector<FlowRecord>& records,
                                             const field2d::NozzleFlowTable& table) {
    std::vector<FlowCheckRow> rows;
    for (std::size_t i = 0; i < records.size(); ++i) {
        const FlowRecord& r = records[i];
        const std::string who = "flow record " + std::to_string(i);
        if (r.nozzle < 0 || r.nozzle >= table.nozzle_count()) {
            throw std::invalid_argument(who + ": no nozzle " + std::to_string(r.nozzle) + " in the table");
        }
        if (!std::isfinite(r.duty_pct) || r.duty_pct < 0.0 || r.duty_pct > 100.0) {
            throw std::invalid_argument(who + ": duty must be in [0, 100] %");
        }
        if (!std::isfinite(r.volume_l) || r.volume_l < 0.0) throw std::invalid_argument(who + ": volume must be >= 0 L");
        if (!std::isfinite(r.duration_s) || r.duration_s <= 0.0) {
            throw std::invalid_argument(who + ": duration must be > 0 s");
        }
        FlowCheckRow row;
        row.nozzle = r.nozzle;
        row.duty_pct = r.duty_pct;
        row.delivered_ml_min = r.volume_l * 1000.0 * 60.0 / r.duration_s;
        const bool covered = r.duty_pct >= table.min_duty_pct(r.nozzle) && r.duty_pct <= table.max_duty_pct(r.nozzle);
        row.table_ml_min = covered ? table.flow_ml_min(r.nozzle, r.duty_pct) : kNaN;
        row.error_ml_min = row.delivered_ml_min - row.table_ml_min;
        row.error_pct = row.table_ml_min > 0.0 ? 100.0 * row.error_ml_min / row.table_ml_min : kNaN;
        rows.push_back(row);
    }
    return rows;
}

std::map<std::string, double> flow_table_metrics(const std::vector<FlowCheckRow>& rows) {
    std::size_t n = 0;
    double max_abs = 0.0;
    double sum_abs = 0.0;
    for (const FlowCheckRow& row : rows) {
        if (!std::isfinite(row.error_pct)) continue;
        ++n;
        max_abs = std::max(max_abs, std::abs(row.error_pct));
        sum_abs += std::abs(row.error_pct);
    }
    std::map<std::string, double> m;
    m["flow_table_points"] = static_cast<double>(n);
    if (n > 0) {
        m["flow_table_max_abs_error_pct"] = max_abs;
        m["flow_table_mean_abs_error_pct"] = sum_abs / static_cast<double>(n);
    }
    return m;
}

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
    if (x.size() != y.size() || x.size() < 2) {
        throw std::invalid_argument("fit_line: needs at least 2 (x, y) pairs of equal count");
    }
    const double n = static_cast<double>(x.size());
    double mx = 0.0;
    double my = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        mx += x[i];
        my += y[i];
    }
    mx /= n;
    my /= n;
    double sxx = 0.0;
    double sxy = 0.0;
    double syy = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        sxx += (x[i] - mx) * (x[i] - mx);
        sxy += (x[i] - mx) * (y[i] - my);
        syy += (y[i] - my) * (y[i] - my);
    }
    if (!(sxx > 0.0)) throw std::invalid_argument("fit_line: all x are equal");
    LineFit fit;
    fit.n = x.size();
    fit.slope = sxy / sxx;
    fit.intercept = my - fit.slope * mx;
    fit.r2 = syy > 0.0 ? sxy * sxy / (sxx * syy) : 1.0;
    return fit;
}

std::map<std::string, double> eq13_fit_metrics(const std::vector<FlowCheckRow>& rows, double from_pct, double to_pct) {
    // Mean over nozzles per duty (Table 3's "mean" row).
    std::map<double, std::pair<double, int>> by_duty;
    for (const FlowCheckRow& row : rows) {
        if (row.duty_pct < from_pct || row.duty_pct > to_pct) continue;
        auto& [sum, count] = by_duty[row.duty_pct];
        sum += row.delivered_ml_min;
        ++count;
    }
    std::vector<double> s;
    std::vector<double> q;
    for (const auto& [duty, acc] : by_duty) {
        s.push_back(duty);
        q.push_back(acc.first / acc.second / 1000.0);  // L/min
    }
    std::map<std::string, double> m;
    m["eq13_points"] = static_cast<double>(s.size());
    if (s.size() < 2) return m;
    const LineFit fit = fit_line(s, q);
    m["eq13_slope_l_min_per_pct"] = fit.slope;
    m["eq13_intercept_l_min"] = fit.intercept;
    m["eq13_r2"] = fit.r2;
    return m;
}

std::map<std::string, double> centre_rule_metrics(const std::vector<CentreRuleSample>& samples,
                                                  const field2d::Polygon& area) {
    double crossings = 0.0;
    double out_samples = 0.0;
    double spray_l = 0.0;
    double longest_s = 0.0;
    double longest_m = 0.0;
    bool was_out = false;
    double left_s = 0.0;        // when the running spell outside began
    double travel_m = 0.0;      // the centre's travel since then
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const CentreRuleSample& s = samples[i];
        const auto where = [&] { return "centre rule: sample " + std::to_string(i) + " (t " + std::to_string(s.t_s) + " s)"; };
        if (!std::isfinite(s.t_s) || !std::isfinite(s.centre.east_m) || !std::isfinite(s.centre.north_m) ||
            !std::isfinite(s.volume_l)) {
            throw std::invalid_argument(where() + ": non-finite value");
        }
        if (s.volume_l < 0.0) throw std::invalid_argument(where() + ": negative volume " + std::to_string(s.volume_l));
        if (i > 0 && s.t_s < samples[i - 1].t_s) throw std::invalid_argument(where() + ": time goes back");
        const bool out = !area.contains(s.centre);
        if (!out) {
            was_out = false;
            continue;
        }
        ++out_samples;
        if (!was_out) {
            ++crossings;
            left_s = s.t_s;
            travel_m = 0.0;
        } else {
            travel_m += std::hypot(s.centre.east_m - samples[i - 1].centre.east_m,
                                   s.centre.north_m - samples[i - 1].centre.north_m);
        }
        was_out = true;
        if (s.volume_l > 0.0) {
            spray_l += s.volume_l;
            if (s.t_s - left_s >= longest_s) {
                longest_s = s.t_s - left_s;
                longest_m = travel_m;
            }
        }
    }
    return {{"centre_out_crossings", crossings},
            {"centre_out_samples", out_samples},
            {"centre_out_spray_ml", spray_l * 1000.0},
            {"centre_out_close_s", longest_s},
            {"centre_out_close_m", longest_m}};
}

}  // namespace rig::harness
