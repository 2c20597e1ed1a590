#include "fretbuzz/scheme/DenseMatrixScheme.hpp"

#include <cmath>
#include <numbers>

namespace fretbuzz {

DenseMatrixScheme::DenseMatrixScheme(const Case& c, double dt)
    : n_points_(c.mode_count()),
      dt_(dt),
      mu_(c.string.linear_density),
      length_(c.string.length_m),
      contact_(c.contact.stiffness, c.contact.exponent),
      obstacle_(c.obstacle_height_m) {
    const std::size_t n = n_points_;
    const double dx = length_ / static_cast<double>(n + 1);
    const double norm = std::sqrt(2.0 / length_);
    std::vector<double> s(n * n);  // S_ij = phi_j(x_i)
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j)
            s[i * n + j] = norm * std::sin(std::numbers::pi * static_cast<double>((i + 1) * (j + 1)) /
                                           static_cast<double>(n + 1));
    // C_jj = A_j = e^{-sigma dt}(e^{r dt} + e^{-r dt}), r = sqrt(sigma^2 - omega^2); C~_jj = e^{-2 sigma dt}.
    std::vector<double> a(n), e(n);
    for (std::size_t j = 0; j < n; ++j) {
        const double w = 2.0 * std::numbers::pi * c.modes.frequency_hz[j];
        const double sigma = c.modes.sigma_per_s[j];
        const double disc = sigma * sigma - w * w;
        a[j] = disc < 0.0 ? 2.0 * std::exp(-sigma * dt) * std::cos(std::sqrt(-disc) * dt)
                          : 2.0 * std::exp(-sigma * dt) * std::cosh(std::sqrt(disc) * dt);
        e[j] = std::exp(-2.0 * sigma * dt);
    }
    // D = S C (dx S^T), D~ = S C~ (dx S^T)
    d_.assign(n * n, 0.0);
    d_tilde_.assign(n * n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t k = 0; k < n; ++k) {
            double sum_a = 0.0, sum_e = 0.0;
            for (std::size_t j = 0; j < n; ++j) {
                const double sij_skj = s[i * n + j] * s[k * n + j];
                sum_a += a[j] * sij_skj;
                sum_e += e[j] * sij_skj;
            }
            d_[i * n + k] = dx * sum_a;
            d_tilde_[i * n + k] = dx * sum_e;
        }
    // u^0 from q^0; u^1 from the exact free motion of each mode (the paper's start).
    u_prev_.assign(n, 0.0);
    u_.assign(n, 0.0);
    for (std::size_t j = 0; j < n; ++j) {
        const double w = 2.0 * std::numbers::pi * c.modes.frequency_hz[j];
        const double sigma = c.modes.sigma_per_s[j];
        const double q0 = c.initial_displacement[j], v0 = c.initial_velocity[j];
        const double disc = sigma * sigma - w * w;
        double q1 = 0.0;
        if (disc < 0.0) {
            const double wd = std::sqrt(-disc);
            q1 = std::exp(-sigma * dt) * (q0 * std::cos(wd * dt) + (v0 + sigma * q0) * std::sin(wd * dt) / wd);
        } else {
            const double g = std::sqrt(disc);
            const double sn = g > 0.0 ? std::sinh(g * dt) / g : dt;
            q1 = std::exp(-sigma * dt) * (q0 * std::cosh(g * dt) + (v0 + sigma * q0) * sn);
        }
        for (std::size_t i = 0; i < n; ++i) {
            u_prev_[i] += s[i * n + j] * q0;
            u_[i] += s[i * n + j] * q1;
        }
    }
    u_next_.assign(n, 0.0);
    free_.assign(n, 0.0);
    eta_prev_.resize(n);
}

void DenseMatrixScheme::step() {
    const std::size_t n = n_points_;
    for (std::size_t i = 0; i < n; ++i) {
        double sum = 0.0;
        for (std::size_t k = 0; k < n; ++k) sum += d_[i * n + k] * u_[k] - d_tilde_[i * n + k] * u_prev_[k];
        free_[i] = sum;
    }
    const double k = dt_ * dt_ / mu_;
    for (std::size_t i = 0; i < n; ++i) {
        const double g = obstacle_[i];
        if (!std::isfinite(g)) {
            u_next_[i] = free_[i];
            continue;
        }
        const double a = g - u_prev_[i];
        const ContactSolution s = contact_.solve(a, g - free_[i] - a, k);
        u_next_[i] = free_[i] + k * s.force;
    }
    std::swap(u_prev_, u_);
    std::swap(u_, u_next_);
    ++n_;
}

double DenseMatrixScheme::displacement_at(double x) const {
    const std::size_t n = n_points_;
    const double dx = length_ / static_cast<double>(n + 1);
    const double norm = std::sqrt(2.0 / length_);
    double u = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
        double q = 0.0;
        for (std::size_t i = 0; i < n; ++i)
            q += norm * std::sin(std::numbers::pi * static_cast<double>((i + 1) * (j + 1)) / static_cast<double>(n + 1)) *
                 u_[i];
        u += dx * q * norm * std::sin(static_cast<double>(j + 1) * std::numbers::pi * x / length_);
    }
    return u;
}

}  // namespace fretbuzz
