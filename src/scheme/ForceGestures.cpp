#include "fretbuzz/scheme/ForceGestures.hpp"

#include <algorithm>

#include "fretbuzz/scheme/SecondPolarisation.hpp"

namespace fretbuzz {

ForceGestures::ForceGestures(const Plan& plan, std::span<const std::vector<double>> driven) : plan_(&plan) {
    for (const ForceSpec& spec : plan.forces())
        gestures_.emplace_back(spec, plan.basis(), plan.dt(), -spec.direction * polarisation_share(spec.angle_deg, false));
    for (const std::vector<double>& shape : driven) gestures_.emplace_back(shape, plan.basis());
    load_.assign(gestures_.size(), 0.0);
    rows_.assign(gestures_.size(), nullptr);
    row_.assign(plan.mode_count(), 0.0);
    coefficients_.assign(gestures_.size(), 0.0);
    const PointContact& points = plan.point_contact();
    for (const ForceProfile& g : gestures_)
        for (std::size_t p = 0; p < points.size(); ++p)
            at_points_.push_back(kernels::dot(g.shape().data(), points.row(p).data(), g.shape().size()));
}

void ForceGestures::reshape_driven(std::size_t g, std::span<const double> shape) {
    gestures_[g].reshape(shape, plan_->basis(), row_);
    const PointContact& points = plan_->point_contact();
    for (std::size_t p = 0; p < points.size(); ++p)
        at_points_[g * points.size() + p] = kernels::dot(shape.data(), points.row(p).data(), shape.size());
}

bool ForceGestures::act_from(long n) const {
    return std::any_of(gestures_.begin(), gestures_.end(), [n](const ForceProfile& g) { return g.acts_from(n); });
}

bool ForceGestures::load(long n) {
    bool loaded = false;
    for (std::size_t g = 0; g < gestures_.size(); ++g) {
        load_[g] = gestures_[g].at_step(n);
        loaded = loaded || load_[g] != 0.0;
    }
    return loaded;
}

double ForceGestures::at_grid(std::size_t i) const {
    double u = 0.0;
    for (std::size_t g = 0; g < gestures_.size(); ++g) u += load_[g] * gestures_[g].on_grid(i);
    return plan_->force_to_displacement() * u;
}

double ForceGestures::at_point(std::size_t p) const {
    const std::size_t points = plan_->point_contact().size();
    double u = 0.0;
    for (std::size_t g = 0; g < gestures_.size(); ++g) u += load_[g] * at_points_[g * points + p];
    return plan_->force_to_displacement() * u;
}

void ForceGestures::add_impulse(double k, std::span<double> impulse) const {
    for (std::size_t g = 0; g < gestures_.size(); ++g)
        if (load_[g] != 0.0) kernels::axpy(k * load_[g], gestures_[g].shape().data(), impulse.data(), impulse.size());
}

void ForceGestures::push_rows(double k, kernels::StepPass& pass) {
    std::size_t count = 0;
    for (std::size_t g = 0; g < gestures_.size(); ++g) {
        if (load_[g] == 0.0) continue;
        rows_[count] = gestures_[g].shape().data();
        coefficients_[count++] = k * load_[g];
    }
    pass.push_rows = rows_.data();
    pass.push_coefficients = coefficients_.data();
    pass.pushes = count;
}

// A driven load's work is not counted: inside an assembly what a bridge does on its string is
// the link's energy exchange, which the assembly's balance holds without it (two passes over
// the modes per load and step saved, on every step of a string on a bridge).
void ForceGestures::begin_step(const ModalState& modes) {
    for (std::size_t g = 0; g < gestures_.size(); ++g)
        if (load_[g] != 0.0 && !gestures_[g].driven()) gestures_[g].begin_step(modes.q(), modes.d());
}

void ForceGestures::end_step(const ModalState& modes) {
    for (std::size_t g = 0; g < gestures_.size(); ++g)
        if (load_[g] != 0.0 && !gestures_[g].driven()) gestures_[g].end_step(modes.q(), load_[g]);
}

double ForceGestures::add_work(double sum) const {
    for (const ForceProfile& g : gestures_) sum += g.work();
    return sum;
}

}  // namespace fretbuzz
