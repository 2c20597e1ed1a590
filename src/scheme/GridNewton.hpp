#pragma once
// The exact points beside the grid's obstacle points (PointContact::Grid) in one Newton solve:
// the grid's equations stay one scalar each given the points' (and the pads') forces, so Newton
// runs on the points' unknowns, the pads' and the fingers' heights alone, each grid equation
// solved inside every evaluation (a Schur complement: see PointContact.hpp).
// (Private to PointContact.cpp, which instantiates it for the plan's laws.)
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "PointNewton.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/ContactForceLaw.hpp"
#include "fretbuzz/scheme/PointContact.hpp"

namespace fretbuzz {

class GridNewton {
public:
    using State = PointContact::State;
    using Pad = PointContact::Pad;
    using Grid = PointContact::Grid;

    explicit GridNewton(const PointContact& contact) : contact_(&contact), points_(contact) {}

    // k dx sum_i M_pi f_i over the grid's pushing points and the fingers' pads (u at x_p: p < size();
    // pad a's u_s for p == size() + a).
    double grid_push(const State& s, double k, const Grid& grid, std::size_t p, std::span<const Pad> pads) const;
    // The grid's equations (and the pads') given the points' forces; returns whether any grid or
    // pad point pushed. (s.pad_* is scratch: s is otherwise read only.)
    // `height`: the fingers' heights to try (GridPads::trial); none: their own solves (GridPads::solve).
    template <ContactForceLaw Law>
    bool solve_grid(State& s, const Law& law, double k, Grid& grid, std::span<const Pad> pads,
                    std::span<const double> pad_force, const std::vector<double>* height = nullptr) const;
    // evaluated: s holds the evaluation at Newton's start. may_fail: returns false where Newton
    // does not converge (else throws SolverError).
    template <class Matrix, ContactForceLaw Law>
    bool solve_with_grid(State& s, const Law& law, double k, Grid& grid, std::span<Pad> pads, bool evaluated,
                         bool may_fail = false) const;

private:
    // The joint system's residuals at increments `at`, the pads' `at_x` and the fingers' heights
    // `at_height` (the grid's equations solved for them where `solve`); the largest, a finger's
    // measured against the points' `scale`.
    template <ContactForceLaw Law>
    double joint_residual(State& s, const Law& law, double k, Grid& grid, std::span<const Pad> pads,
                          const std::vector<double>& at, std::span<const double> at_x,
                          const std::vector<double>& at_height, bool solve, double scale) const;
    // Newton's step `step` from s.increment, the pads' x and s.height, halved until the residual
    // `norm` drops: true, the unknowns moved and `norm` theirs; false where none did (at the
    // round-off floor: the last trial taken where it is as good, else r's evaluation restored).
    template <class Vector, ContactForceLaw Law>
    bool joint_step(State& s, const Law& law, double k, Grid& grid, std::span<const Pad> pads, const Vector& step,
                    std::span<double> x, double& norm, double scale) const;
    // The grid's part of the joint Jacobian (solve_with_grid's k^2 dx terms): each of its points in
    // contact responds to a push by w_i = f_i' / (1 + k f_i'), which moves the points' and the pads'
    // rows through their couplings M_pi and m^a_i.
    template <class Matrix, ContactForceLaw Law>
    void grid_response(const State& s, const Law& law, double k, const Grid& grid, std::span<const Pad> pads,
                       std::span<const double> pad_slope, Matrix& jacobian) const;
    // The fingers' part of the Jacobian.
    template <class Matrix>
    void pads_jacobian(State& s, double k, const Grid& grid, std::span<const Pad> pads, std::span<const double> pad_slope,
                       Matrix& jacobian) const;

