#pragma once
// An independent discretisation of StringProblem for cross-checking the modal scheme: the
// energy-conserving finite-difference penalty scheme of Bilbao, Torin and Chatziioannou
// (Acta Acustica united with Acustica 101, 2015), on x_i = i h, h = L/N, i = 0..N:
//     (1 + sigma0 dt) u^{n+1} = 2 u^n - (1 - sigma0 dt) u^{n-1}
//                               + (dt^2/mu) (T dxx u^n - EI dxxxx u^n + f^n),
// u_0 = u_N = 0 and dxx u = 0 at the ends (simply supported), with the pointwise discrete
// gradient f^n_i = (Psi(eta_i^{n+1}) - Psi(eta_i^{n-1})) / (eta_i^{n+1} - eta_i^{n-1}).
// It conserves (lossless) or dissipates (sigma0 > 0) the discrete energy
//     H^{n+1/2} = mu/2 |dt+ u^n|^2 + T/2 <dx+ u^{n+1}, dx+ u^n> + EI/2 <dxx u^{n+1}, dxx u^n>
//                 + h sum_i (Psi(eta_i^{n+1}) + Psi(eta_i^n)) / 2
// exactly: H^{n+1/2} - H^{n-1/2} = -2 mu sigma0 dt |(u^{n+1} - u^{n-1}) / (2 dt)|^2.
// Nothing of the modal code is used.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/reference/DiscreteGradientContact.hpp"
#include "fretbuzz/reference/StringProblem.hpp"

namespace fretbuzz::reference {

// Largest stable dt on h = L/N: dt^2 (c^2/h^2 + 4 EI/(mu h^4)) <= 1.
double stability_limit(const StringProblem& problem, std::size_t intervals);

class FiniteDifferenceString {
public:
    // Throws InputError unless intervals >= 2 and 0 < dt < stability_limit.
    FiniteDifferenceString(const StringProblem& problem, std::size_t intervals, double dt);

    // n -> n + 1. The first step is the linear Taylor start from rest.
    void step();

    long step_index() const { return n_; }
    double time() const { return static_cast<double>(n_) * dt_; }
    double dt() const { return dt_; }
    double grid_step() const { return h_; }
    std::span<const double> displacement() const { return current_; }  // u^n_i, i = 0..N
    // u(x, t_n), linear between grid points.
    double displacement_at(double x) const;
    // H^{n-1/2} (n >= 1) and the energy lost to sigma0 since H^{1/2} (joules).
    double energy() const { return energy_; }
    double dissipated() const { return dissipated_; }
    int max_contact_iterations() const { return max_iterations_; }

private:
    void second_difference(std::span<const double> u, std::span<double> out) const;  // dxx, zero at the ends
    double energy_between(std::span<const double> later, std::span<const double> earlier) const;

    StringProblem problem_;
    DiscreteGradientContact contact_;
    std::size_t intervals_;
    double h_, dt_;
    long n_ = 0;
    std::vector<double> obstacle_;                    // g(x_i), i = 0..N
    std::vector<double> previous_, current_, next_;   // u^{n-1}, u^n, u^{n+1}
    std::vector<double> curvature_, bending_;         // dxx u^n, dxx dxx u^n
    std::vector<double> curvature_next_;
    double energy_ = 0.0;
    double dissipated_ = 0.0;
    int max_iterations_ = 0;
};

}  // namespace fretbuzz::reference
