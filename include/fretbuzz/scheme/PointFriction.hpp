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
// Beside obstacle points on the grid (PointContact::grid_coupled(): a fretboard's board under
// its exact crowns), grid point i's friction f_i moves point p by k dx M_pi f_i and point p's
// moves grid point i by k c_p M_pi f_p (M_pi = phi(x_p) . S_i); each grid equation stays a
// scalar one given the points' forces, so Newton's method runs on the points' unknowns alone
// with each grid equation solved inside it (a Schur complement, as PointContact does along z).
// The work per step, dt (sum_p c_p f_p v_p + dx sum_i f_i v_i), is never positive. Stepping
// allocates nothing.
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

    std::size_t size() const { return points_ != nullptr ? points_->size() : 0; }
    // The grid's obstacle points rubbing in the same step (grid_coupled() only): each one's grid
    // index, free-step velocity v0_i and normal force; receives each one's f_i (N/m) and v_i.
    struct Grid {
        std::span<const std::size_t> points;
        std::span<const double> v0, normal;
        std::span<double> force, velocity;
        double step = 0.0;  // dx
    };
    bool grid_coupled() const { return points_ != nullptr && points_->grid_coupled(); }
    // Points with normal[p] != 0 rub: their forces (N/m) into force, 0 elsewhere; v0 as above.
    // Returns the work of the step (J, <= 0), the grid's included. Throws SolverError if
    // Newton's method fails.
    double solve(const Friction& law, std::span<const double> v0, std::span<const double> normal, double k, double dt,
                 std::span<double> force);
    double solve(const Friction& law, std::span<const double> v0, std::span<const double> normal, double k, double dt,
                 std::span<double> force, Grid& grid);
    int iterations() const { return iterations_; }  // of the last solve (1 for scalar solves)

private:
    struct Step;  // one solve's data
    double solve(const Step& step, std::span<double> force);
    void newton(const Step& step);
    // The grid's equations given the points' g (grid only); each one's slope phi' / (1 + K phi').
    void solve_grid(const Step& step, const std::vector<double>& g);
    double residual(const Step& step, const std::vector<double>& g, std::vector<double>& r);
    double objective(const Step& step, const std::vector<double>& g);
    // The points' widths c_p, G_pq and M_pi, as the normal solve has them.
    double weight(std::size_t p) const { return points_->weight(p); }
    double gram(std::size_t p, std::size_t q) const { return points_->gram(p, q); }
    double coupling(std::size_t p, std::size_t i) const { return points_->grid_coupling(p, i); }

    const PointContact* points_ = nullptr;  // the plan's (it outlives every stepper)
    std::vector<double> g_, trial_, r_, trial_r_;  // Newton's unknowns g_p = phi(v_p), residuals
    std::vector<double> grid_slope_;               // per rubbing grid point
    struct Newton;  // its matrix and factors (Eigen's), made once
    std::unique_ptr<Newton> newton_;
    int iterations_ = 0;
};

}  // namespace fretbuzz
