#include "controller/valve_calibration_procedure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <stdexcept>

namespace rig::controller {

ValveCalibrationProcedure::ValveCalibrationProcedure(CalibrationRunConfig config) : config_(std::move(config)) {
    if (config_.openings_pct.empty()) throw std::invalid_argument("valve calibration run: no openings");
}

void ValveCalibrationProcedure::pause() {
    step_ = Step::move;
    commanded_ = false;
    pump_samples_.clear();
    main_samples_.clear();
}

void ValveCalibrationProcedure::start_hold(TimeNs now_ns) {
    step_ = Step::settle;
    step_since_ns_ = now_ns;
    pump_samples_.clear();
    main_samples_.clear();
}

double ValveCalibrationProcedure::update(TimeNs now_ns, bool valve_idle, std::optional<double> pump_l_min,
                                         std::optional<double> main_l_min) {
    const double opening = config_.openings_pct[opening_index_];
    switch (step_) {
        case Step::move:
            // The first period only sends the valve; from the next on, wait for it to get there.
            if (commanded_ && valve_idle) start_hold(now_ns);
            commanded_ = true;
            break;
        case Step::settle:
            if (now_ns - step_since_ns_ >= seconds_to_ns(config_.settle_s)) {
                step_ = Step::measure;
                step_since_ns_ = now_ns;
            }
            break;
        case Step::measure:
            if (pump_l_min && main_l_min) {
                pump_samples_.push_back(*pump_l_min);
                main_samples_.push_back(*main_l_min);
            }
            if (now_ns - step_since_ns_ >= seconds_to_ns(config_.measure_s)) {
                if (pump_samples_.size() >= 2) {
                    const auto [low, high] = std::minmax_element(pump_samples_.begin(), pump_samples_.end());
                    const double n = static_cast<double>(pump_samples_.size());
                    const double pump_mean = std::accumulate(pump_samples_.begin(), pump_samples_.end(), 0.0) / n;
                    const double main_mean = std::accumulate(main_samples_.begin(), main_samples_.end(), 0.0) / n;
                    if (pump_mean > 0.0 && *high - *low <= config_.steady_pump_pct / 100.0 * pump_mean) {
                        points_.push_back(Point{opening, pump_mean, main_mean});
                    }
                }
                opening_index_ = (opening_index_ + 1) % config_.openings_pct.size();
                step_ = Step::move;
                commanded_ = false;
            }
            break;
    }
    return config_.openings_pct[opening_index_];
}

std::vector<ValveCalibrationProcedure::Line> ValveCalibrationProcedure::fit() const {
    std::map<double, std::vector<const Point*>> by_opening;
    for (const Point& point : points_) by_opening[point.opening_pct].push_back(&point);
    std::vector<Line> lines;
    for (const auto& [opening, points] : by_opening) {
        Line line;
        line.line.opening_pct = opening;
        line.points = static_cast<int>(points.size());
        const double n = static_cast<double>(points.size());
        double mean_x = 0.0, mean_y = 0.0;
        line.pump_min_l_min = points.front()->pump_l_min;
        line.pump_max_l_min = points.front()->pump_l_min;
        for (const Point* point : points) {
            mean_x += point->pump_l_min / n;
            mean_y += point->main_l_min / n;
            line.pump_min_l_min = std::min(line.pump_min_l_min, point->pump_l_min);
            line.pump_max_l_min = std::max(line.pump_max_l_min, point->pump_l_min);
        }
        if (line.points < config_.min_points || line.pump_max_l_min - line.pump_min_l_min < config_.min_span_l_min) {
            continue;
        }
        double sxx = 0.0, sxy = 0.0, syy = 0.0;
        for (const Point* point : points) {
            sxx += (point->pump_l_min - mean_x) * (point->pump_l_min - mean_x);
            sxy += (point->pump_l_min - mean_x) * (point->main_l_min - mean_y);
            syy += (point->main_l_min - mean_y) * (point->main_l_min - mean_y);
        }
        // Every point at one pump flow (min_span_l_min 0): no slope to fit.
        if (!(line.pump_max_l_min > line.pump_min_l_min) || !(sxx > 0.0)) continue;
        line.line.slope = sxy / sxx;
        line.line.intercept_l_min = mean_y - line.line.slope * mean_x;
        double residual = 0.0;
        for (const Point* point : points) {
            const double error = point->main_l_min - (line.line.slope * point->pump_l_min + line.line.intercept_l_min);
            residual += error * error;
        }
        line.r2 = syy > 0.0 ? 1.0 - residual / syy : 1.0;
        lines.push_back(line);
    }
    return lines;
}

std::string ValveCalibrationProcedure::yaml() const {
    std::string text =
        "# The valve calibration this controller measured on the rig (seed 000 sec. 2.4.2,\n"
        "# Fig. 11): main = slope x pump + intercept_l_min per opening, by least squares.\n"
        "calibration:\n";
    char line[200];
    for (const Line& fitted : fit()) {
        std::snprintf(line, sizeof line,
                      "  - { opening_pct: %.1f, slope: %.4f, intercept_l_min: %.3f }   # R^2 %.4f, %d points, "
                      "pump %.1f-%.1f L/min\n",
                      fitted.line.opening_pct, fitted.line.slope, fitted.line.intercept_l_min, fitted.r2,
                      fitted.points, fitted.pump_min_l_min, fitted.pump_max_l_min);
        text += line;
    }
    std::snprintf(line, sizeof line, "points: %zu\n", points_.size());
    text += line;
    return text;
}

}  // namespace rig::controller
