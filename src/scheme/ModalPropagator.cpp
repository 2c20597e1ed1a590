#include "fretbuzz/scheme/ModalPropagator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "fretbuzz/numerics/Kernels.hpp"

namespace fretbuzz {

namespace {
constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Below this |sin(omega_d dt)| a mode sits (almost) on a multiple of the Nyquist
// frequency: two samples do not determine its amplitude, so no bound is claimed.
constexpr double kAliasingLimit = 1e-9;
}  // namespace

ModalPropagator::ModalPropagator(const ModeTable& modes, double dt) : dt_(dt), frequency_hz_(modes.frequency_hz) {
    const std::size_t n = modes.size();
    for (auto* v : {&decay_, &beta_, &loss_, &omega_, &sigma_, &rate_, &half_decay_, &expm1_half_, &sin_step_, &versine_step_,
                    &amplitude_q_, &amplitude_d_, &speed_factor_})
        v->resize(n);
    underdamped_.resize(n);
    special_modes_.reserve(n);
    compute(modes.sigma_per_s);
}

void ModalPropagator::set_damping(std::span<const double> sigma_per_s) { compute(sigma_per_s); }

void ModalPropagator::compute(std::span<const double> sigma_per_s) {
    const std::size_t n = frequency_hz_.size();
    const double dt = dt_;
    lossless_ = true;
    special_modes_.clear();
    for (std::size_t j = 0; j < n; ++j) {
        const double w = 2.0 * std::numbers::pi * frequency_hz_[j];
        const double s = sigma_per_s[j];
        if (s != 0.0) lossless_ = false;
        omega_[j] = w;
        sigma_[j] = s;
        const double h = std::exp(-s * dt);
        const double hm1 = std::expm1(-s * dt);
        half_decay_[j] = h;
        expm1_half_[j] = hm1;
        decay_[j] = h * h;
        loss_[j] = -std::expm1(-2.0 * s * dt);
        if (s < w) {
            const double wd = std::sqrt((w - s) * (w + s));
            const double half = std::sin(0.5 * wd * dt);
            rate_[j] = wd;
            underdamped_[j] = 1;
            sin_step_[j] = std::sin(wd * dt);
            versine_step_[j] = 2.0 * half * half;
            // beta = |1 - e^{(-s + i wd) dt}|^2 = (1 - h)^2 + 4 h sin^2(wd dt / 2)
            beta_[j] = hm1 * hm1 + 4.0 * h * half * half;
        } else {
            const double g = std::sqrt((s - w) * (s + w));
            rate_[j] = g;
            underdamped_[j] = 0;
            sin_step_[j] = std::sinh(g * dt);
            const double half = std::sinh(0.5 * g * dt);
            versine_step_[j] = 2.0 * half * half;
            // beta = (1 - e^{-(s-g)dt})(1 - e^{-(s+g)dt}), s - g = w^2 / (s + g)
            beta_[j] = std::expm1(-w * w / (s + g) * dt) * std::expm1(-(s + g) * dt);
        }
    }
    std::fill(amplitude_q_.begin(), amplitude_q_.end(), 0.0);
    std::fill(amplitude_d_.begin(), amplitude_d_.end(), 0.0);
    for (std::size_t j = 0; j < n; ++j) {
        speed_factor_[j] = underdamped_[j] ? omega_[j] : sigma_[j] + rate_[j];
        if (!underdamped_[j] || std::abs(sin_step_[j]) < kAliasingLimit) {
            special_modes_.push_back(j);
            continue;
        }
        amplitude_q_[j] = (-versine_step_[j] - expm1_half_[j]) / sin_step_[j];
        amplitude_d_[j] = half_decay_[j] / sin_step_[j];
    }
}

void ModalPropagator::free_amplitudes(std::span<const double> q, std::span<const double> d,
                                      std::span<double> amplitude) const {
    kernels::free_amplitudes(amplitude_q_.data(), amplitude_d_.data(), q.data(), d.data(), amplitude.data(), size());
    for (std::size_t j : special_modes_) amplitude[j] = free_amplitude(j, q[j], d[j]);
}

void ModalPropagator::first_step(std::span<const double> q0, std::span<const double> v0, std::span<double> q1,
                                 std::span<double> d1) const {
    for (std::size_t j = 0; j < size(); ++j) {
        // q(dt) = h [q0 C + (v0 + s q0) Sn], C = cos(wd dt) or cosh(g dt), Sn = sin(wd dt)/wd or sinh(g dt)/g;
        // q(dt) - q0 = q0 (h C - 1) + h (v0 + s q0) Sn with h C - 1 = (h - 1) + h (C - 1).
        const double h = half_decay_[j];
        const double c_minus_one = underdamped_[j] ? -versine_step_[j] : versine_step_[j];
        const double sn = rate_[j] > 0.0 ? sin_step_[j] / rate_[j] : dt_;
        const double change = q0[j] * (expm1_half_[j] + h * c_minus_one) + h * (v0[j] + sigma_[j] * q0[j]) * sn;
        d1[j] = change;
        q1[j] = q0[j] + change;
    }
}

double ModalPropagator::scaled_modal_energy(std::span<const double> q, std::span<const double> d) const {
    return kernels::modal_energy(decay_.data(), beta_.data(), q.data(), d.data(), size());
}

bool ModalPropagator::free_phasor(std::size_t j, double q, double d, std::complex<double>& c,
                                  std::complex<double>& z) const {
    if (!underdamped_[j] || std::abs(sin_step_[j]) < kAliasingLimit) return false;
    // q(t) = e^{-s t} (q cos wd t + c2 sin wd t) = Re((q - i c2) e^{(-s + i wd) t}), c2 as in free_amplitudes.
    c = {q, -(amplitude_q_[j] * q + amplitude_d_[j] * d)};
    z = {-sigma_[j], rate_[j]};
    return true;
}

double ModalPropagator::free_amplitude(std::size_t j, double q, double d) const {
    if (std::abs(sin_step_[j]) < kAliasingLimit) return (q == 0.0 && d == 0.0) ? 0.0 : kInfinity;
    const double h = half_decay_[j];
    if (underdamped_[j]) {
        // q(t) = e^{-s t} (c1 cos wd t + c2 sin wd t) through q^n (t = 0) and q^n - d^n (t = -dt):
        // c2 sin(wd dt) = q (cos(wd dt) - h) + d h, cos(wd dt) - h = -versine - (h - 1).
        const double c2 = (q * (-versine_step_[j] - expm1_half_[j]) + d * h) / sin_step_[j];
        return std::sqrt(q * q + c2 * c2);
    }
    // Overdamped: q(t) = c+ e^{-(s-g)t} + c- e^{-(s+g)t}; |q(t)| <= |c+| + |c-|.
    const double s = sigma_[j], g = rate_[j];
    const double a_slow = std::exp((s - g) * dt_), a_fast = std::exp((s + g) * dt_);
    const double c_minus = ((q - d) - q * a_slow) / (a_fast - a_slow);
    return std::abs(q - c_minus) + std::abs(c_minus);
}

}  // namespace fretbuzz
