#pragma once
// The exact one-step map of each damped modal oscillator q'' + 2 sigma q' + omega^2 q = 0
// (Issanchou et al. 2017, eq. 4: q^{n+1} = A q^n - e q^{n-1} with A = 2 e^{-sigma dt} cos(omega_d dt),
// e = e^{-2 sigma dt}). It is written in difference form, d^n = q^n - q^{n-1}:
//     d^{n+1} = e d^n - beta q^n,   q^{n+1} = q^n + d^{n+1},   beta = 1 + e - A,
// with beta computed without cancellation, so that low modes at tiny dt keep full precision.
// The same coefficients give the discrete energy of section 3 in closed form
// (C1 = (1+e)/2, C2 = beta/dt^2, C3 = (1-e)/dt once the paper's theta_j and sigma*_j are
// substituted), and bounds on the free motion used to rule out contact.
#include <complex>
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/numerics/CacheAligned.hpp"

#include "fretbuzz/model/ModeTable.hpp"

namespace fretbuzz {

class ModalPropagator {
public:
    ModalPropagator(const ModeTable& modes, double dt);

    // New dampings sigma_j for the same frequencies and dt, computed in place (no allocation:
    // a sounding instrument can change its damping between two audio blocks).
    void set_damping(std::span<const double> sigma_per_s);

    std::size_t size() const { return decay_.size(); }
    double dt() const { return dt_; }
    std::span<const double> decay() const { return decay_; }  // e_j
    std::span<const double> beta() const { return beta_; }    // 1 + e_j - A_j
    std::span<const double> loss() const { return loss_; }    // 1 - e_j
    std::span<const double> omega() const { return omega_; }
    bool lossless() const { return lossless_; }

    // Exact free motion over the first step from displacement q0 and velocity v0:
    // q1 = q(dt), d1 = q1 - q0 (computed without cancellation).
    void first_step(std::span<const double> q0, std::span<const double> v0, std::span<double> q1,
                    std::span<double> d1) const;

    // sum_j (1+e_j)/2 d_j^2 + beta_j q_j (q_j - d_j): the modal energy times 2 dt^2 / mu.
    double scaled_modal_energy(std::span<const double> q, std::span<const double> d) const;

    // Largest |q_j(t)|, t >= t_n, of the free motion from (q^n, d^n); +infinity where two
    // samples do not determine it (a mode aliased onto a multiple of the Nyquist frequency).
    double free_amplitude(std::size_t j, double q, double d) const;
    // free_amplitude for every mode at once (vectorised for the usual underdamped modes).
    void free_amplitudes(std::span<const double> q, std::span<const double> d, std::span<double> amplitude) const;
    // The free motion through (q^n, d^n) as the continuous q(t_n + t) = Re(c e^{z t}), z = -sigma + i omega_d,
    // of which the steps are samples. False (c, z untouched) for a mode it does not describe:
    // overdamped, or aliased onto a multiple of the Nyquist frequency.
    bool free_phasor(std::size_t j, double q, double d, std::complex<double>& c, std::complex<double>& z) const;
    // Per-mode factor turning an amplitude into the largest |dq_j/dt| of that free motion:
    // omega_j when underdamped (q = Re(c e^{z t}), |z| = omega), sigma_j + gamma_j otherwise.
    std::span<const double> speed_factor() const { return speed_factor_; }

private:
    struct FreeMotionCoefficients {
        double c_plus, c_minus;  // overdamped: q(t) = c+ e^{-(s-g)t} + c- e^{-(s+g)t}
    };

    void compute(std::span<const double> sigma_per_s);

    double dt_;
    bool lossless_ = true;
    std::vector<double> frequency_hz_;
    AlignedVector decay_, beta_, loss_, omega_, sigma_;
    AlignedVector rate_;            // omega_d (underdamped) or gamma = sqrt(sigma^2 - omega^2)
    std::vector<unsigned char> underdamped_;
    AlignedVector half_decay_;      // e^{-sigma dt}
    AlignedVector expm1_half_;      // e^{-sigma dt} - 1
    AlignedVector sin_step_;        // sin(omega_d dt) or sinh(gamma dt)
    AlignedVector versine_step_;    // 1 - cos(omega_d dt) = 2 sin^2(omega_d dt / 2), or cosh(gamma dt) - 1
    // Underdamped amplitude R = sqrt(q^2 + ((a q + b d) / sin(omega_d dt))^2): a, b / sin(omega_d dt)
    // (zero for the modes handled one by one: overdamped or aliased).
    AlignedVector amplitude_q_, amplitude_d_;
    std::vector<std::size_t> special_modes_;
    AlignedVector speed_factor_;
};

}  // namespace fretbuzz