    const PointContact* contact_;
    PointNewton points_;  // the points' and the pads' parts of the Jacobian
};

inline double GridNewton::grid_push(const State& s, double k, const Grid& grid, std::size_t p,
                                    std::span<const Pad> pads) const {
    const std::size_t points = contact_->size();
    const auto coupling = [&](std::size_t i) { return p < points ? contact_->grid_coupling(p, i) : pads[p - points].grid[i]; };
    double shift = 0.0;
    for (std::size_t r = 0; r < grid.points.size(); ++r)
        if (grid.solutions[r].force != 0.0) shift += coupling(grid.points[r]) * grid.solutions[r].force;
    if (grid.pads != nullptr) {
        const std::span<const std::size_t> fingers_points = grid.pads->points();
        for (std::size_t r = 0; r < fingers_points.size(); ++r)
            if (s.pad_force[r] != 0.0) shift += coupling(fingers_points[r]) * s.pad_force[r];
    }
    return k * grid.step * shift;
}

template <ContactForceLaw Law>
bool GridNewton::solve_grid(State& s, const Law& law, double k, Grid& grid, std::span<const Pad> pads,
                              std::span<const double> pad_force, const std::vector<double>* height) const {
    bool pushes = false;
    s.pushing.clear();  // (within its reserved room)
    for (std::size_t p = 0; p < contact_->size(); ++p)
        if (s.force[p] != 0.0) s.pushing.push_back(p);
    if (grid.pads != nullptr) {
        // The fingers' pad predictions raised by the points' (and the pads') forces; one trial of their solve.
        const std::span<const std::size_t> fingers_points = grid.pads->points();
        for (std::size_t r = 0; r < fingers_points.size(); ++r) {
            const std::size_t i = fingers_points[r];
            double shift = 0.0;
            for (std::size_t p : s.pushing) shift += contact_->weight(p) * contact_->grid_coupling(p, i) * s.force[p];
            for (std::size_t a = 0; a < pads.size(); ++a)
                if (pad_force[a] != 0.0) shift += pads[a].grid[i] * pad_force[a];
            s.pad_shift[r] = k * shift;
        }
        const auto n = fingers_points.size();
        const std::size_t fingers = grid.pads->heights();
        const auto shift = std::span<const double>(s.pad_shift).first(n);
        const auto force = std::span<double>(s.pad_force).first(n);
        const auto residual = std::span<double>(s.height_residual).first(fingers);
        const auto size = std::span<double>(s.height_size).first(fingers);
        if (height != nullptr)
            grid.pads->trial(shift, std::span<const double>(*height).first(fingers), force, residual, size);
        else
            grid.pads->solve(shift, force, std::span<double>(s.height).first(fingers), residual, size);
        pushes = point_newton::any_push(force);
    }
    for (std::size_t r = 0; r < grid.points.size(); ++r) {
        const std::size_t i = grid.points[r];
        double b = grid.b[r];
        for (std::size_t p : s.pushing) b -= k * contact_->weight(p) * contact_->grid_coupling(p, i) * s.force[p];
        for (std::size_t a = 0; a < pads.size(); ++a)
            if (pad_force[a] != 0.0) b -= k * pads[a].grid[i] * pad_force[a];
        grid.solutions[r] = law.solve(grid.a[r], b, k);
        pushes = pushes || grid.solutions[r].force != 0.0;
    }
    return pushes;
}

template <class Matrix, ContactForceLaw Law>
void GridNewton::grid_response(const State& s, const Law& law, double k,
                       const Grid& grid, std::span<const Pad> pads,
                       std::span<const double> pad_slope, Matrix& jacobian) const {
    const std::vector<std::size_t>& awake = s.awake_list;
    const std::size_t count = awake.size();
    const std::size_t pad_count = pads.size();
    for (std::size_t g = 0; g < grid.points.size(); ++g) {
        const ContactSolution& sol = grid.solutions[g];
        if (sol.force == 0.0 && sol.increment + grid.a[g] <= 0.0 && grid.a[g] <= 0.0) continue;
        const double slope = law.slope_of_quotient(grid.a[g], sol.increment, sol.force);
        const double w = slope / (1.0 + k * slope);
        if (w == 0.0) continue;
        const std::size_t i = grid.points[g];
        const double kkw = k * k * grid.step * w;
        for (std::size_t a = 0; a < count; ++a)
            for (std::size_t c = 0; c < count; ++c) {
                const std::size_t p = awake[a], q = awake[c];
                jacobian(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(c)) -=
                    kkw * contact_->weight(q) * s.slope[q] * contact_->grid_coupling(p, i) * contact_->grid_coupling(q, i);
            }
        for (std::size_t pa = 0; pa < pad_count; ++pa) {
            const double m_i = pads[pa].grid[i];
            const auto e = static_cast<Eigen::Index>(count + pa);
            for (std::size_t a = 0; a < count; ++a) {
                const std::size_t p = awake[a];
                const auto ia = static_cast<Eigen::Index>(a);
                jacobian(ia, e) -= kkw * pad_slope[pa] * contact_->grid_coupling(p, i) * m_i;
                jacobian(e, ia) += kkw * contact_->weight(p) * s.slope[p] * m_i * contact_->grid_coupling(p, i);
            }
            for (std::size_t pb = 0; pb < pad_count; ++pb)
                jacobian(e, static_cast<Eigen::Index>(count + pb)) += kkw * pad_slope[pb] * m_i * pads[pb].grid[i];
        }
    }
}

template <class Matrix>
void GridNewton::pads_jacobian(State& s, double k, const Grid& grid, std::span<const Pad> pads,
                                 std::span<const double> pad_slope, Matrix& jacobian) const {
    // The fingers' part of the Jacobian. Unknown c (a point, a pad) moves the fingers' pad
    // predictions along v (k c_q f_q' M_q. for a point, k F_a' m^a for pad a), their forces by
    // dF_i/dw_i v_i (each pad point's own response: the heights are unknowns of their own), the
    // rows by k dx M_p. (dF/dw v) (a pad's row: minus k dx m^a . (dF/dw v)), and finger f's row
    // by its pull . v. Finger f's height moves its pad's forces by dF_i/ds, its row by its slope.
    const std::span<const std::size_t> points = grid.pads->points();
    const std::size_t n = points.size();
    const std::size_t fingers = grid.pads->heights();
    const std::vector<std::size_t>& awake = s.awake_list;
    const std::size_t count = awake.size();
    const std::size_t columns = count + pads.size();  // (the fingers' come after)
    const std::span<double> response = std::span<double>(s.pad_response).first(n);
    const std::span<double> lift = std::span<double>(s.pad_lift).first(n);
    const std::span<double> pull = std::span<double>(s.pad_pull).first(n);
    grid.pads->slopes(response, lift, pull, std::span<double>(s.height_slope).first(fingers));
    const auto coupling = [&](std::size_t c, std::size_t r) {
        return c >= count ? pads[c - count].grid[points[r]] : contact_->grid_coupling(awake[c], points[r]);
    };
    // Column c's change of the rows through pad points [from, to) moving by moved(r).
    const auto add_rows = [&](Eigen::Index column, std::size_t from, std::size_t to, auto&& moved) {
        for (std::size_t a = 0; a < columns; ++a) {
            double sum = 0.0;
            for (std::size_t r = from; r < to; ++r) sum += coupling(a, r) * moved(r);
            jacobian(static_cast<Eigen::Index>(a), column) += (a >= count ? -1.0 : 1.0) * k * grid.step * sum;
        }
    };
    for (std::size_t c = 0; c < columns; ++c) {
        const double scale = c >= count ? k * pad_slope[c - count] : k * contact_->weight(awake[c]) * s.slope[awake[c]];
        if (scale == 0.0) continue;
        const auto column = static_cast<Eigen::Index>(c);
        add_rows(column, 0, n, [&](std::size_t r) { return response[r] * scale * coupling(c, r); });
        for (std::size_t f = 0, from = 0; f < fingers; from = s.height_end[f++]) {
            double sum = 0.0;
            for (std::size_t r = from; r < s.height_end[f]; ++r) sum += pull[r] * coupling(c, r);
            jacobian(static_cast<Eigen::Index>(columns + f), column) = scale * sum;
        }
    }
    for (std::size_t f = 0, from = 0; f < fingers; from = s.height_end[f++]) {
        const auto column = static_cast<Eigen::Index>(columns + f);
        add_rows(column, from, s.height_end[f], [&](std::size_t r) { return lift[r]; });
        jacobian(column, column) = s.height_slope[f];
    }
}

template <ContactForceLaw Law>
double GridNewton::joint_residual(State& s, const Law& law, double k, Grid& grid, std::span<const Pad> pads,
                                    const std::vector<double>& at, std::span<const double> at_x,
                                    const std::vector<double>& at_height, bool solve, double scale) const {
    const std::vector<std::size_t>& awake = s.awake_list;
    const std::size_t pad_count = pads.size();
    const std::size_t fingers = grid.pads != nullptr ? grid.pads->heights() : 0;
    const auto room = [&](std::vector<double>& v) { return std::span<double>(v).first(pad_count); };
    const std::span<double> pad_force = room(s.press_force), pad_slope = room(s.press_slope),
                            pad_residual = room(s.press_residual);
    for (std::size_t q : awake) s.quotient[q] = law.difference_quotient(s.eta_prev[q], at[q]);
    for (std::size_t a = 0; a < pad_count; ++a) pads[a].press->force_and_slope(at_x[a], pad_force[a], pad_slope[a]);
    if (solve) {
        // (the grid reads the points' forces from s.force: the quotients, for this evaluation)
        std::swap(s.force, s.quotient);
        solve_grid(s, law, k, grid, pads, pad_force, &at_height);
        std::swap(s.force, s.quotient);
    }
    double largest = 0.0;
    for (std::size_t p : awake) {
        double push = 0.0;
        for (std::size_t q : awake) push += contact_->gram(p, q) * s.quotient[q];
        for (std::size_t a = 0; a < pad_count; ++a) push += pads[a].coupling[p] * pad_force[a];
        s.residual[p] = at[p] + k * push + grid_push(s, k, grid, p, pads) - s.b[p];
        largest = std::max(largest, std::abs(s.residual[p]));
    }
    for (std::size_t a = 0; a < pad_count; ++a) {
        double push = 0.0;
        for (std::size_t q : awake) push += contact_->weight(q) * pads[a].coupling[q] * s.quotient[q];
        for (std::size_t b = 0; b < pad_count; ++b) push += point_newton::cross(pads, a, b) * pad_force[b];
        pad_residual[a] = at_x[a] - pads[a].predicted - k * push - grid_push(s, k, grid, contact_->size() + a, pads);
        largest = std::max(largest, std::abs(pad_residual[a]));
    }
    // A finger's equation rounds relative to its own size (a stiff pad's slope times the
    // finger's height): measured against the points' scale, its floor at theirs.
    for (std::size_t f = 0; f < fingers; ++f) {
        const double size = s.height_size[f];
        largest = std::max(largest, std::abs(s.height_residual[f]) * (size > scale ? scale / size : 1.0));
    }
    return largest;
}

template <class Vector, ContactForceLaw Law>
bool GridNewton::joint_step(State& s, const Law& law, double k, Grid& grid, std::span<const Pad> pads,
                              const Vector& step, std::span<double> x, double& norm, double scale) const {
    const std::vector<std::size_t>& awake = s.awake_list;
    const std::size_t count = awake.size();
    const std::size_t pad_count = pads.size();
    const std::size_t fingers = grid.pads != nullptr ? grid.pads->heights() : 0;
    const std::size_t first_height = count + pad_count;
    std::vector<double>& r = s.increment;
    // joint_residual swaps s.force with s.quotient: the trial point lives in a vector of its own.
    std::vector<double>& candidate = s.candidate;
    const std::span<double> trial_x = std::span<double>(s.press_trial).first(pad_count);
    double t = 1.0, trial_norm = 0.0;
    // Backtracking is for the kink of [eta]_+ far from the solution; near it, a full Newton
    // step that does not lower the residual finds it at its round-off floor (a stiff pad's
    // force rounds to its slope times eps |u|, far above eps times the unknowns).
    const int halvings = norm <= 1e-9 * scale ? 1 : 40;
    for (int halving = 0; halving < halvings; ++halving, t *= 0.5) {
        for (std::size_t a = 0; a < count; ++a) candidate[awake[a]] = r[awake[a]] + t * step(static_cast<Eigen::Index>(a));
        for (std::size_t a = 0; a < pad_count; ++a) trial_x[a] = x[a] + t * step(static_cast<Eigen::Index>(count + a));
        for (std::size_t f = 0; f < fingers; ++f)
            s.height_candidate[f] = s.height[f] + t * step(static_cast<Eigen::Index>(first_height + f));
        trial_norm = joint_residual(s, law, k, grid, pads, candidate, trial_x, s.height_candidate, true, scale);
        if (trial_norm < norm) {
            r.swap(candidate);
            s.height.swap(s.height_candidate);
            std::copy(trial_x.begin(), trial_x.end(), x.begin());
            norm = trial_norm;
            return true;
        }
    }
    if (trial_norm <= 2.0 * norm && point_newton::converged(trial_norm, step, true, scale)) {
        // At the round-off floor, the last trial as good as r: it is the one evaluated
        // (the fingers' state is its trial's), so it is the answer.
        r.swap(candidate);
        s.height.swap(s.height_candidate);
        std::copy(trial_x.begin(), trial_x.end(), x.begin());
        norm = trial_norm;
    } else {
        joint_residual(s, law, k, grid, pads, r, x, s.height, true, scale);  // back to r's quotients and grid solutions
    }
    return false;
}

// Newton on the points' increments r_p (and each pad's x_a, and the fingers' height steps),
// the grid's equations solved inside each evaluation (w_i = f_i' / (1 + k f_i') their
// response to a push), and the fingers' pad points too (GridPads: their forces join the
// grid's in R_p and R_a, each finger's equation is a row; pads_jacobian their part of J):
//     R_p = r_p + k sum_q G_pq f_q + k dx sum_i M_pi f_i + k sum_a h^a_p F_a(x_a) - b_p,
//     R_a = x_a - w_a - k sum_q c_q h^a_q f_q - k sum_b (s_a . s_b) F_b(x_b) - k dx sum_i m^a_i f_i,
//     dR_p/dr_q = delta_pq + k G_pq f_q' - k^2 dx c_q f_q' sum_i M_pi M_qi w_i,
//     dR_p/dx_a = k h^a_p F_a' - k^2 dx F_a' sum_i M_pi m^a_i w_i,
//     dR_a/dr_q = -k c_q h^a_q f_q' + k^2 dx c_q f_q' sum_i m^a_i M_qi w_i,
//     dR_a/dx_b = delta_ab - k (s_a . s_b) F_b' + k^2 dx F_b' sum_i m^a_i m^b_i w_i.
// evaluated: s (and grid.solutions) hold the evaluation at s.increment, the pads' x and s.height.
template <class Matrix, ContactForceLaw Law>
bool GridNewton::solve_with_grid(State& s, const Law& law, double k, Grid& grid, std::span<Pad> pads,
                                   bool evaluated, bool may_fail) const {
    double scale = points_.newton_scale(s);
    const std::vector<std::size_t>& awake = s.awake_list;
    const std::size_t count = awake.size();
    const std::size_t pad_count = pads.size();
    const std::size_t fingers = grid.pads != nullptr ? grid.pads->heights() : 0;
    for (std::size_t f = 0; f < fingers; ++f) s.height_end[f] = grid.pads->end(f);
    const std::size_t first_height = count + pad_count;
    const auto m = static_cast<Eigen::Index>(first_height + fingers);
    Matrix jacobian(m, m);
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, Matrix::MaxRowsAtCompileTime, 1> step(m);
    std::vector<double>& r = s.increment;
    // Each pad's unknown x and dF/dx (joint_residual forms them, with F(x) and the residual).
    const std::span<double> x = std::span<double>(s.press_x).first(pad_count);
    const std::span<const double> pad_slope = std::span<double>(s.press_slope).first(pad_count);
    const std::span<const double> pad_residual = std::span<double>(s.press_residual).first(pad_count);
    for (std::size_t a = 0; a < pad_count; ++a) {
        x[a] = pads[a].x;
        scale = std::max({scale, std::abs(pads[a].predicted), std::abs(x[a])});
    }
    const double tolerance = 4.0 * std::numeric_limits<double>::epsilon() * scale;
    std::copy(r.begin(), r.end(), s.candidate.begin());
    double norm = joint_residual(s, law, k, grid, pads, r, x, s.height, !evaluated, scale);
    int iteration = 0;
    bool stalled = false;
    // (a start carried on from the last steps that needs more than a few iterations is a poor one)
    const int iterations = may_fail ? 8 : point_newton::kMaxNewton;
    for (; iteration < iterations && norm > tolerance; ++iteration) {
        points_.points_jacobian(s, law, k, r, jacobian);
        points_.pad_border(s, k, pads, pad_slope, jacobian);
        if (fingers > 0) {
            jacobian.bottomRows(static_cast<Eigen::Index>(fingers)).setZero();
            jacobian.rightCols(static_cast<Eigen::Index>(fingers)).setZero();
        }
        grid_response(s, law, k, grid, pads, pad_slope, jacobian);
        if (grid.pads != nullptr) pads_jacobian(s, k, grid, pads, pad_slope, jacobian);
        for (std::size_t a = 0; a < count; ++a) step(static_cast<Eigen::Index>(a)) = -s.residual[awake[a]];
        for (std::size_t a = 0; a < pad_count; ++a) step(static_cast<Eigen::Index>(count + a)) = -pad_residual[a];
        for (std::size_t f = 0; f < fingers; ++f) step(static_cast<Eigen::Index>(first_height + f)) = -s.height_residual[f];
        step = Eigen::PartialPivLU<Matrix>(jacobian).solve(step);
        if (!joint_step(s, law, k, grid, pads, step, x, norm, scale)) {
            stalled = true;
            break;
        }
    }
    // (a held note's start: taken only where Newton got to round-off, as it does from a good one)
    if (may_fail && !(norm <= tolerance || (stalled && point_newton::converged(norm, step, stalled, scale)))) return false;
    if (!point_newton::converged(norm, step, stalled, scale)) {
        throw SolverError("point contact: the joint Newton solve of " + std::to_string(count) + " points, " +
                          std::to_string(pad_count) + " pads and the grid's obstacle points did not converge (residual " +
                          std::to_string(norm) + " m)");
    }
    s.iterations = std::max(s.iterations, iteration);
    for (std::size_t p : awake) s.force[p] = s.quotient[p];
    for (std::size_t a = 0; a < pad_count; ++a) pads[a].x = x[a];
    return true;
}

}  // namespace fretbuzz
