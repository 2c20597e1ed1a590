#include "fretbuzz/reference/FiniteDifferenceString.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fretbuzz/Error.hpp"

namespace fretbuzz::reference {

double stability_limit(const StringProblem& problem, std::size_t intervals) {
    const double h = problem.length_m / static_cast<double>(intervals);
    const double c = problem.wave_speed();
    const double kappa2 = problem.bending_stiffness / problem.linear_density;
    return 1.0 / std::sqrt(c * c / (h * h) + 4.0 * kappa2 / (h * h * h * h));
}

FiniteDifferenceString::FiniteDifferenceString(const StringProblem& problem, std::size_t intervals, double dt)
    : problem_(problem),
      contact_(problem.contact_stiffness, problem.contact_exponent),
      intervals_(intervals),
      h_(problem.length_m / static_cast<double>(intervals)),
      dt_(dt) {
    problem_.validate();
    require_at_least("finite-difference intervals N", static_cast<double>(intervals), 2.0);
    require_positive("finite-difference time step dt", dt);
    // Strictly below the limit: at it the energy is only semi-definite.
    if (!(dt < stability_limit(problem_, intervals)))
        throw InputError(out_of_range_message("finite-difference time step dt", dt,
                                              "must be below the stability limit " +
                                                  std::to_string(stability_limit(problem_, intervals)) + " s"));
    const std::size_t points = intervals + 1;
    obstacle_.resize(points);
    current_.assign(points, 0.0);
    for (std::size_t i = 1; i < intervals; ++i) {
        const double x = static_cast<double>(i) * h_;
        obstacle_[i] = problem_.obstacle(x);
        current_[i] = problem_.initial_shape(x);
        if (current_[i] < obstacle_[i])
            throw InputError(out_of_range_message("initial shape at x = " + std::to_string(x) + " m", current_[i],
                                                  "must not be below the obstacle height " + std::to_string(obstacle_[i])));
    }
    obstacle_.front() = obstacle_.back() = -std::numeric_limits<double>::infinity();  // the supports
    previous_ = current_;
    next_.assign(points, 0.0);
    curvature_.assign(points, 0.0);
    curvature_next_.assign(points, 0.0);
    bending_.assign(points, 0.0);
}

void FiniteDifferenceString::second_difference(std::span<const double> u, std::span<double> out) const {
    const double inv_h2 = 1.0 / (h_ * h_);
    out.front() = out.back() = 0.0;  // u = 0 and dxx u = 0 at simply supported ends
    for (std::size_t i = 1; i < intervals_; ++i) out[i] = (u[i + 1] - 2.0 * u[i] + u[i - 1]) * inv_h2;
}

double FiniteDifferenceString::energy_between(std::span<const double> later, std::span<const double> earlier) const {
    const double mu = problem_.linear_density;
    double kinetic = 0.0, tension = 0.0, bending = 0.0, contact = 0.0;
    for (std::size_t i = 0; i < intervals_; ++i) {
        const double velocity = (later[i] - earlier[i]) / dt_;
        kinetic += velocity * velocity;
        tension += (later[i + 1] - later[i]) * (earlier[i + 1] - earlier[i]);
    }
    for (std::size_t i = 1; i < intervals_; ++i) {
        bending += curvature_next_[i] * curvature_[i];
        contact += contact_.potential(obstacle_[i] - later[i]) + contact_.potential(obstacle_[i] - earlier[i]);
    }
    return 0.5 * mu * h_ * kinetic + 0.5 * problem_.tension_n * tension / h_ +
           0.5 * problem_.bending_stiffness * h_ * bending + 0.5 * h_ * contact;
}

void FiniteDifferenceString::step() {
    const double mu = problem_.linear_density;
    const double loss = problem_.loss_per_s * dt_;
    second_difference(current_, curvature_);
    second_difference(curvature_, bending_);
    const double linear_gain = dt_ * dt_ / mu;
    for (std::size_t i = 1; i < intervals_; ++i) {
        const double stiffness_force = problem_.tension_n * curvature_[i] - problem_.bending_stiffness * bending_[i];
        if (n_ == 0)  // from rest: u^1 = u^0 + dt^2/(2 mu) L u^0, second-order accurate
            next_[i] = current_[i] + 0.5 * linear_gain * stiffness_force;
        else
            next_[i] = (2.0 * current_[i] - (1.0 - loss) * previous_[i] + linear_gain * stiffness_force) / (1.0 + loss);
    }
    if (n_ > 0) {
        // The contact force enters u^{n+1} with gain k; each point is an independent scalar equation.
        const double k = linear_gain / (1.0 + loss);
        for (std::size_t i = 1; i < intervals_; ++i) {
            if (!std::isfinite(obstacle_[i])) continue;
            const double before = obstacle_[i] - previous_[i];  // eta^{n-1}
            const double free_change = obstacle_[i] - next_[i] - before;
            const ContactStep s = contact_.solve(before, free_change, k);
            next_[i] += k * s.force;
            max_iterations_ = std::max(max_iterations_, s.iterations);
        }
    }
    second_difference(next_, curvature_next_);
    energy_ = energy_between(next_, current_);
    if (n_ > 0) {
        double rate = 0.0;  // |(u^{n+1} - u^{n-1}) / (2 dt)|^2
        for (std::size_t i = 1; i < intervals_; ++i) {
            const double v = (next_[i] - previous_[i]) / (2.0 * dt_);
            rate += v * v;
        }
        dissipated_ += 2.0 * mu * problem_.loss_per_s * dt_ * h_ * rate;
    }
    previous_.swap(current_);
    current_.swap(next_);
    ++n_;
}

double FiniteDifferenceString::displacement_at(double x) const {
    const double position = std::clamp(x / h_, 0.0, static_cast<double>(intervals_));
    const auto left = std::min(static_cast<std::size_t>(position), intervals_ - 1);
    const double weight = position - static_cast<double>(left);
    return (1.0 - weight) * current_[left] + weight * current_[left + 1];
}

}  // namespace fretbuzz::reference
