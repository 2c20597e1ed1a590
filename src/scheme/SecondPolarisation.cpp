#include "fretbuzz/scheme/SecondPolarisation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "fretbuzz/numerics/Kernels.hpp"

namespace fretbuzz {

SecondPolarisation::SecondPolarisation(const Plan& plan, std::span<const double> q0, std::span<const double> v0)
    : plan_(plan),
      q_(q0.begin(), q0.end()),
      d_(q0.size(), 0.0),
      v0_(v0.begin(), v0.end()),
      predicted_(q0.size(), 0.0),
      impulse_(q0.size(), 0.0),
      grid_(q0.size(), 0.0),
      before_(q0.size(), 0.0) {
    forces_.reserve(q0.size());
    for (const ForceSpec& spec : plan.forces()) {
        const double share = polarisation_share(spec.angle_deg, true);
        if (share != 0.0) gestures_.emplace_back(spec, plan.basis(), plan.dt(), share);
    }
    gesture_load_.assign(gestures_.size(), 0.0);
    const PointContact& points = plan.point_contact();
    if (!points.empty()) {
        point_friction_ = PointFriction(points);
        point_v0_.assign(points.size(), 0.0);
        point_force_.assign(points.size(), 0.0);
        for (std::vector<double>* v : {&joint_v0_, &joint_normal_, &joint_force_, &joint_velocity_}) v->reserve(q0.size());
        joint_index_.reserve(q0.size());
        for (const ForceProfile& g : gestures_)
            for (std::size_t p = 0; p < points.size(); ++p)
                gesture_at_points_.push_back(kernels::dot(g.shape().data(), points.row(p).data(), q0.size()));
    }
}

bool SecondPolarisation::add_gesture_loads(long n, bool pushed) {
    // Explicit, as along z (see ForceProfile), added to the friction's impulse.
    bool loaded = false;
    const double k = plan_.force_to_displacement();
    for (std::size_t g = 0; g < gestures_.size(); ++g) {
        gesture_load_[g] = gestures_[g].at_step(n);
        if (gesture_load_[g] == 0.0) continue;
        if (!loaded && !pushed) std::fill(impulse_.begin(), impulse_.end(), 0.0);
        loaded = true;
        kernels::axpy(k * gesture_load_[g], gestures_[g].shape().data(), impulse_.data(), impulse_.size());
    }
    return loaded;
}

void SecondPolarisation::first_step() {
    std::vector<double> q1(q_.size());
    plan_.propagator_y().first_step(q_, v0_, q1, d_);
    q_ = std::move(q1);
}

void SecondPolarisation::step(long step, std::span<const std::pair<std::size_t, double>> normal,
                              std::span<const double> point_normal) {
    const ModalPropagator& prop = plan_.propagator_y();
    const Friction& law = plan_.friction();
    const std::size_t n = q_.size();
    forces_.clear();
    // The gestures' loads of this step move y at every point: the friction is solved with them.
    const double k_load = plan_.force_to_displacement();
    const auto load_at = [&](std::size_t i) {
        double u = 0.0;
        for (std::size_t g = 0; g < gestures_.size(); ++g) u += gestures_[g].at_step(step) * gestures_[g].on_grid(i);
        return k_load * u;
    };
    // Exact points rubbing beside grid points: both solved together (PointFriction).
    const bool points_rub = law.coefficient() > 0.0 && !point_normal.empty();
    const bool joint = points_rub && !normal.empty();
    joint_index_.clear();
    joint_v0_.clear();
    joint_normal_.clear();
    if (law.coefficient() > 0.0 && !normal.empty()) {
        const double dt = plan_.dt();
        const double k = plan_.force_to_displacement();
        const double dx = plan_.basis().grid_step();
        kernels::predict(prop.decay().data(), prop.beta().data(), q_.data(), d_.data(), predicted_.data(), n);
        const bool use_transform = normal.size() > plan_.transform_threshold();
        if (use_transform) {
            for (std::size_t j = 0; j < n; ++j) impulse_[j] = q_[j] - d_[j];
            plan_.basis().to_grid(predicted_, grid_);
            plan_.basis().to_grid(impulse_, before_);
        }
        for (const auto& [i, f_n] : normal) {
            double w = 0.0, y_before = 0.0;
            if (use_transform) {
                w = grid_[i];
                y_before = before_[i];
            } else {
                const double* row = plan_.basis().row(i).data();
                double y_now = 0.0;
                w = kernels::dot(row, predicted_.data(), n);
                kernels::dot_current_previous(row, q_.data(), d_.data(), n, y_now, y_before);
            }
            if (!gestures_.empty()) w += load_at(i);
            if (joint) {
                joint_index_.push_back(i);
                joint_v0_.push_back((w - y_before) / (2.0 * dt));
                joint_normal_.push_back(f_n);
                continue;
            }
            const FrictionSolution s = law.solve((w - y_before) / (2.0 * dt), f_n, k, dt);
            max_iterations_ = std::max(max_iterations_, s.iterations);
            // -dx f (y^{n+1} - y^{n-1}) / 2 with y^{n+1} - y^{n-1} = 2 dt v: >= 0 exactly.
            friction_ -= dx * s.force * s.velocity * dt;
            if (s.force != 0.0) forces_.emplace_back(i, s.force);
        }
    }
    if (points_rub) solve_points(step, point_normal, joint);  // (the grid's forces into forces_ if joint)
    spread_forces();
    bool pushed = !forces_.empty();
    if (points_rub) pushed = add_point_impulse(pushed);
    const bool loaded = !gestures_.empty() && add_gesture_loads(step, pushed);
    for (std::size_t g = 0; g < gestures_.size() && loaded; ++g)
        if (gesture_load_[g] != 0.0) gestures_[g].begin_step(q_, d_);
    const double losses =
        kernels::advance(prop.decay().data(), prop.beta().data(), prop.lossless() ? nullptr : prop.loss().data(),
                         !pushed && !loaded ? nullptr : impulse_.data(), q_.data(), d_.data(), n);
    damping_ += plan_.modal_loss_scale() * losses;
    for (std::size_t g = 0; g < gestures_.size() && loaded; ++g)
        if (gesture_load_[g] != 0.0) gestures_[g].end_step(q_, gesture_load_[g]);
    if (pushed && !point_normal.empty()) report_point_forces();
}

void SecondPolarisation::solve_points(long step, std::span<const double> point_normal, bool joint) {
    const PointContact& points = plan_.point_contact();
    const std::size_t n = q_.size();
    const double dt = plan_.dt();
    const double k = plan_.force_to_displacement();
    const ModalPropagator& prop = plan_.propagator_y();
    if (!joint) kernels::predict(prop.decay().data(), prop.beta().data(), q_.data(), d_.data(), predicted_.data(), n);
    for (std::size_t p = 0; p < points.size(); ++p) {
        point_v0_[p] = 0.0;
        if (point_normal[p] == 0.0) continue;
        const double* row = points.row(p).data();
        double y_now = 0.0, y_before = 0.0;
        double w = kernels::dot(row, predicted_.data(), n);
        kernels::dot_current_previous(row, q_.data(), d_.data(), n, y_now, y_before);
        for (std::size_t g = 0; g < gestures_.size(); ++g)
            w += k * gestures_[g].at_step(step) * gesture_at_points_[g * points.size() + p];
        point_v0_[p] = (w - y_before) / (2.0 * dt);
    }
    if (joint) {
        joint_force_.resize(joint_index_.size());
        joint_velocity_.resize(joint_index_.size());
        PointFriction::Grid grid{joint_index_, joint_v0_, joint_normal_, joint_force_, joint_velocity_,
                                 plan_.basis().grid_step()};
        friction_ -= point_friction_.solve(plan_.friction(), point_v0_, point_normal, k, dt, point_force_, grid);
        for (std::size_t r = 0; r < joint_index_.size(); ++r)
            if (joint_force_[r] != 0.0) forces_.emplace_back(joint_index_[r], joint_force_[r]);
    } else {
        friction_ -= point_friction_.solve(plan_.friction(), point_v0_, point_normal, k, dt, point_force_);
    }
    max_iterations_ = std::max(max_iterations_, point_friction_.iterations());
}

bool SecondPolarisation::add_point_impulse(bool pushed) {
    const PointContact& points = plan_.point_contact();
    const double k = plan_.force_to_displacement();
    bool rubbed = false;
    for (std::size_t p = 0; p < points.size(); ++p) {
        if (point_force_[p] == 0.0) continue;
        if (!rubbed && !pushed) std::fill(impulse_.begin(), impulse_.end(), 0.0);
        rubbed = true;
        kernels::axpy(k * points.weight(p) * point_force_[p], points.row(p).data(), impulse_.data(), impulse_.size());
    }
    return rubbed || pushed;
}

void SecondPolarisation::report_point_forces() {
    // As a force per length at the grid point nearest x_p, the same total force (as along z).
    const PointContact& points = plan_.point_contact();
    const double dx = plan_.basis().grid_step();
    for (std::size_t p = 0; p < points.size(); ++p) {
        if (point_force_[p] == 0.0) continue;
        const double index = std::clamp(std::round(points.point(p).x_m / dx) - 1.0, 0.0, static_cast<double>(q_.size() - 1));
        forces_.emplace_back(static_cast<std::size_t>(index), point_force_[p] * points.weight(p) / dx);
    }
}

void SecondPolarisation::spread_forces() {
    if (!forces_.empty()) plan_.forces_to_modes(forces_, grid_, impulse_);
}

void SecondPolarisation::fly(long flown, long planned, std::size_t head, std::span<const std::vector<double>> probes) {
    const ModalPropagator& prop = plan_.propagator_y();
    const double before = energy();
    const std::size_t width = probes.size();
    if (width == 0) head = 0;  // nobody reads per-step values: every mode may jump
    rows_.resize(static_cast<std::size_t>(flown) * width);
    for (long m = 0; m < flown && head > 0; ++m) {
        kernels::advance(prop.decay().data(), prop.beta().data(), nullptr, nullptr, q_.data(), d_.data(), head);
        for (std::size_t p = 0; p < width; ++p)
            rows_[static_cast<std::size_t>(m) * width + p] = kernels::dot(probes[p].data(), q_.data(), head);
    }
    if (flown == planned) {
        if (!flight_ || flight_->steps() != planned) flight_.emplace(prop, planned);
        flight_->jump(q_, d_, head);
    } else {
        for (long m = 0; m < flown; ++m)
            kernels::advance(prop.decay().data() + head, prop.beta().data() + head, nullptr, nullptr, q_.data() + head,
                             d_.data() + head, q_.size() - head);
    }
    damping_ += before - energy();
}

void SecondPolarisation::silence() {
    std::fill(q_.begin(), q_.end(), 0.0);
    std::fill(d_.begin(), d_.end(), 0.0);
    std::fill(v0_.begin(), v0_.end(), 0.0);
}

double SecondPolarisation::displacement(std::span<const double> mode_shapes) const {
    return kernels::dot(mode_shapes.data(), q_.data(), q_.size());
}

double SecondPolarisation::velocity(std::span<const double> mode_shapes) const {
    return kernels::dot(mode_shapes.data(), d_.data(), d_.size()) / plan_.dt();
}

double SecondPolarisation::energy() const {
    return plan_.modal_energy_scale() * plan_.propagator_y().scaled_modal_energy(q_, d_);
}

double polarisation_share(double angle_deg, bool y) {
    const double angle = angle_deg * std::numbers::pi / 180.0;
    const double share = y ? std::sin(angle) : std::cos(angle);
    // Along an axis exactly (0, 90, 180, ... degrees): the other component is exactly zero.
    return std::fmod(angle_deg, 90.0) == 0.0 ? std::round(share) : share;
}

std::vector<double> along_polarisation(const std::vector<double>& v, double angle_deg, bool y) {
    const double share = polarisation_share(angle_deg, y);
    std::vector<double> out(v);
    for (double& x : out) x *= share;
    return out;
}

std::vector<double> along_polarisation(const std::vector<double>& v, const Case& c, bool y) {
    if (c.two_polarisations()) return along_polarisation(v, c.polarisation.angle_deg, y);
    return y ? std::vector<double>(v.size(), 0.0) : v;
}

}  // namespace fretbuzz
