#pragma once
// Newton's method on the exact points' own system (PointContact): the points that move one
// another within a step through the modes, and the pads pressing on their u_s (one more unknown
// each, bordering the points' P x P Jacobian), solved together where any touches. Its parts of
// the Jacobian (the points', the pads' border) are the joint solve's too (GridNewton). The
// systems live on the stack up to point_newton::kSmall unknowns: stepping allocates nothing.
// (Private to PointContact.cpp, which instantiates it for the plan's laws.)
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/ContactForceLaw.hpp"
#include "fretbuzz/scheme/PointContact.hpp"

namespace fretbuzz {

namespace point_newton {
constexpr int kMaxNewton = 60;
// Up to this many points the Newton system lives on the stack (a bass's 20 or 24 frets).
constexpr int kSmall = 32;
using SmallMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kSmall, kSmall>;

// Newton's answer is taken when its residual is small, or when its last correction is: a stiff
// row (a pad of stiffness 1e15 at 48 kHz: dR/dx ~ 1e9) cannot get its residual below its slope
// times the rounding of x, ~1e-10 m, however exact x is (detail::monotone_root's floor, for
// one unknown). The correction J^-1 R measures the error in the unknowns themselves.
// (`stalled`: the line search found no decrease, so the correction is the one at the answer.)
template <class Vector>
bool converged(double norm, const Vector& correction, bool stalled, double scale) {
    const double tolerance = 1e-9 * scale;
    return norm <= tolerance || (stalled && correction.cwiseAbs().maxCoeff() <= tolerance);
}

// s_a . s_b of pads a and b of one solve.
inline double cross(std::span<const PointContact::Pad> pads, std::size_t a, std::size_t b) {
    return a == b ? pads[a].self : pads[a].cross[b];
}

inline double pad_force_at(const PointContact::Pad& pad, double x) {
    double force = 0.0, slope = 0.0;
    pad.press->force_and_slope(x, force, slope);
    return force;
}

// Whether any of these forces acts.
inline bool any_push(std::span<const double> forces) {
    return std::any_of(forces.begin(), forces.end(), [](double f) { return f != 0.0; });
}
}  // namespace point_newton

class PointNewton {
public:
    using State = PointContact::State;
    using Pad = PointContact::Pad;

    explicit PointNewton(const PointContact& contact) : contact_(&contact) {}

