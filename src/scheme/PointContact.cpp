#include "fretbuzz/scheme/PointContact.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

#include "GridNewton.hpp"
#include "PointNewton.hpp"
#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/scheme/PenaltyContact.hpp"

namespace fretbuzz {

namespace {
// Points whose rows are orthogonal to this (on distinct grid points: round-off) are solved alone.
constexpr double kUncoupled = 1e-12;
using point_newton::any_push;
using point_newton::kSmall;
using point_newton::pad_force_at;
using point_newton::SmallMatrix;
}  // namespace

PointContact::PointContact(const ModalBasis& basis, std::vector<PointObstacle> points, bool grid_coupled)
    : points_(std::move(points)) {
    const std::size_t count = points_.size();
    const std::size_t n = basis.mode_count();
    for (const PointObstacle& p : points_) {
        rows_.push_back(basis.mode_shapes_at(p.x_m));
        heights_.push_back(p.height_m);
    }
    planned_heights_ = heights_;
    gram_.resize(count * count);
    for (std::size_t p = 0; p < count; ++p)
        for (std::size_t q = 0; q < count; ++q)
            gram_[p * count + q] = points_[q].weight_m * kernels::dot(rows_[p].data(), rows_[q].data(), n);
    for (std::size_t p = 0; p < count; ++p)
        for (std::size_t q = 0; q < count; ++q)
            if (p != q && std::abs(gram(p, q)) > kUncoupled * std::sqrt(gram(p, p) * gram(q, q))) coupled_ = true;
    if (grid_coupled) {
        // M_pi = sum_j S_ij phi_j(x_p): each point's row taken to the grid (one transform each, once).
        grid_points_ = n;
        grid_rows_.resize(count * n);
        for (std::size_t p = 0; p < count; ++p)
            basis.to_grid(rows_[p], std::span<double>(grid_rows_).subspan(p * n, n));
    }
}

void PointContact::set_offset(double offset) {
    for (std::size_t p = 0; p < heights_.size(); ++p)
        heights_[p] = std::min(planned_heights_[p] + offset, std::max(planned_heights_[p], 0.0));
}

PointContact::State PointContact::make_state(std::size_t pads) const {
    State s;
    for (std::vector<double>* v : {&s.press_x, &s.press_force, &s.press_slope, &s.press_residual, &s.press_trial, &s.press_moved, &s.press_own})
        v->assign(pads, 0.0);
    for (std::vector<double>* v : {&s.eta_before, &s.eta_prev, &s.eta_curr, &s.force, &s.increment, &s.b, &s.quotient, &s.slope, &s.residual, &s.candidate})
        v->assign(size(), 0.0);
    for (std::vector<double>* v : {&s.pad_shift, &s.pad_force, &s.pad_response, &s.pad_lift, &s.pad_pull, &s.height,
                                   &s.height_candidate, &s.height_residual, &s.height_size, &s.height_slope})
        v->assign(grid_points_, 0.0);
    s.resting.assign(size(), 0);
    s.awake_list.reserve(size());
    s.pushing.reserve(size());
    s.height_end.assign(grid_points_, 0);
    s.awake = size();
    return s;
}

namespace {
// A resting point's eta: far enough apart that no step can bring it to contact.
constexpr double kRestingEta = -1.0;
}  // namespace

void PointContact::rest(State& s, std::size_t p) const {
    if (s.resting[p] != 0) return;
    s.resting[p] = 1;
    --s.awake;
    s.eta_before[p] = s.eta_prev[p] = s.eta_curr[p] = kRestingEta;
    s.force[p] = 0.0;
}

void PointContact::wake(State& s, std::size_t p, std::span<const double> q, std::span<const double> d) const {
    double u_now = 0.0, u_before = 0.0;
    kernels::dot_current_previous(rows_[p].data(), q.data(), d.data(), q.size(), u_now, u_before);
    s.eta_curr[p] = heights_[p] - u_now;
    s.eta_prev[p] = heights_[p] - u_before;
    s.eta_before[p] = kRestingEta;  // (not known: no start from it)
    if (s.resting[p] != 0) ++s.awake;
    s.resting[p] = 0;
}

void PointContact::start(State& s, std::span<const double> q, std::span<const double> d) const {
    for (std::size_t p = 0; p < size(); ++p) {
        wake(s, p, q, d);
        s.force[p] = 0.0;
    }
}

template <ContactForceLaw Law>
bool PointContact::solve(State& s, std::span<const double> predicted, const Law& law, double k,
                         std::span<Pad> pads) const {
    solve_points(s, predicted, law, k, pads);
    return commit(s);
}

template <ContactForceLaw Law>
void PointContact::solve_points(State& s, std::span<const double> predicted, const Law& law, double k,
                                std::span<Pad> pads, bool held) const {
    if (pads.size() > s.press_x.size()) throw std::logic_error("PointContact: more pads than its state has room for");
    const std::size_t count = size();
    s.iterations = 0;
    s.prediction_size = 0.0;
    // Each point alone first: the answer where the points do not couple, else Newton's start.
    for (std::size_t p = 0; p < count; ++p) {
        const double a = s.eta_prev[p];
        if (s.resting[p] != 0) {  // (its prediction was not formed)
            s.b[p] = s.increment[p] = s.force[p] = 0.0;
            continue;
        }
        s.b[p] = heights_[p] - predicted[p] - a;
        s.prediction_size = std::max({s.prediction_size, std::abs(heights_[p]), std::abs(predicted[p])});
        if (held && s.eta_curr[p] > 0.0) {
            // Newton's start where the point is held in contact: eta^{n+1} extrapolated from the
            // last three levels (two where it touched at only two).
            s.increment[p] = s.eta_prev[p] > 0.0 && s.eta_before[p] > 0.0
                                 ? 3.0 * s.eta_curr[p] - 4.0 * s.eta_prev[p] + s.eta_before[p]
                                 : 2.0 * (s.eta_curr[p] - s.eta_prev[p]);
            continue;
        }
        const ContactSolution alone = law.solve(a, s.b[p], k * gram(p, p));
        s.increment[p] = alone.increment;
        s.force[p] = alone.force;
        s.iterations = std::max(s.iterations, alone.iterations);
    }
    if (held) return;  // (the joint solve follows)
    const long touching = std::count_if(s.force.begin(), s.force.end(), [](double f) { return f != 0.0; });
    bool pressed = false;
    for (const Pad& pad : pads) pressed = pressed || pad_force_at(pad, pad.x) != 0.0;
    // The pads move every point they overlap in mode space, and one another; the points move them.
    // (A single pad with no point awake: its own solution.)
    if (!pads.empty() && (s.awake > 0 || pads.size() > 1) && (pressed || touching > 0)) {
        if (s.awake + pads.size() <= static_cast<std::size_t>(kSmall))
            PointNewton(*this).solve_coupled<SmallMatrix>(s, law, k, pads);
        else
            PointNewton(*this).solve_coupled<Eigen::MatrixXd>(s, law, k, pads);
    } else if (coupled_ && touching > 0 && count > 1) {
        if (s.awake <= static_cast<std::size_t>(kSmall))
            PointNewton(*this).solve_coupled<SmallMatrix>(s, law, k, {});
        else
            PointNewton(*this).solve_coupled<Eigen::MatrixXd>(s, law, k, {});
    }
}

bool PointContact::commit(State& s) const {
    for (std::size_t p = 0; p < size(); ++p) {
        const double eta_next = s.eta_prev[p] + s.increment[p];
        s.eta_before[p] = s.eta_prev[p];
        s.eta_prev[p] = s.eta_curr[p];
        s.eta_curr[p] = eta_next;
    }
    return any_push(s.force);
}

template <ContactForceLaw Law>
bool PointContact::solve(State& s, std::span<const double> predicted, const Law& law, double k, Grid& grid,
                         std::span<Pad> pads) const {
    // A held note (the last step needed the joint solve): Newton at once, from the last step's
    // motion carried on (eta in contact at its last rate, the fingers' last height steps in
    // s.height), not from each side's own solution.
    const bool held = grid.pads != nullptr && s.joint;
    const GridNewton newton(*this);
    solve_points(s, predicted, law, k, pads, held);
    const auto pads_press = [&] {
        return std::any_of(pads.begin(), pads.end(), [](const Pad& pad) { return pad_force_at(pad, pad.x) != 0.0; });
    };
    if (held) {
        grid.pads->guess(std::span<double>(s.height).first(grid.pads->heights()));
        const bool solved = s.awake + pads.size() + grid.pads->heights() <= static_cast<std::size_t>(kSmall)
                                ? newton.solve_with_grid<SmallMatrix>(s, law, k, grid, pads, false, true)
                                : newton.solve_with_grid<Eigen::MatrixXd>(s, law, k, grid, pads, false, true);
        if (solved) {
            // Still joint where both sides push at the solution.
            const bool points_push = pads_press() || any_push(s.force);
            bool grid_pushes = any_push(std::span<const double>(s.pad_force).first(grid.pads->points().size()));
            for (const ContactSolution& g : grid.solutions) grid_pushes = grid_pushes || g.force != 0.0;
            s.joint = points_push && grid_pushes;
            return commit(s);
        }
        // Not from that start (a note let go or struck anew): from each side's own solution.
        solve_points(s, predicted, law, k, pads);
    }
    const std::span<double> pad_force = std::span<double>(s.press_own).first(pads.size());
    for (std::size_t a = 0; a < pads.size(); ++a) pad_force[a] = pad_force_at(pads[a], pads[a].x);
    const bool points_push = any_push(pad_force) || any_push(s.force);
    const bool grid_pushes = newton.solve_grid(s, law, k, grid, pads, pad_force);
    // Apart, each side's solution is the joint one if the other's push leaves it as it is: the
    // grid solved with the points' (and the pad's) forces already; the points and the pad, with
    // no force of their own, need the grid's push to leave them apart.
    bool joint = points_push && grid_pushes;
    if (grid_pushes && !points_push) {
        // The grid's (and the fingers' pads') push at u(x_p) and at each pad's u_s.
        for (std::size_t p = 0; p < size() && !joint; ++p) {
            s.quotient[p] = s.increment[p] - newton.grid_push(s, k, grid, p, pads);
            joint = law.difference_quotient(s.eta_prev[p], s.quotient[p]) != 0.0;
        }
        const std::span<double> pad_x = std::span<double>(s.press_moved).first(pads.size());
        for (std::size_t a = 0; a < pads.size() && !joint; ++a) {
            pad_x[a] = pads[a].x + newton.grid_push(s, k, grid, size() + a, pads);
            joint = pad_force_at(pads[a], pad_x[a]) != 0.0;
        }
        if (!joint) {
            for (std::size_t p = 0; p < size(); ++p) s.increment[p] = s.quotient[p];
            for (std::size_t a = 0; a < pads.size(); ++a) pads[a].x = pad_x[a];
        }
    }
    s.joint = joint;
    if (joint) {  // (from the evaluation just made: the points' own solutions, the fingers' own solves)
        const std::size_t heights = grid.pads != nullptr ? grid.pads->heights() : 0;
        if (s.awake + pads.size() + heights <= static_cast<std::size_t>(kSmall))
            newton.solve_with_grid<SmallMatrix>(s, law, k, grid, pads, true);
        else
            newton.solve_with_grid<Eigen::MatrixXd>(s, law, k, grid, pads, true);
    }
    return commit(s);
}

template <ContactForceLaw Law>
double PointContact::potential(const State& s, const Law& law, bool current) const {
    double sum = 0.0;
    for (std::size_t p = 0; p < size(); ++p)
        if (const double eta = current ? s.eta_curr[p] : s.eta_prev[p]; eta > 0.0)  // (Psi = 0 apart)
            sum += points_[p].weight_m * law.potential(eta);
    return sum;
}

void PointContact::add_impulse(const State& s, double k, std::span<double> impulse) const {
    for (std::size_t p = 0; p < size(); ++p)
        if (s.force[p] != 0.0) kernels::axpy(k * points_[p].weight_m * s.force[p], rows_[p].data(), impulse.data(), impulse.size());
}

// The laws the scheme plans with.
template bool PointContact::solve(State&, std::span<const double>, const PenaltyContact&, double, std::span<Pad>) const;
template bool PointContact::solve(State&, std::span<const double>, const PenaltyContact&, double, Grid&,
                                  std::span<Pad>) const;
template double PointContact::potential(const State&, const PenaltyContact&, bool) const;

}  // namespace fretbuzz
