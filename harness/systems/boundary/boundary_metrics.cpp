#include "harness/systems/boundary/boundary_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "rig/text/number_text.h"

namespace rig::harness {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The wet-edge probes lie on a lattice a quarter cell apart through this
// distance outside the edge. The judge once searched only +-2 m from the edge,
// from +2 m inward; anchoring the lattice there keeps every excess it measured
// inside that window the same to the last bit.
constexpr double kProbeLatticeOutsideM = 2.0;

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
    if (!(probe.spacing_m > 0.0) || !(probe.from_m >= 0.0) || !(probe.wet_threshold_ul_cm2 > 0.0) ||
        !std::isfinite(probe.to_m)) {
        throw std::invalid_argument(
            "wet_edge_profile: probe needs spacing_m > 0, from_m >= 0, a wet threshold > 0 and a finite to_m");
    }
    const double to_m = probe.to_m < 0.0 ? length : probe.to_m;
    // Along the edge u; the outside (right of u) n.
    const double ue = de / length;
    const double un = dn / length;
    const double ne = un;
    const double nn = -ue;
    const double step = raster.cell_m / 4.0;
    const double east_end = raster.east0_m + raster.cell_m * static_cast<double>(raster.nx);
    const double north_end = raster.north0_m + raster.cell_m * static_cast<double>(raster.ny);
    // The cell under a point, or none off the ground.
    const auto cell = [&](double e, double n) -> std::optional<std::size_t> {
        const double fx = std::floor((e - raster.east0_m) / raster.cell_m);
        const double fy = std::floor((n - raster.north0_m) / raster.cell_m);
        if (!(fx >= 0.0 && fy >= 0.0 && fx < static_cast<double>(raster.nx) && fy < static_cast<double>(raster.ny))) {
            return std::nullopt;
        }
        return static_cast<std::size_t>(fy) * raster.nx + static_cast<std::size_t>(fx);
    };
    EdgeProfile profile;
    if (to_m < probe.from_m) return profile;
    const auto stations = static_cast<std::size_t>(std::floor((to_m - probe.from_m) / probe.spacing_m + 1e-9)) + 1;
    for (std::size_t k = 0; k < stations; ++k) {
        const double s = probe.from_m + static_cast<double>(k) * probe.spacing_m;
        const double pe = edge.from_east_m + s * ue;
        const double pn = edge.from_north_m + s * un;
        // Where the probe's line crosses the ground: d in [d_in, d_out] (slabs
        // of a rectangle; the cell test below has the last word at its borders).
        double d_in = -INFINITY;
        double d_out = INFINITY;
        const auto slab = [&](double p, double dir, double lo, double hi) {
            if (dir == 0.0) {
                if (p < lo || p > hi) d_in = INFINITY;
                return;
            }
            const double a = (lo - p) / dir;
            const double b = (hi - p) / dir;
            d_in = std::max(d_in, std::min(a, b));
            d_out = std::min(d_out, std::max(a, b));
        };
        slab(pe, ne, raster.east0_m, east_end);
        slab(pn, nn, raster.north0_m, north_end);
        double excess = kNaN;
        double at_least = kNaN;
        StationFinding finding = StationFinding::off_ground;
        if (d_in <= d_out) {
            // Probes at d = kProbeLatticeOutsideM - j step, from the ground's
            // outer end inward: the first wet one is the outermost. The wet edge
            // lies between it and the dry probe before it: take the middle
            // (within step / 2 = an eighth of a cell of the edge along the probe).
            // Wet at the first probe on the ground: the edge lies past the ground's end.
            const auto j_first = static_cast<long>(std::floor((kProbeLatticeOutsideM - d_out) / step)) - 1;
            const auto j_last = static_cast<long>(std::ceil((kProbeLatticeOutsideM - d_in) / step)) + 1;
            for (long j = j_first; j <= j_last; ++j) {
                const double d = kProbeLatticeOutsideM - static_cast<double>(j) * step;
                const std::optional<std::size_t> at = cell(pe + d * ne, pn + d * nn);
                if (!at) {
                    if (finding == StationFinding::off_ground) continue;  // not on the ground yet
                    break;                                                // past its inner end
                }
                const bool first_on_ground = finding == StationFinding::off_ground;
                finding = StationFinding::dry;
                if (raster.dose_ul_cm2[*at] < probe.wet_threshold_ul_cm2) continue;
                if (first_on_ground) {
                    finding = StationFinding::wet_to_ground_end;
                    at_least = d;
                } else {
                    finding = StationFinding::wet_edge;
                    excess = d + 0.5 * step;
                }
                break;
            }
        }
        profile.station_m.push_back(s);
        profile.excess_m.push_back(excess);
        profile.finding.push_back(finding);
        profile.at_least_m.push_back(at_least);
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

namespace {

// Why a summary over a profile's stations is not the edge's value: stations
// wet to the judged ground's end, or off it. Empty when every station is a
// wet edge or dry.
std::string unknown_stations_reason(const EdgeProfile& profile) {
    std::size_t beyond = 0;
    std::size_t off = 0;
    double least = INFINITY;
    for (std::size_t i = 0; i < profile.finding.size(); ++i) {
        if (profile.finding[i] == StationFinding::wet_to_ground_end) {
            ++beyond;
            least = std::min(least, profile.at_least_m[i]);
        } else if (profile.finding[i] == StationFinding::off_ground) {
            ++off;
        }
    }
    const std::string of = " of " + std::to_string(profile.finding.size()) + " stations";
    std::string reason;
    if (beyond > 0) {
        reason = "wet to the end of the judged ground (judge.ground) at " + std::to_string(beyond) + of +
                 ": the wet edge lies beyond it, at least " + fixed_text(least, 3) +
                 " m past the boundary (+ outside); a larger ground would measure it";
    }
    if (off > 0) {
        reason += (reason.empty() ? "" : "; ") + std::to_string(off) + of +
                  " probe off the judged ground (judge.ground does not reach them)";
    }
    return reason;
}

// The smallest excess known for every station: the measured minimum, when no
// station wet to the ground's end could lie below it and none is off the ground.
std::optional<double> known_min(const EdgeProfile& profile, const Summary& measured) {
    if (measured.n == 0) return std::nullopt;
    for (std::size_t i = 0; i < profile.finding.size(); ++i) {
        if (profile.finding[i] == StationFinding::off_ground) return std::nullopt;
        if (profile.finding[i] == StationFinding::wet_to_ground_end && profile.at_least_m[i] < measured.min) {
            return std::nullopt;
        }
    }
    return measured.min;
}

}  // namespace

std::map<std::string, double> excess_metrics(const std::string& prefix, const EdgeProfile& profile,
                                             std::map<std::string, std::string>& not_measured) {
    std::map<std::string, double> m;
    const Summary s = summarize(profile.excess_m);
    const auto dry = static_cast<std::size_t>(
        std::count(profile.finding.begin(), profile.finding.end(), StationFinding::dry));
    m[prefix + "_stations"] = static_cast<double>(s.n);
    m[prefix + "_stations_dry"] = static_cast<double>(dry);
    if (const std::string unknown = unknown_stations_reason(profile); !unknown.empty()) {
        for (const char* name : {"_mean_m", "_sd_m", "_max_m"}) not_measured[prefix + name] = unknown;
        if (const std::optional<double> min = known_min(profile, s)) {
            m[prefix + "_min_m"] = *min;
        } else {
            not_measured[prefix + "_min_m"] = unknown;
        }
        return m;
    }
    if (s.n == 0) {
        not_measured[prefix + "_mean_m"] = "no wet ground at any station of the edge";
        not_measured[prefix + "_sd_m"] = "no wet ground at any station of the edge";
        return m;
    }
    m[prefix + "_mean_m"] = s.mean;
    m[prefix + "_min_m"] = s.min;
    m[prefix + "_max_m"] = s.max;
    if (s.n > 1) m[prefix + "_sd_m"] = s.sd;
    return m;
}

std::map<std::string, double> per_nozzle_excess_metrics(const std::string& prefix, const std::vector<EdgeProfile>& per_nozzle,
                                                        std::map<std::string, std::string>& not_measured) {
    std::map<std::string, double> m;
    for (std::size_t i = 0; i < per_nozzle.size(); ++i) {
        const std::string p = prefix + "_nozzle" + std::to_string(i);
        const Summary s = summarize(per_nozzle[i].excess_m);
        m[p + "_stations"] = static_cast<double>(s.n);
        if (const std::string unknown = unknown_stations_reason(per_nozzle[i]); !unknown.empty()) {
            for (const char* name : {"_mean_m", "_sd_m", "_max_m"}) not_measured[p + name] = unknown;
            continue;
        }
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

std::map<std::string, double> centre_rule_metrics(const std::vector<CentreRuleSample>& samples, const field2d::Polygon& area,
                                                  std::map<std::string, std::string>& not_measured) {
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
    std::map<std::string, double> m = {{"centre_out_crossings", crossings},
                                       {"centre_out_samples", out_samples},
                                       {"centre_out_spray_ml", spray_l * 1000.0}};
    if (crossings == 0.0) {
        // No spell outside: no time to close in. A 0 would read as a rule obeyed.
        const char* why = "the boom centre never left the target area: the rule was never put to the test";
        not_measured["centre_out_close_s"] = why;
        not_measured["centre_out_close_m"] = why;
    } else {
        m["centre_out_close_s"] = longest_s;
        m["centre_out_close_m"] = longest_m;
    }
    return m;
}

}  // namespace rig::harness
