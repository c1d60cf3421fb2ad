#include "emulators/field2d/boom_lift.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rig::field2d {

void validate(const ParallelogramLift& lift, const std::string& where) {
    const auto positive = [&](const char* name, double value) {
        if (!std::isfinite(value) || value <= 0.0) {
            throw std::invalid_argument(where + "." + name + ": must be finite and > 0, got " + std::to_string(value));
        }
    };
    positive("rod_length_m", lift.rod_length_m);
    positive("hinge_height_m", lift.hinge_height_m);
    if (!std::isfinite(lift.antenna_to_o_m)) throw std::invalid_argument(where + ".antenna_to_o_m: must be finite");
    if (!std::isfinite(lift.hinge_to_boom_centre_m)) {
        throw std::invalid_argument(where + ".hinge_to_boom_centre_m: must be finite");
    }
}

double eq18_boom_offset_m(const ParallelogramLift& lift, double boom_height_m) {
    const double drop_m = lift.hinge_height_m - boom_height_m;
    if (!std::isfinite(boom_height_m) || std::abs(drop_m) > lift.rod_length_m) {
        throw std::invalid_argument("Eq. 18: boom height " + std::to_string(boom_height_m) +
                                    " m is out of the lift's reach [" + std::to_string(lift.min_height_m()) + ", " +
                                    std::to_string(lift.max_height_m()) + "] m");
    }
    return std::sqrt(lift.rod_length_m * lift.rod_length_m - drop_m * drop_m) -
           (lift.antenna_to_o_m - lift.hinge_to_boom_centre_m);
}

BoomHeightProfile::BoomHeightProfile(std::vector<HeightKnot> knots) : knots_(std::move(knots)) {
    if (knots_.empty()) throw std::invalid_argument("boom height profile: needs at least one knot");
    for (std::size_t i = 0; i < knots_.size(); ++i) {
        const HeightKnot& k = knots_[i];
        if (!std::isfinite(k.t_s) || !std::isfinite(k.height_m) || k.height_m <= 0.0) {
            throw std::invalid_argument("boom height profile: knot " + std::to_string(i) +
                                        " needs a finite time and a finite height > 0");
        }
        if (i > 0 && !(k.t_s > knots_[i - 1].t_s)) {
            throw std::invalid_argument("boom height profile: knot " + std::to_string(i) +
                                        " is not after the one before it (times must increase)");
        }
    }
}

double BoomHeightProfile::height_at(double t_s) const {
    if (t_s <= knots_.front().t_s) return knots_.front().height_m;
    if (t_s >= knots_.back().t_s) return knots_.back().height_m;
    const auto next = std::upper_bound(knots_.begin(), knots_.end(), t_s,
                                       [](double t, const HeightKnot& k) { return t < k.t_s; });
    const auto prev = next - 1;
    const double f = (t_s - prev->t_s) / (next->t_s - prev->t_s);
    return prev->height_m + f * (next->height_m - prev->height_m);
}

double BoomHeightProfile::min_height_m() const {
    return std::min_element(knots_.begin(), knots_.end(),
                            [](const HeightKnot& a, const HeightKnot& b) { return a.height_m < b.height_m; })
        ->height_m;
}

double BoomHeightProfile::max_height_m() const {
    return std::max_element(knots_.begin(), knots_.end(),
                            [](const HeightKnot& a, const HeightKnot& b) { return a.height_m < b.height_m; })
        ->height_m;
}

}  // namespace rig::field2d
