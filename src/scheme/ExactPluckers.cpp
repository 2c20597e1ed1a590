#include "fretbuzz/scheme/ExactPluckers.hpp"

#include <algorithm>

namespace fretbuzz {

ExactPluckers::ExactPluckers(const Plan& plan, const PlayedParts& parts, const ForceGestures& gestures) : plan_(&plan) {
    if (parts.plucks().empty()) return;
    first_ = parts.fingers().size();
    count_ = parts.plucks().size();
    const std::size_t n = plan.mode_count();
    const PointContact& points = plan.point_contact();
    const auto shape = [&](std::size_t j) { return parts.plucks()[j].shape(); };
    for (const ForceProfile& g : gestures.list())
        for (std::size_t j = 0; j < count_; ++j) gesture_at_pluck_.push_back(kernels::dot(g.shape().data(), shape(j).data(), n));
    // m_i = s . S_i: each pad's coupling to the grid's obstacle and finger pad points
    const bool beside_grid = !plan.obstacle_points().empty() || !plan.fingers().empty();
    if (beside_grid) at_grid_.resize(count_ * n);
    for (std::size_t j = 0; j < count_; ++j) {
        for (std::size_t p = 0; p < points.size(); ++p)
            at_points_.push_back(kernels::dot(shape(j).data(), points.row(p).data(), shape(j).size()));
        if (beside_grid) plan.basis().to_grid(shape(j), std::span<double>(at_grid_).subspan(j * n, n));
        for (std::size_t b = 0; b < count_; ++b) cross_.push_back(kernels::dot(shape(j).data(), shape(b).data(), n));
    }
    load_.assign(count_, 0.0);
    acting_.reserve(count_);
    pads_.reserve(count_);
    pad_cross_.reserve(count_ * count_);
}

bool ExactPluckers::any_on(const PlayedParts& parts) const {
    for (std::size_t j = 0; j < count_; ++j)
        if (on(parts, j)) return true;
    return false;
}

void ExactPluckers::start(PlayedParts& parts, std::size_t j, double u_before, double u_now) const {
    pluck(parts, j).start(std::span<const double>(&u_before, 1), std::span<const double>(&u_now, 1));
}

void ExactPluckers::restart(PlayedParts& parts, const ModalState& modes) const {
    for (std::size_t j = 0; j < count_; ++j) {
        if (!on(parts, j)) continue;
        double u_now = 0.0, u_before = 0.0;
        modes.at_both(pluck(parts, j).shape().data(), u_now, u_before);
        start(parts, j, u_before, u_now);
    }
}

bool ExactPluckers::gather(PlayedParts& parts) {
    acting_.clear();  // (within its reserved room)
    for (std::size_t j = 0; j < count_; ++j) {
        if (!on(parts, j)) continue;
        if (pluck(parts, j).left()) {
            parts.set_on(first_ + j, false);
            continue;
        }
        acting_.push_back(j);
    }
    return !acting_.empty();
}

double ExactPluckers::prediction(const PlayedParts& parts, std::size_t j, const ModalState& modes,
                                 const ForceGestures& gestures, bool loaded) const {
    const double* row = parts.plucks()[j].shape().data();
    double w = 0.0;
    modes.predict_at(&row, 1, &w);
    if (loaded)
        for (std::size_t g = 0; g < gestures.size(); ++g)
            w += plan_->force_to_displacement() * gestures.load_of(g) * gesture_at_pluck_[g * count_ + j];
    return w;
}

void ExactPluckers::take_force(PlayedParts& parts, std::size_t j, double force, StepRecord& record) {
    record.iterations(pluck(parts, j).max_iterations());
    load_[j] = force;
    if (force != 0.0) record.mark_loaded();
}

double ExactPluckers::solve_alone(PlayedParts& parts, const ModalState& modes, const ForceGestures& gestures, long n,
                                  StepRecord& record) {
    const std::size_t j = acting_.front();
    const double w = prediction(parts, j, modes, gestures, record.loaded);
    double force = 0.0;
    const double psi = pluck(parts, j).step(n, std::span<const double>(&w, 1), std::span<double>(&force, 1));
    take_force(parts, j, force, record);
    return psi;
}

std::span<PointContact::Pad> ExactPluckers::pads(PlayedParts& parts, const ModalState& modes,
                                                 const ForceGestures& gestures, long n, bool loaded, bool with_grid) {
    const std::size_t count = acting_.size();
    const std::size_t points = plan_->point_contact().size(), modes_count = modes.size();
    pads_.clear();  // (within their reserved room)
    pad_cross_.clear();
    for (std::size_t a : acting_)
        for (std::size_t b : acting_) pad_cross_.push_back(cross_[a * count_ + b]);
    for (std::size_t a = 0; a < count; ++a) {
        const std::size_t j = acting_[a];
        Pluck& p = pluck(parts, j);
        p.prepare(n);
        const double w = prediction(parts, j, modes, gestures, loaded);
        const std::span<const double> grid =
            with_grid ? std::span<const double>(at_grid_).subspan(j * modes_count, modes_count) : std::span<const double>();
        pads_.push_back({&p, w, p.shape_square(), std::span<const double>(pad_cross_).subspan(a * count, count),
                         std::span<const double>(at_points_).subspan(j * points, points), p.solve_alone(w), grid});
    }
    return pads_;
}

void ExactPluckers::conclude(PlayedParts& parts, long n, StepRecord& record) {
    for (std::size_t a = 0; a < pads_.size(); ++a) {
        const std::size_t j = acting_[a];
        take_force(parts, j, pluck(parts, j).conclude(n, pads_[a].x), record);
    }
}

void ExactPluckers::add_impulse(PlayedParts& parts, double k, std::span<double> impulse) const {
    for (std::size_t j = 0; j < count_; ++j)
        if (load_[j] != 0.0) kernels::axpy(k * load_[j], pluck(parts, j).shape().data(), impulse.data(), impulse.size());
}

}  // namespace fretbuzz
