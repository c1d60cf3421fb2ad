#include "emulators/spray_circuit.h"
#include "rig/text/number_text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>
#include <string>

namespace rig::emulators {

namespace {

DepositionGridParams grid_for(DepositionGridParams grid, int nozzle_count, double boom_width_m) {
    grid.nozzle_count = nozzle_count;
    grid.nozzle_spacing_m = boom_width_m / nozzle_count;
    return grid;
}

int total_nozzles(const std::vector<int>& sections) {
    if (sections.empty() || sections.size() > 16) throw std::invalid_argument("spray circuit: 1 to 16 sections");
    for (int nozzles : sections) {
        if (nozzles <= 0) throw std::invalid_argument("spray circuit: every section needs at least one nozzle");
    }
    return std::accumulate(sections.begin(), sections.end(), 0);
}

}  // namespace

SprayCircuit::SprayCircuit(const Plant& plant, SprayCircuitParams params)
    : plant_(plant),
      params_(std::move(params)),
      valve_(params_.valve),
      flow_map_(params_.flow_map),
      deposition_(grid_for(params_.deposition, total_nozzles(params_.section_nozzles), params_.boom_width_m)),
      step_ns_(seconds_to_ns(params_.step_s)) {
    if (!(params_.pump_flow_l_min > 0.0)) throw std::invalid_argument("spray circuit: pump_flow_l_min must be > 0");
    if (!(params_.pipeline_time_constant_s > 0.0)) {
        throw std::invalid_argument("spray circuit: pipeline_time_constant_s must be > 0");
    }
    if (!(params_.pipeline_air_l >= 0.0) || !std::isfinite(params_.pipeline_air_l)) {
        throw std::invalid_argument("spray circuit: pipeline_air_l must be >= 0");
    }
    if (!(params_.nozzle_rated_flow_l_min > 0.0) || !(params_.nozzle_rated_pressure_mpa > 0.0)) {
        throw std::invalid_argument("spray circuit: nozzle_rated_flow_l_min and nozzle_rated_pressure_mpa must be > 0");
    }
    if (!(params_.section_valve_open_s >= 0.0) || !(params_.section_valve_close_s >= 0.0) ||
        !(params_.droplet_fall_s >= 0.0)) {
        throw std::invalid_argument("spray circuit: valve and droplet delays must be >= 0");
    }
    if (step_ns_ <= 0) throw std::invalid_argument("spray circuit: step_s must be > 0");
    if (!(params_.throttle_ramp_s >= 0.0)) throw std::invalid_argument("spray circuit: throttle_ramp_s must be >= 0");
    for (std::size_t i = 0; i < params_.throttle_steps.size(); ++i) {
        const ThrottleStep& step = params_.throttle_steps[i];
        if (!(step.flow_l_min > 0.0) || !std::isfinite(step.flow_l_min) || !std::isfinite(step.at_s)) {
            throw std::invalid_argument("spray circuit: throttle step " + std::to_string(i) +
                                        ": flow_l_min must be > 0 and at_s finite");
        }
        if (i > 0 && !(step.at_s >= params_.throttle_steps[i - 1].at_s + params_.throttle_ramp_s)) {
            throw std::invalid_argument("spray circuit: throttle step " + std::to_string(i) +
                                        ": at_s must come at least throttle_ramp_s after the step before");
        }
    }
    nozzle_count_ = total_nozzles(params_.section_nozzles);
    for (int section = 0; section < section_count(); ++section) {
        nozzle_section_.insert(nozzle_section_.end(), params_.section_nozzles[static_cast<std::size_t>(section)],
                               section);
    }
    nozzles_by_feed_.resize(static_cast<std::size_t>(nozzle_count_));
    std::iota(nozzles_by_feed_.begin(), nozzles_by_feed_.end(), 0);
    const double centre = 0.5 * (nozzle_count_ - 1);
    std::stable_sort(nozzles_by_feed_.begin(), nozzles_by_feed_.end(),
                     [centre](int a, int b) { return std::abs(a - centre) < std::abs(b - centre); });
    section_pending_.assign(static_cast<std::size_t>(section_count()), {});
    pump_flow_l_min_ = params_.pump_flow_l_min;
}

double SprayCircuit::throttle_flow_l_min(double t_s) const {
    double flow = params_.pump_flow_l_min;
    for (const ThrottleStep& step : params_.throttle_steps) {
        if (t_s < step.at_s) break;
        const double into_s = t_s - step.at_s;
        if (into_s >= params_.throttle_ramp_s) {
            flow = step.flow_l_min;
        } else {
            flow += (step.flow_l_min - flow) * into_s / params_.throttle_ramp_s;
        }
    }
    return flow;
}

void SprayCircuit::advance_to(TimeNs t) {
    advanced_to_ns_ = std::max(advanced_to_ns_, t);
    const std::int64_t target_steps = t / step_ns_;
    while (steps_done_ < target_steps) step_once();
}

void SprayCircuit::require_advanced_to(TimeNs now_ns, const std::string& device) const {
    if (now_ns == advanced_to_ns_) return;
    const auto seconds = [](TimeNs t) { return fixed_text(ns_to_seconds(t), 6) + " s"; };
    throw std::logic_error(device + " sampled the spray circuit at t=" + seconds(now_ns) +
                           " but the circuit was advanced to t=" + seconds(advanced_to_ns_) +
                           ": the master advances it to each instant before the devices step "
                           "(add_truth_model), a device never does");
}

void SprayCircuit::set_valve_drive(BallValve::Drive drive) { valve_.set_drive(drive); }

void SprayCircuit::set_sections_commanded(std::uint16_t open_mask) {
    const TimeNs now = steps_done_ * step_ns_;
    for (int section = 0; section < section_count(); ++section) {
        const std::uint16_t bit = static_cast<std::uint16_t>(1u << section);
        if ((open_mask & bit) == (sections_commanded_ & bit)) continue;
        const bool open = (open_mask & bit) != 0;
        const TimeNs acts_at = now + seconds_to_ns(open ? params_.section_valve_open_s : params_.section_valve_close_s);
        auto& pending = section_pending_[static_cast<std::size_t>(section)];
        // A command that would act no later than one still on its way overtakes it.
        while (!pending.empty() && pending.back().first >= acts_at) pending.pop_back();
        pending.emplace_back(acts_at, open);
    }
    sections_commanded_ = static_cast<std::uint16_t>(open_mask & ((1u << section_count()) - 1u));
}

void SprayCircuit::set_unloading_open(bool open) { unloading_open_ = open; }

int SprayCircuit::open_nozzle_count() const {
    int open = 0;
    for (int section = 0; section < section_count(); ++section) {
        if (sections_open_ & (1u << section)) open += params_.section_nozzles[static_cast<std::size_t>(section)];
    }
    return open;
}

double SprayCircuit::pipeline_lag_s(double main_flow_l_min, int open_nozzles) const {
    if (params_.pipeline_air_l == 0.0 || open_nozzles <= 0 || !(main_flow_l_min > 0.0)) {
        return params_.pipeline_time_constant_s;
    }
    constexpr double kAtmosphereMpa = 0.101325;
    const double per_nozzle = main_flow_l_min / open_nozzles;
    const double ratio = per_nozzle / params_.nozzle_rated_flow_l_min;
    const double gauge_mpa = params_.nozzle_rated_pressure_mpa * ratio * ratio;
    const double absolute_mpa = gauge_mpa + kAtmosphereMpa;
    const double flow_l_s = main_flow_l_min / 60.0;
    // R C = (2 P_g / Q) (V P_atm / P^2): litres over litres per second, pressures cancel.
    return params_.pipeline_time_constant_s +
           2.0 * params_.pipeline_air_l * kAtmosphereMpa * gauge_mpa / (absolute_mpa * absolute_mpa * flow_l_s);
}

void SprayCircuit::step_once() {
    const TimeNs now = steps_done_ * step_ns_;
    const double dt = params_.step_s;
    const double t_s = ns_to_seconds(now);

    // Section valves act on each command after its delay, in order.
    for (int section = 0; section < section_count(); ++section) {
        const std::uint16_t bit = static_cast<std::uint16_t>(1u << section);
        auto& pending = section_pending_[static_cast<std::size_t>(section)];
        while (!pending.empty() && now >= pending.front().first) {
            sections_open_ = pending.front().second ? static_cast<std::uint16_t>(sections_open_ | bit)
                                                    : static_cast<std::uint16_t>(sections_open_ & ~bit);
            pending.pop_front();
        }
    }

    valve_.step(dt);
    pump_flow_l_min_ = throttle_flow_l_min(t_s) *
                       (1.0 + params_.pump_pulsation_pct / 100.0 * std::sin(2.0 * M_PI * params_.pump_pulsation_hz * t_s));

    const int open_nozzles = open_nozzle_count();
    if (open_nozzles == 0 || unloading_open_) {
        // Nowhere to go (or all of it goes back to the tank): the boom line stops.
        main_flow_l_min_ = 0.0;
    } else {
        const double settled = flow_map_.main_flow_l_min(valve_.opening_pct(), pump_flow_l_min_) * open_nozzles /
                               nozzle_count_;
        const double lag_s = pipeline_lag_s(settled, open_nozzles);
        main_flow_l_min_ += (settled - main_flow_l_min_) * (1.0 - std::exp(-dt / lag_s));
    }
    const double volume_l = main_flow_l_min_ / 60.0 * dt;
    main_volume_l_ += volume_l;

    // Which open nozzles have enough flow to spray: nearest the feed first.
    int spraying = 0;
    if (main_flow_l_min_ > 0.0) {
        spraying = std::min(open_nozzles, static_cast<int>(main_flow_l_min_ / params_.min_nozzle_flow_l_min));
        spraying = std::max(spraying, 1);  // below that it dribbles from the centre nozzle
    }
    nozzles_spraying_ = spraying;
    if (spraying > 0) {
        const TimeNs landing_ns = now + seconds_to_ns(params_.droplet_fall_s);
        const double landing_s = ns_to_seconds(landing_ns);
        const VehicleState at_landing = plant_.vehicle().state_at(landing_s);
        const int pass = plant_.vehicle().pass_index_at(landing_s);
        const double per_nozzle_l = volume_l / spraying;
        int placed = 0;
        for (int nozzle : nozzles_by_feed_) {
            if (placed == spraying) break;
            if (!(sections_open_ & (1u << nozzle_section_[static_cast<std::size_t>(nozzle)]))) continue;
            deposition_.deposit(pass, nozzle, at_landing.nozzle_line_along_m, per_nozzle_l);
            ++placed;
        }
        if (!landing_) landing_edges_.push_back(LandingEdge{landing_ns, true});
        landing_ = true;
    } else if (landing_) {
        landing_edges_.push_back(LandingEdge{now + seconds_to_ns(params_.droplet_fall_s), false});
        landing_ = false;
    }
    ++steps_done_;
}

msg::HydraulicsTruth SprayCircuit::truth() const {
    msg::HydraulicsTruth truth;
    truth.time_ns(steps_done_ * step_ns_);
    truth.pump_flow_l_min(pump_flow_l_min_);
    truth.valve_opening_pct(valve_.opening_pct());
    truth.main_flow_l_min(main_flow_l_min_);
    truth.main_volume_l(main_volume_l_);
    truth.sections_commanded_mask(sections_commanded_);
    truth.sections_spraying_mask(sections_open_);
    truth.unloading_open(unloading_open_);
    truth.nozzles_spraying(static_cast<std::uint16_t>(nozzles_spraying_));
    return truth;
}

}  // namespace rig::emulators
