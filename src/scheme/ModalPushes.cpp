#include "fretbuzz/scheme/ModalPushes.hpp"

#include <algorithm>

namespace fretbuzz {

ModalPushes::ModalPushes(const Plan& plan) : plan_(&plan), impulse_(plan.mode_count(), 0.0) {
    screened_.reserve(plan.mode_count() + plan.point_contact().size());  // (a running string never allocates)
}

void ModalPushes::form(Forces forces, std::span<double> grid, const ExactPoints& points) {
    if (forces.empty())
        std::fill(impulse_.begin(), impulse_.end(), 0.0);
    else
        plan_->forces_to_modes(forces, grid, impulse_);
    if (points.pushed()) points.add_impulse(plan_->force_to_displacement(), impulse_);
}

void ModalPushes::fill(kernels::StepPass& pass, StepRoute::Push push, Forces forces, std::span<double> grid,
                       const ExactPoints& points, const ForceGestures& gestures, const ExactPluckers& pluckers,
                       PlayedParts& parts) {
    std::size_t pushes = 0;
    switch (push) {
        case StepRoute::Push::none: break;
        case StepRoute::Push::vector:
            form(forces, grid, points);
            pass.impulse = impulse_.data();
            break;
        case StepRoute::Push::loaded_vector: {
            form(forces, grid, points);
            const double k = plan_->force_to_displacement();
            gestures.add_impulse(k, impulse_);
            pluckers.add_impulse(parts, k, impulse_);
            pass.impulse = impulse_.data();
            break;
        }
        case StepRoute::Push::point_rows: {
            const PointContact& contact = plan_->point_contact();
            const PointContact::State& state = points.state();
            for (std::size_t p = 0; p < contact.size(); ++p)
                if (state.force[p] != 0.0) {
                    coefficients_[pushes] = plan_->force_to_displacement() * contact.weight(p) * state.force[p];
                    rows_[pushes++] = contact.row(p).data();
                }
        }
            [[fallthrough]];
        case StepRoute::Push::rows:
            for (const auto& [i, f] : forces) {
                coefficients_[pushes] = plan_->impulse_scale() * f;
                rows_[pushes++] = plan_->basis().row(i).data();
            }
            pass.push_rows = rows_.data();
            pass.push_coefficients = coefficients_.data();
            pass.pushes = pushes;
            break;
    }
}

void ModalPushes::tell(ContactScheduler& scheduler, StepRoute::Push push, const ModalState& modes, Forces forces,
                       const ExactPoints& points) {
    switch (push) {
        case StepRoute::Push::none: break;
        case StepRoute::Push::vector:
        case StepRoute::Push::loaded_vector: scheduler.pushed(modes.q(), modes.d(), impulse_); break;
        case StepRoute::Push::rows: scheduler.pushed(modes.q(), modes.d(), forces, plan_->impulse_scale()); break;
        case StepRoute::Push::point_rows: {
            // Each push times its point's weight (exact point p screened as N + p, its force
            // as one per dx).
            screened_.assign(forces.begin(), forces.end());
            const PointContact& contact = plan_->point_contact();
            const PointContact::State& state = points.state();
            const double dx = plan_->basis().grid_step();
            for (std::size_t p = 0; p < contact.size(); ++p)
                if (state.force[p] != 0.0) screened_.emplace_back(modes.size() + p, contact.weight(p) * state.force[p] / dx);
            scheduler.pushed(modes.q(), modes.d(), screened_, plan_->impulse_scale());
            break;
        }
    }
}

}  // namespace fretbuzz