    // The awake points' list, and the size Newton's tolerance is relative to.
    double newton_scale(State& s) const;
    // J = I + k G diag(d f_q / d r_q) over the awake points, at r's quotients (their slopes into s.slope).
    template <class Matrix, ContactForceLaw Law>
    void points_jacobian(State& s, const Law& law, double k, const std::vector<double>& r, Matrix& jacobian) const;
    // The pads' rows and columns beside it.
    template <class Matrix>
    void pad_border(const State& s, double k, std::span<const Pad> pads, std::span<const double> pad_slope,
                    Matrix& jacobian) const;
    // The points (and the pads) together, from s.increment (each point's own solution); s.force
    // and each pad's x take the solution (throws SolverError where Newton does not converge).
    template <class Matrix, ContactForceLaw Law>
    void solve_coupled(State& s, const Law& law, double k, std::span<Pad> pads) const;

private:
    const PointContact* contact_;
};

inline double PointNewton::newton_scale(State& s) const {
    // The awake points (a resting one is apart and stays so: its force is zero whatever the
    // others do, and no equation of the others reads its unknown), and the size of their
    // unknowns, which Newton's tolerance is relative to.
    s.awake_list.clear();
    double scale = std::numeric_limits<double>::min();
    for (std::size_t p = 0; p < contact_->size(); ++p) {
        if (s.resting[p] != 0) {
            s.quotient[p] = s.force[p] = 0.0;
            continue;
        }
        s.awake_list.push_back(p);
        scale = std::max({scale, std::abs(s.b[p]), std::abs(s.eta_prev[p]), std::abs(s.increment[p])});
    }
    // b_p = height - u_p - eta_p^{n-1} carries the rounding of the predicted u_p: no residual
    // is known to better than that.
    return std::max(scale, s.prediction_size);
}

template <class Matrix, ContactForceLaw Law>
void PointNewton::points_jacobian(State& s, const Law& law, double k, const std::vector<double>& r,
                                   Matrix& jacobian) const {
    // J = I + k G diag(d f_q / d r_q) over the awake points, at r's quotients
    const std::vector<std::size_t>& awake = s.awake_list;
    for (std::size_t q : awake) s.slope[q] = law.slope_of_quotient(s.eta_prev[q], r[q], s.quotient[q]);
    for (std::size_t a = 0; a < awake.size(); ++a)
        for (std::size_t c = 0; c < awake.size(); ++c)
            jacobian(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(c)) =
                (a == c ? 1.0 : 0.0) + k * contact_->gram(awake[a], awake[c]) * s.slope[awake[c]];
}

template <class Matrix>
void PointNewton::pad_border(const State& s, double k, std::span<const Pad> pads, std::span<const double> pad_slope,
                              Matrix& jacobian) const {
    // Each pad's row and column beside the points' Jacobian (points_jacobian's slopes):
    // dR_p/dx_a = k h^a_p F_a', dR_a/dr_q = -k c_q h^a_q f_q', dR_a/dx_b = delta_ab - k (s_a . s_b) F_b'.
    const std::vector<std::size_t>& awake = s.awake_list;
    const std::size_t count = awake.size();
    for (std::size_t a = 0; a < pads.size(); ++a) {
        const auto e = static_cast<Eigen::Index>(count + a);
        for (std::size_t c = 0; c < count; ++c) {
            const std::size_t p = awake[c];
            const auto i = static_cast<Eigen::Index>(c);
            jacobian(i, e) = k * pads[a].coupling[p] * pad_slope[a];
            jacobian(e, i) = -k * contact_->weight(p) * pads[a].coupling[p] * s.slope[p];
        }
        for (std::size_t b = 0; b < pads.size(); ++b)
            jacobian(e, static_cast<Eigen::Index>(count + b)) =
                (a == b ? 1.0 : 0.0) - k * point_newton::cross(pads, a, b) * pad_slope[b];
    }
}

template <class Matrix, ContactForceLaw Law>
void PointNewton::solve_coupled(State& s, const Law& law, double k, std::span<Pad> pads) const {
    double scale = newton_scale(s);
    const std::vector<std::size_t>& awake = s.awake_list;
    const std::size_t count = awake.size();
    const std::size_t pad_count = pads.size();
    const auto m = static_cast<Eigen::Index>(count + pad_count);
    Matrix jacobian(m, m);
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, Matrix::MaxRowsAtCompileTime, 1> step(m);
    // Each pad's unknown x, its force F(x), dF/dx and residual beside the points'.
    const auto room = [&](std::vector<double>& v) { return std::span<double>(v).first(pad_count); };
    const std::span<double> x = room(s.press_x), pad_force = room(s.press_force), pad_slope = room(s.press_slope),
                            pad_residual = room(s.press_residual), trial_x = room(s.press_trial);
    for (std::size_t a = 0; a < pad_count; ++a) {
        x[a] = pads[a].x;
        scale = std::max({scale, std::abs(pads[a].predicted), std::abs(x[a])});
    }
    // residual_p = r_p + k sum_q G_pq f_q(r_q) + k sum_a h^a_p F_a(x_a) - b_p, at increments r (and
    // the pads' x); returns the largest size of them.
    const auto residual_at = [&](const std::vector<double>& r, std::span<const double> at) {
        double largest = 0.0;
        for (std::size_t q : awake) s.quotient[q] = law.difference_quotient(s.eta_prev[q], r[q]);
        for (std::size_t a = 0; a < pad_count; ++a) pads[a].press->force_and_slope(at[a], pad_force[a], pad_slope[a]);
        for (std::size_t p : awake) {
            double push = 0.0;
            for (std::size_t q : awake) push += contact_->gram(p, q) * s.quotient[q];
            for (std::size_t a = 0; a < pad_count; ++a) push += pads[a].coupling[p] * pad_force[a];
            s.residual[p] = r[p] + k * push - s.b[p];
            largest = std::max(largest, std::abs(s.residual[p]));
        }
        for (std::size_t a = 0; a < pad_count; ++a) {
            double push = 0.0;
            for (std::size_t q : awake) push += contact_->weight(q) * pads[a].coupling[q] * s.quotient[q];
            for (std::size_t b = 0; b < pad_count; ++b) push += point_newton::cross(pads, a, b) * pad_force[b];
            pad_residual[a] = at[a] - pads[a].predicted - k * push;
            largest = std::max(largest, std::abs(pad_residual[a]));
        }
        return largest;
    };
    const double tolerance = 4.0 * std::numeric_limits<double>::epsilon() * scale;
    std::vector<double>& r = s.increment;
    double norm = residual_at(r, x);
    std::vector<double>& trial = s.force;  // scratch until the forces are formed at the end
    int iteration = 0;
    bool stalled = false;
    for (; iteration < point_newton::kMaxNewton && norm > tolerance; ++iteration) {
        // the points' Jacobian, bordered by the pads' rows and columns
        points_jacobian(s, law, k, r, jacobian);
        pad_border(s, k, pads, pad_slope, jacobian);
        for (std::size_t a = 0; a < count; ++a) step(static_cast<Eigen::Index>(a)) = -s.residual[awake[a]];
        for (std::size_t a = 0; a < pad_count; ++a) step(static_cast<Eigen::Index>(count + a)) = -pad_residual[a];
        step = Eigen::PartialPivLU<Matrix>(jacobian).solve(step);
        // Backtracking on the residual: the kink of [eta]_+ at eta = 0 can overshoot.
        double t = 1.0;
        bool decreased = false;
        for (int halving = 0; halving < 40; ++halving, t *= 0.5) {
            for (std::size_t a = 0; a < count; ++a) trial[awake[a]] = r[awake[a]] + t * step(static_cast<Eigen::Index>(a));
            for (std::size_t a = 0; a < pad_count; ++a) trial_x[a] = x[a] + t * step(static_cast<Eigen::Index>(count + a));
            const double trial_norm = residual_at(trial, trial_x);
            if (trial_norm < norm) {
                r.swap(trial);
                std::copy(trial_x.begin(), trial_x.end(), x.begin());
                norm = trial_norm;
                decreased = true;
                break;
            }
        }
        if (!decreased) {
            residual_at(r, x);  // back to r's quotients
            stalled = true;     // at the round-off floor
            break;
        }
    }
    if (!point_newton::converged(norm, step, stalled, scale))
        throw SolverError("point contact: the coupled Newton solve of " + std::to_string(count) + " points and " +
                          std::to_string(pad_count) + " pads did not converge (residual " + std::to_string(norm) + " m)");
    s.iterations = std::max(s.iterations, iteration);
    for (std::size_t p = 0; p < contact_->size(); ++p) s.force[p] = s.quotient[p];
    for (std::size_t a = 0; a < pad_count; ++a) pads[a].x = x[a];
}

}  // namespace fretbuzz
