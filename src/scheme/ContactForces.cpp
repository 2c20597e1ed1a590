#include "fretbuzz/scheme/ContactForces.hpp"

#include <algorithm>
#include <cmath>

namespace fretbuzz {

ContactForces::ContactForces(const Plan& plan) : plan_(&plan) {
    // Bounded by the grid: reserved once, so that a running string never allocates (real-time use).
    forces_.reserve(plan.mode_count());
    rubbing_.reserve(plan.mode_count());
}

void ContactForces::add_off_grid(const ExactPoints& points, const ExactPluckers& pluckers) {
    const auto report = [this](double x, double force) { report_at(x, force); };
    if (points.pushed()) points.each_force(report);
    pluckers.each_force(*plan_, report);  // (none without pluckers)
}

void ContactForces::report_at(double x, double force) {
    const double dx = plan_->basis().grid_step();
    const double index = std::clamp(std::round(x / dx) - 1.0, 0.0, static_cast<double>(plan_->mode_count() - 1));
    forces_.emplace_back(static_cast<std::size_t>(index), force / dx);
}

std::span<const std::pair<std::size_t, double>> ContactForces::rubbing(const PlayedParts& parts) {
    // Friction along y acts where the string is pressed along z: on the obstacle, and under a
    // finger (which does not move along y) with the finger's push plus the obstacle's. Force
    // gestures and pluckers drag nothing sideways.
    if (parts.pad_points() == 0) return forces_;
    rubbing_.clear();
    for (const auto& [i, f] : forces_)
        if (!parts.on_pad(i)) rubbing_.emplace_back(i, f);
    parts.each_on([&](const PlayedPart& part) {
        for (std::size_t p = 0; p < part.pad().size(); ++p)
            if (const double f = part.rubbing_force(p); f > 0.0) rubbing_.emplace_back(part.pad()[p], f);
    });
    return rubbing_;
}

}  // namespace fretbuzz
