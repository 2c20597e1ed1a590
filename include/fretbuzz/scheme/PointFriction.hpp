#pragma once
// Friction along y at point obstacles held at their exact positions x_p (PointContact's
// points, with two polarisations). Point p's friction force per unit length f_p acts over its
// width c_p on the row phi(x_p), as its normal force does along z:
//     y-modes: q^{n+1} = ... + (dt^2/mu) sum_p c_p f_p phi(x_p),
// so a point's force moves every other point in the same step (G_pq = c_q phi(x_p) . phi(x_q),
// PointContact's coupling). With v_p = (y_p^{n+1} - y_p^{n-1}) / (2 dt) and Friction's law
// f_p = -mu_f |F_p| phi(v_p), the points in contact solve
//     v_p + (k / (2 dt)) mu_f sum_q G_pq |F_q| phi(v_q) = v0_p,   k = dt^2/mu,
// a monotone system: in g_p = phi(v_p) it is the gradient of a strictly convex function (one
// root), solved by Newton's method with a line search from each point's own scalar root. A single
// point, or points whose rows do not couple, take Friction's scalar solve with K scaled by G_pp.
// The work per step, dt sum_p c_p f_p v_p, is never positive. Stepping allocates nothing.
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "fretbuzz/scheme/Friction.hpp"
#include "fretbuzz/scheme/PointContact.hpp"

namespace fretbuzz {

class PointFriction {
public:
    PointFriction();
    explicit PointFriction(const PointContact& points);
    PointFriction(const PointFriction& other);
    PointFriction& operator=(const PointFriction& other);
    PointFriction(PointFriction&&) noexcept;
    PointFriction& operator=(PointFriction&&) noexcept;
    ~PointFriction();

    std::size_t size() const { return weights_.size(); }
    // Points with normal[p] != 0 rub: their forces (N/m) into force, 0 elsewhere; v0 as above.
    // Returns the work of the step (J, <= 0). Throws SolverError if Newton's method fails.
    double solve(const Friction& law, std::span<const double> v0, std::span<const double> normal, double k, double dt,
                 std::span<double> force);
    int iterations() const { return iterations_; }  // of the last solve (1 for scalar solves)

private:
    double residual(std::span<const double> v0, std::span<const double> normal, double v_eps, double scale,
                    const std::vector<double>& g, std::vector<double>& r) const;
    double objective(std::span<const double> v0, std::span<const double> normal, double v_eps, double scale,
                     const std::vector<double>& g) const;
    double gram(std::size_t p, std::size_t q) const { return gram_[p * weights_.size() + q]; }

    std::vector<double> weights_;
    std::vector<double> gram_;  // G_pq, row by row
    bool coupled_ = false;
    std::vector<double> g_, trial_, r_, trial_r_;  // Newton's unknowns g_p = phi(v_p), residuals
    struct Newton;  // its matrix and factors (Eigen's), made once
    std::unique_ptr<Newton> newton_;
    int iterations_ = 0;
};

}  // namespace fretbuzz
