#include "fretbuzz/scheme/PointContact.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/scheme/PenaltyContact.hpp"

namespace fretbuzz {

namespace {
// Points whose rows are orthogonal to this (on distinct grid points: round-off) are solved alone.
constexpr double kUncoupled = 1e-12;
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
bool PointContact::solve(State& s, std::span<const double> predicted, const Law& law, double k) const {
    return solve(s, predicted, law, k, std::span<Pad>());
}

template <ContactForceLaw Law>
bool PointContact::solve(State& s, std::span<const double> predicted, const Law& law, double k,
                         std::span<Pad> pads) const {
    solve_points(s, predicted, law, k, pads);
    return commit(s);
}

namespace {
// s_a . s_b of pads a and b of one solve.
double cross(std::span<const PointContact::Pad> pads, std::size_t a, std::size_t b) {
    return a == b ? pads[a].self : pads[a].cross[b];
}

double pad_force_at(const PointContact::Pad& pad, double x) {
    double force = 0.0, slope = 0.0;
    pad.press->force_and_slope(x, force, slope);
    return force;
}
}  // namespace

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
            solve_coupled<SmallMatrix>(s, law, k, pads);
        else
            solve_coupled<Eigen::MatrixXd>(s, law, k, pads);
    } else if (coupled_ && touching > 0 && count > 1) {
        if (s.awake <= static_cast<std::size_t>(kSmall))
            solve_coupled<SmallMatrix>(s, law, k, {});
        else
            solve_coupled<Eigen::MatrixXd>(s, law, k, {});
    }
}

namespace {
// Whether any of these forces acts.
bool any_push(std::span<const double> forces) {
    return std::any_of(forces.begin(), forces.end(), [](double f) { return f != 0.0; });
}
}  // namespace

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
bool PointContact::solve(State& s, std::span<const double> predicted, const Law& law, double k, Grid& grid) const {
    return solve(s, predicted, law, k, grid, std::span<Pad>());
}

