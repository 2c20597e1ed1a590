#include "fretbuzz/scheme/Stepper.hpp"

#include <algorithm>
#include <limits>
#include <numeric>

namespace fretbuzz {

namespace {
double dot(std::span<const double> a, std::span<const double> b) {
    return std::inner_product(a.begin(), a.end(), b.begin(), 0.0);
}
}  // namespace

Stepper::Stepper(const Plan& plan, std::span<const double> q0, std::span<const double> v0)
    : plan_(plan),
      screen_(plan),
      q_(q0.begin(), q0.end()),
      d_(q0.size(), 0.0),
      v0_(v0.begin(), v0.end()),
      predicted_(q0.size(), 0.0),
      impulse_(q0.size(), 0.0),
      grid_(q0.size(), 0.0),
      eta_prev_(q0.size(), 0.0),
      eta_curr_(q0.size(), 0.0),
      tracked_(q0.size(), 0),
      last_force_step_(q0.size(), std::numeric_limits<long>::min() / 2) {}

double Stepper::displacement(std::span<const double> mode_shapes) const { return dot(mode_shapes, q_); }

double Stepper::velocity(std::span<const double> mode_shapes) const { return dot(mode_shapes, d_) / plan_.dt(); }

double Stepper::energy() const {
    const double scale = plan_.linear_density() / (2.0 * plan_.dt() * plan_.dt());
    return scale * plan_.propagator().scaled_modal_energy(q_, d_) + contact_energy();
}

double Stepper::contact_energy() const { return 0.5 * plan_.basis().grid_step() * (psi_curr_ + psi_prev_); }

void Stepper::step() {
    if (n_ == 0) {
        // q^1 is the exact free motion of each mode; contact starts acting from step 1 on.
        std::vector<double> q1(q_.size());
        plan_.propagator().first_step(q_, v0_, q1, d_);
        const std::vector<double>& g = plan_.obstacle();
        const PenaltyContact& law = plan_.contact();
        plan_.basis().to_grid(q_, grid_);
        for (std::size_t i : plan_.obstacle_points()) psi_prev_ += law.potential(g[i] - grid_[i]);
        q_ = std::move(q1);
        plan_.basis().to_grid(q_, grid_);
        for (std::size_t i : plan_.obstacle_points()) psi_curr_ += law.potential(g[i] - grid_[i]);
        n_ = 1;
        return;
    }
    if (screen_.window_over(n_)) begin_window();
    solve_contacts();
    apply_impulse();
    advance_modes();
    ++n_;
}

void Stepper::begin_window() {
    if (stats_.windows > 0 && n_ > window_start_)
        screen_.finish_window(window_candidate_steps_ / static_cast<double>(n_ - window_start_));
    ++stats_.windows;
    window_start_ = n_;
    window_candidate_steps_ = 0.0;

    recent_contacts_.clear();
    for (const auto& [i, f] : forces_) recent_contacts_.push_back(i);
    for (std::size_t i : plan_.obstacle_points())
        if (last_force_step_[i] >= n_ - 2 && !std::count(recent_contacts_.begin(), recent_contacts_.end(), i))
            recent_contacts_.push_back(i);

    for (std::size_t i : screen_.candidates()) tracked_[i] = 2;  // stale unless still a candidate
    plan_.basis().to_grid(q_, grid_);
    screen_.begin(n_, q_, d_, grid_, recent_contacts_);
    const std::vector<double>& g = plan_.obstacle();
    for (std::size_t i : screen_.candidates()) {
        if (tracked_[i] == 0) {
            eta_curr_[i] = g[i] - grid_[i];
            track(i);
        }
        tracked_[i] = 1;
    }
    for (unsigned char& flag : tracked_)
        if (flag == 2) flag = 0;
}

void Stepper::track(std::size_t i) {
    // eta^{n-1} from q^{n-1} = q^n - d^n; eta^n is set by the caller.
    const std::span<const double> row = plan_.basis().row(i);
    double u_prev = 0.0;
    for (std::size_t j = 0; j < row.size(); ++j) u_prev += row[j] * (q_[j] - d_[j]);
    eta_prev_[i] = plan_.obstacle()[i] - u_prev;
}

void Stepper::solve_contacts() {
    forces_.clear();
    psi_prev_ = psi_curr_;
    psi_curr_ = 0.0;
    const std::span<const std::size_t> candidates = screen_.candidates();
    window_candidate_steps_ += static_cast<double>(candidates.size());
    stats_.candidate_point_steps += static_cast<double>(candidates.size());
    if (candidates.empty()) return;

    const ModalPropagator& prop = plan_.propagator();
    const auto e = prop.decay();
    const auto beta = prop.beta();
    for (std::size_t j = 0; j < q_.size(); ++j) predicted_[j] = q_[j] + (e[j] * d_[j] - beta[j] * q_[j]);
    const bool use_transform = candidates.size() > plan_.transform_threshold();
    if (use_transform) {
        plan_.basis().to_grid(predicted_, grid_);
        ++stats_.transform_steps;
    }
    const std::vector<double>& g = plan_.obstacle();
    const PenaltyContact& law = plan_.contact();
    const double k = plan_.force_to_displacement();
    for (std::size_t i : candidates) {
        const double w = use_transform ? grid_[i] : dot(plan_.basis().row(i), predicted_);
        const double a = eta_prev_[i];
        const ContactSolution s = law.solve(a, g[i] - w - a, k);
        const double eta_next = a + s.increment;
        eta_prev_[i] = eta_curr_[i];
        eta_curr_[i] = eta_next;
        psi_curr_ += law.potential(eta_next);
        stats_.max_newton_iterations = std::max(stats_.max_newton_iterations, s.iterations);
        if (s.force != 0.0) {
            forces_.emplace_back(i, s.force);
            last_force_step_[i] = n_;
        }
    }
    if (!forces_.empty()) ++stats_.contact_steps;
}

void Stepper::apply_impulse() {
    if (forces_.empty()) return;
    // delta q = (dt^2/mu) dx S^T f: local in space (S delta = (dt^2/mu) f), spread over all modes.
    const double k = plan_.force_to_displacement();
    if (forces_.size() > plan_.transform_threshold()) {
        std::fill(grid_.begin(), grid_.end(), 0.0);
        for (const auto& [i, f] : forces_) grid_[i] = k * f;
        plan_.basis().to_modes(grid_, impulse_);
    } else {
        std::fill(impulse_.begin(), impulse_.end(), 0.0);
        const double dx = plan_.basis().grid_step();
        for (const auto& [i, f] : forces_) {
            const std::span<const double> row = plan_.basis().row(i);
            const double c = k * dx * f;
            for (std::size_t j = 0; j < row.size(); ++j) impulse_[j] += c * row[j];
        }
    }
}

void Stepper::advance_modes() {
    const ModalPropagator& prop = plan_.propagator();
    const auto e = prop.decay();
    const auto beta = prop.beta();
    const auto loss = prop.loss();
    const std::size_t n = q_.size();
    const bool pushed = !forces_.empty();
    double losses = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
        const double next = e[j] * d_[j] - beta[j] * q_[j] + (pushed ? impulse_[j] : 0.0);
        const double span = next + d_[j];  // q^{n+1} - q^{n-1}
        losses += loss[j] * span * span;
        q_[j] += next;
        d_[j] = next;
    }
    dissipated_ += plan_.linear_density() / (4.0 * plan_.dt() * plan_.dt()) * losses;

    if (pushed) {
        // Points the impulse may now bring into reach: track them from the new state.
        const std::size_t before = screen_.candidates().size();
        const std::size_t added = screen_.widen(impulse_);
        const std::span<const std::size_t> candidates = screen_.candidates();
        for (std::size_t c = before; c < before + added; ++c) {
            const std::size_t i = candidates[c];
            if (tracked_[i] == 1) continue;
            eta_curr_[i] = plan_.obstacle()[i] - dot(plan_.basis().row(i), q_);
            track(i);
            tracked_[i] = 1;
        }
    }
}

}  // namespace fretbuzz