template <ContactForceLaw Law>
bool PointContact::solve(State& s, std::span<const double> predicted, const Law& law, double k, Grid& grid,
                         std::span<Pad> pads) const {
    // A held note (the last step needed the joint solve): Newton at once, from the last step's
    // motion carried on (eta in contact at its last rate, the fingers' last height steps in
    // s.height), not from each side's own solution.
    const bool held = grid.pads != nullptr && s.joint;
    solve_points(s, predicted, law, k, pads, held);
    const auto pads_press = [&] {
        return std::any_of(pads.begin(), pads.end(), [](const Pad& pad) { return pad_force_at(pad, pad.x) != 0.0; });
    };
    if (held) {
        grid.pads->guess(std::span<double>(s.height).first(grid.pads->heights()));
        const bool solved = s.awake + pads.size() + grid.pads->heights() <= static_cast<std::size_t>(kSmall)
                                ? solve_with_grid<SmallMatrix>(s, law, k, grid, pads, false, true)
                                : solve_with_grid<Eigen::MatrixXd>(s, law, k, grid, pads, false, true);
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
    const bool grid_pushes = solve_grid(s, law, k, grid, pads, pad_force);
    // Apart, each side's solution is the joint one if the other's push leaves it as it is: the
    // grid solved with the points' (and the pad's) forces already; the points and the pad, with
    // no force of their own, need the grid's push to leave them apart.
    bool joint = points_push && grid_pushes;
    if (grid_pushes && !points_push) {
        // The grid's (and the fingers' pads') push at u(x_p) and at each pad's u_s.
        for (std::size_t p = 0; p < size() && !joint; ++p) {
            s.quotient[p] = s.increment[p] - grid_push(s, k, grid, p, pads);
            joint = law.difference_quotient(s.eta_prev[p], s.quotient[p]) != 0.0;
        }
        const std::span<double> pad_x = std::span<double>(s.press_moved).first(pads.size());
        for (std::size_t a = 0; a < pads.size() && !joint; ++a) {
            pad_x[a] = pads[a].x + grid_push(s, k, grid, size() + a, pads);
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
            solve_with_grid<SmallMatrix>(s, law, k, grid, pads, true);
        else
            solve_with_grid<Eigen::MatrixXd>(s, law, k, grid, pads, true);
    }
    return commit(s);
}

double PointContact::grid_push(const State& s, double k, const Grid& grid, std::size_t p, std::span<const Pad> pads) const {
    const auto coupling = [&](std::size_t i) { return p < size() ? grid_coupling(p, i) : pads[p - size()].grid[i]; };
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
bool PointContact::solve_grid(State& s, const Law& law, double k, Grid& grid, std::span<const Pad> pads,
                              std::span<const double> pad_force, const std::vector<double>* height) const {
    bool pushes = false;
    s.pushing.clear();  // (within its reserved room)
    for (std::size_t p = 0; p < size(); ++p)
        if (s.force[p] != 0.0) s.pushing.push_back(p);
    if (grid.pads != nullptr) {
        // The fingers' pad predictions raised by the points' (and the pads') forces; one trial of their solve.
        const std::span<const std::size_t> fingers_points = grid.pads->points();
        for (std::size_t r = 0; r < fingers_points.size(); ++r) {
            const std::size_t i = fingers_points[r];
            double shift = 0.0;
            for (std::size_t p : s.pushing) shift += points_[p].weight_m * grid_coupling(p, i) * s.force[p];
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
        pushes = any_push(force);
    }
    for (std::size_t r = 0; r < grid.points.size(); ++r) {
        const std::size_t i = grid.points[r];
        double b = grid.b[r];
        for (std::size_t p : s.pushing) b -= k * points_[p].weight_m * grid_coupling(p, i) * s.force[p];
        for (std::size_t a = 0; a < pads.size(); ++a)
            if (pad_force[a] != 0.0) b -= k * pads[a].grid[i] * pad_force[a];
        grid.solutions[r] = law.solve(grid.a[r], b, k);
        pushes = pushes || grid.solutions[r].force != 0.0;
    }
    return pushes;
}

double PointContact::newton_scale(State& s) const {
    // The awake points (a resting one is apart and stays so: its force is zero whatever the
    // others do, and no equation of the others reads its unknown), and the size of their
    // unknowns, which Newton's tolerance is relative to.
    s.awake_list.clear();
    double scale = std::numeric_limits<double>::min();
    for (std::size_t p = 0; p < size(); ++p) {
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
void PointContact::points_jacobian(State& s, const Law& law, double k, const std::vector<double>& r,
                                   Matrix& jacobian) const {
    // J = I + k G diag(d f_q / d r_q) over the awake points, at r's quotients
    const std::vector<std::size_t>& awake = s.awake_list;
    for (std::size_t q : awake) s.slope[q] = law.slope_of_quotient(s.eta_prev[q], r[q], s.quotient[q]);
    for (std::size_t a = 0; a < awake.size(); ++a)
        for (std::size_t c = 0; c < awake.size(); ++c)
            jacobian(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(c)) =
                (a == c ? 1.0 : 0.0) + k * gram(awake[a], awake[c]) * s.slope[awake[c]];
}

template <class Matrix>
void PointContact::pad_border(const State& s, double k, std::span<const Pad> pads, std::span<const double> pad_slope,
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
            jacobian(e, i) = -k * points_[p].weight_m * pads[a].coupling[p] * s.slope[p];
        }
        for (std::size_t b = 0; b < pads.size(); ++b)
            jacobian(e, static_cast<Eigen::Index>(count + b)) = (a == b ? 1.0 : 0.0) - k * cross(pads, a, b) * pad_slope[b];
    }
}

template <class Matrix>
void PointContact::pads_jacobian(State& s, double k, const Grid& grid, std::span<const Pad> pads,
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
        return c >= count ? pads[c - count].grid[points[r]] : grid_coupling(awake[c], points[r]);
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
        const double scale = c >= count ? k * pad_slope[c - count] : k * points_[awake[c]].weight_m * s.slope[awake[c]];
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

namespace {
// The grid's part of the joint Jacobian (solve_with_grid's k^2 dx terms): each of its points in
// contact responds to a push by w_i = f_i' / (1 + k f_i'), which moves the points' and the pads'
// rows through their couplings M_pi and m^a_i.
template <class Matrix, ContactForceLaw Law>
void add_grid_response(const PointContact& contact, const PointContact::State& s, const Law& law, double k,
                       const PointContact::Grid& grid, std::span<const PointContact::Pad> pads,
                       std::span<const double> pad_slope, Matrix& jacobian) {
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
                    kkw * contact.weight(q) * s.slope[q] * contact.grid_coupling(p, i) * contact.grid_coupling(q, i);
            }
        for (std::size_t pa = 0; pa < pad_count; ++pa) {
            const double m_i = pads[pa].grid[i];
            const auto e = static_cast<Eigen::Index>(count + pa);
            for (std::size_t a = 0; a < count; ++a) {
                const std::size_t p = awake[a];
                const auto ia = static_cast<Eigen::Index>(a);
                jacobian(ia, e) -= kkw * pad_slope[pa] * contact.grid_coupling(p, i) * m_i;
                jacobian(e, ia) += kkw * contact.weight(p) * s.slope[p] * m_i * contact.grid_coupling(p, i);
            }
            for (std::size_t pb = 0; pb < pad_count; ++pb)
                jacobian(e, static_cast<Eigen::Index>(count + pb)) += kkw * pad_slope[pb] * m_i * pads[pb].grid[i];
        }
    }
}
}  // namespace

template <ContactForceLaw Law>
double PointContact::joint_residual(State& s, const Law& law, double k, Grid& grid, std::span<const Pad> pads,
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
        for (std::size_t q : awake) push += gram(p, q) * s.quotient[q];
        for (std::size_t a = 0; a < pad_count; ++a) push += pads[a].coupling[p] * pad_force[a];
        s.residual[p] = at[p] + k * push + grid_push(s, k, grid, p, pads) - s.b[p];
        largest = std::max(largest, std::abs(s.residual[p]));
    }
    for (std::size_t a = 0; a < pad_count; ++a) {
        double push = 0.0;
        for (std::size_t q : awake) push += points_[q].weight_m * pads[a].coupling[q] * s.quotient[q];
        for (std::size_t b = 0; b < pad_count; ++b) push += cross(pads, a, b) * pad_force[b];
        pad_residual[a] = at_x[a] - pads[a].predicted - k * push - grid_push(s, k, grid, size() + a, pads);
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
bool PointContact::joint_step(State& s, const Law& law, double k, Grid& grid, std::span<const Pad> pads,
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
    if (trial_norm <= 2.0 * norm && converged(trial_norm, step, true, scale)) {
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
bool PointContact::solve_with_grid(State& s, const Law& law, double k, Grid& grid, std::span<Pad> pads,
                                   bool evaluated, bool may_fail) const {
    double scale = newton_scale(s);
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
    const int iterations = may_fail ? 8 : kMaxNewton;
    for (; iteration < iterations && norm > tolerance; ++iteration) {
        points_jacobian(s, law, k, r, jacobian);
        pad_border(s, k, pads, pad_slope, jacobian);
        if (fingers > 0) {
            jacobian.bottomRows(static_cast<Eigen::Index>(fingers)).setZero();
            jacobian.rightCols(static_cast<Eigen::Index>(fingers)).setZero();
        }
        add_grid_response(*this, s, law, k, grid, pads, pad_slope, jacobian);
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
    if (may_fail && !(norm <= tolerance || (stalled && converged(norm, step, stalled, scale)))) return false;
    if (!converged(norm, step, stalled, scale)) {
        throw SolverError("point contact: the joint Newton solve of " + std::to_string(count) + " points, " +
                          std::to_string(pad_count) + " pads and the grid's obstacle points did not converge (residual " +
                          std::to_string(norm) + " m)");
    }
    s.iterations = std::max(s.iterations, iteration);
    for (std::size_t p : awake) s.force[p] = s.quotient[p];
    for (std::size_t a = 0; a < pad_count; ++a) pads[a].x = x[a];
    return true;
}

template <class Matrix, ContactForceLaw Law>
void PointContact::solve_coupled(State& s, const Law& law, double k, std::span<Pad> pads) const {
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
            for (std::size_t q : awake) push += gram(p, q) * s.quotient[q];
            for (std::size_t a = 0; a < pad_count; ++a) push += pads[a].coupling[p] * pad_force[a];
            s.residual[p] = r[p] + k * push - s.b[p];
            largest = std::max(largest, std::abs(s.residual[p]));
        }
        for (std::size_t a = 0; a < pad_count; ++a) {
            double push = 0.0;
            for (std::size_t q : awake) push += points_[q].weight_m * pads[a].coupling[q] * s.quotient[q];
            for (std::size_t b = 0; b < pad_count; ++b) push += cross(pads, a, b) * pad_force[b];
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
    for (; iteration < kMaxNewton && norm > tolerance; ++iteration) {
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
    if (!converged(norm, step, stalled, scale))
        throw SolverError("point contact: the coupled Newton solve of " + std::to_string(count) + " points and " +
                          std::to_string(pad_count) + " pads did not converge (residual " + std::to_string(norm) + " m)");
    s.iterations = std::max(s.iterations, iteration);
    for (std::size_t p = 0; p < size(); ++p) s.force[p] = s.quotient[p];
    for (std::size_t a = 0; a < pad_count; ++a) pads[a].x = x[a];
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
template bool PointContact::solve(State&, std::span<const double>, const PenaltyContact&, double) const;
template bool PointContact::solve(State&, std::span<const double>, const PenaltyContact&, double, std::span<Pad>) const;
template bool PointContact::solve(State&, std::span<const double>, const PenaltyContact&, double, Grid&) const;
template bool PointContact::solve(State&, std::span<const double>, const PenaltyContact&, double, Grid&,
                                  std::span<Pad>) const;
template double PointContact::potential(const State&, const PenaltyContact&, bool) const;

}  // namespace fretbuzz
