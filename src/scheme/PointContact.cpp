#include "fretbuzz/scheme/PointContact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Dense>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/Kernels.hpp"

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

PointContact::State PointContact::make_state() const {
    State s;
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

bool PointContact::solve(State& s, std::span<const double> predicted, const PenaltyContact& law, double k) const {
    return solve(s, predicted, law, k, nullptr);
}

bool PointContact::solve(State& s, std::span<const double> predicted, const PenaltyContact& law, double k, Pad& pad) const {
    return solve(s, predicted, law, k, &pad);
}

bool PointContact::solve(State& s, std::span<const double> predicted, const PenaltyContact& law, double k, Pad* pad) const {
    solve_points(s, predicted, law, k, pad);
    return commit(s);
}

void PointContact::solve_points(State& s, std::span<const double> predicted, const PenaltyContact& law, double k, Pad* pad,
                                bool held) const {
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
    if (pad != nullptr) {
        double force = 0.0, slope = 0.0;
        pad->press->force_and_slope(pad->x, force, slope);
        pressed = force != 0.0;
    }
    // The pad moves every point it overlaps in mode space, and they move it.
    if (pad != nullptr && s.awake > 0 && (pressed || touching > 0)) {  // (no point awake: the pad's own solution)
        if (s.awake + 1 <= static_cast<std::size_t>(kSmall))
            solve_coupled<SmallMatrix>(s, law, k, pad);
        else
            solve_coupled<Eigen::MatrixXd>(s, law, k, pad);
    } else if (coupled_ && touching > 0 && count > 1) {
        if (s.awake <= static_cast<std::size_t>(kSmall))
            solve_coupled<SmallMatrix>(s, law, k, nullptr);
        else
            solve_coupled<Eigen::MatrixXd>(s, law, k, nullptr);
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

namespace {
double pad_force_at(const PointContact::Pad* pad, double x) {
    double force = 0.0, slope = 0.0;
    if (pad != nullptr) pad->press->force_and_slope(x, force, slope);
    return force;
}
}  // namespace

bool PointContact::solve(State& s, std::span<const double> predicted, const PenaltyContact& law, double k, Grid& grid) const {
    return solve(s, predicted, law, k, grid, nullptr);
}

bool PointContact::solve(State& s, std::span<const double> predicted, const PenaltyContact& law, double k, Grid& grid,
                         Pad& pad) const {
    return solve(s, predicted, law, k, grid, &pad);
}

bool PointContact::solve(State& s, std::span<const double> predicted, const PenaltyContact& law, double k, Grid& grid,
                         Pad* pad) const {
    // A held note (the last step needed the joint solve): Newton at once, from the last step's
    // motion carried on (eta in contact at its last rate, the fingers' last height steps in
    // s.height), not from each side's own solution.
    const bool held = grid.pads != nullptr && s.joint;
    solve_points(s, predicted, law, k, pad, held);
    if (held) {
        grid.pads->guess(std::span<double>(s.height).first(grid.pads->heights()));
        const bool solved = s.awake + 1 + grid.pads->heights() <= static_cast<std::size_t>(kSmall)
                                ? solve_with_grid<SmallMatrix>(s, law, k, grid, pad, false, true)
                                : solve_with_grid<Eigen::MatrixXd>(s, law, k, grid, pad, false, true);
        if (solved) {
            // Still joint where both sides push at the solution.
            const bool points_push = pad_force_at(pad, pad != nullptr ? pad->x : 0.0) != 0.0 || any_push(s.force);
            bool grid_pushes = any_push(std::span<const double>(s.pad_force).first(grid.pads->points().size()));
            for (const ContactSolution& g : grid.solutions) grid_pushes = grid_pushes || g.force != 0.0;
            s.joint = points_push && grid_pushes;
            return commit(s);
        }
        // Not from that start (a note let go or struck anew): from each side's own solution.
        solve_points(s, predicted, law, k, pad);
    }
    const double pad_force = pad_force_at(pad, pad != nullptr ? pad->x : 0.0);
    const bool points_push =
        pad_force != 0.0 || any_push(s.force);
    const bool grid_pushes = solve_grid(s, law, k, grid, pad, pad_force);
    // Apart, each side's solution is the joint one if the other's push leaves it as it is: the
    // grid solved with the points' (and the pad's) forces already; the points and the pad, with
    // no force of their own, need the grid's push to leave them apart.
    bool joint = points_push && grid_pushes;
    if (grid_pushes && !points_push) {
        // The grid's (and the pads') push at u(x_p) and at u_s.
        for (std::size_t p = 0; p < size() && !joint; ++p) {
            s.quotient[p] = s.increment[p] - grid_push(s, k, grid, p, pad);
            joint = law.difference_quotient(s.eta_prev[p], s.quotient[p]) != 0.0;
        }
        double pad_x = 0.0;
        if (!joint && pad != nullptr) {
            pad_x = pad->x + grid_push(s, k, grid, size(), pad);
            joint = pad_force_at(pad, pad_x) != 0.0;
        }
        if (!joint) {
            for (std::size_t p = 0; p < size(); ++p) s.increment[p] = s.quotient[p];
            if (pad != nullptr) pad->x = pad_x;
        }
    }
    s.joint = joint;
    if (joint) {  // (from the evaluation just made: the points' own solutions, the fingers' own solves)
        const std::size_t heights = grid.pads != nullptr ? grid.pads->heights() : 0;
        if (s.awake + 1 + heights <= static_cast<std::size_t>(kSmall))
            solve_with_grid<SmallMatrix>(s, law, k, grid, pad, true);
        else
            solve_with_grid<Eigen::MatrixXd>(s, law, k, grid, pad, true);
    }
    return commit(s);
}

double PointContact::grid_push(const State& s, double k, const Grid& grid, std::size_t p, const Pad* pad) const {
    const auto coupling = [&](std::size_t i) { return p < size() ? grid_coupling(p, i) : pad->grid[i]; };
    double shift = 0.0;
    for (std::size_t r = 0; r < grid.points.size(); ++r)
        if (grid.solutions[r].force != 0.0) shift += coupling(grid.points[r]) * grid.solutions[r].force;
    if (grid.pads != nullptr) {
        const std::span<const std::size_t> pads = grid.pads->points();
        for (std::size_t r = 0; r < pads.size(); ++r)
            if (s.pad_force[r] != 0.0) shift += coupling(pads[r]) * s.pad_force[r];
    }
    return k * grid.step * shift;
}

bool PointContact::solve_grid(State& s, const PenaltyContact& law, double k, Grid& grid, const Pad* pad,
                              double pad_force, const std::vector<double>* height) const {
    bool pushes = false;
    s.pushing.clear();  // (within its reserved room)
    for (std::size_t p = 0; p < size(); ++p)
        if (s.force[p] != 0.0) s.pushing.push_back(p);
    if (grid.pads != nullptr) {
        // The pads' predictions raised by the points' (and the pad's) forces; one trial of their solve.
        const std::span<const std::size_t> pads = grid.pads->points();
        for (std::size_t r = 0; r < pads.size(); ++r) {
            const std::size_t i = pads[r];
            double shift = 0.0;
            for (std::size_t p : s.pushing) shift += points_[p].weight_m * grid_coupling(p, i) * s.force[p];
            if (pad_force != 0.0) shift += pad->grid[i] * pad_force;
            s.pad_shift[r] = k * shift;
        }
        const auto n = pads.size();
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
        if (pad_force != 0.0) b -= k * pad->grid[i] * pad_force;
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

template <class Matrix>
void PointContact::points_jacobian(State& s, const PenaltyContact& law, double k, const std::vector<double>& r,
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
void PointContact::pad_border(const State& s, double k, const Pad& pad, double pad_slope, Matrix& jacobian) const {
    // The pad's row and column beside the points' Jacobian (points_jacobian's slopes):
    // dR_p/dx = k h_p F', dR_x/dr_q = -k c_q h_q f_q', dR_x/dx = 1 - k (s . s) F'.
    const std::vector<std::size_t>& awake = s.awake_list;
    const auto e = static_cast<Eigen::Index>(awake.size());
    for (std::size_t a = 0; a < awake.size(); ++a) {
        const std::size_t p = awake[a];
        const auto i = static_cast<Eigen::Index>(a);
        jacobian(i, e) = k * pad.coupling[p] * pad_slope;
        jacobian(e, i) = -k * points_[p].weight_m * pad.coupling[p] * s.slope[p];
    }
    jacobian(e, e) = 1.0 - k * pad.self * pad_slope;
}

template <class Matrix>
void PointContact::pads_jacobian(State& s, double k, const Grid& grid, const Pad* pad, double pad_slope,
                                 Matrix& jacobian) const {
    // The fingers' part of the Jacobian. Unknown c (a point, the pad) moves the pads' predictions
    // along v (k c_q f_q' M_q. for a point, k F' m for the pad), their forces by dF_i/dw_i v_i
    // (each pad point's own response: the heights are unknowns of their own), the rows by
    // k dx M_p. (dF/dw v) (the pad's row: minus k dx m . (dF/dw v)), and finger f's row by
    // its pull . v. Finger f's height moves its pad's forces by dF_i/ds, its row by its slope.
    const std::span<const std::size_t> pads = grid.pads->points();
    const std::size_t n = pads.size();
    const std::size_t fingers = grid.pads->heights();
    const std::vector<std::size_t>& awake = s.awake_list;
    const std::size_t count = awake.size();
    const std::size_t columns = pad != nullptr ? count + 1 : count;  // (the fingers' come after)
    const std::span<double> response = std::span<double>(s.pad_response).first(n);
    const std::span<double> lift = std::span<double>(s.pad_lift).first(n);
    const std::span<double> pull = std::span<double>(s.pad_pull).first(n);
    grid.pads->slopes(response, lift, pull, std::span<double>(s.height_slope).first(fingers));
    const auto coupling = [&](std::size_t c, std::size_t r) {
        return c == count ? pad->grid[pads[r]] : grid_coupling(awake[c], pads[r]);
    };
    // Column c's change of the rows through pad points [from, to) moving by moved(r).
    const auto add_rows = [&](Eigen::Index column, std::size_t from, std::size_t to, auto&& moved) {
        for (std::size_t a = 0; a < columns; ++a) {
            double sum = 0.0;
            for (std::size_t r = from; r < to; ++r) sum += coupling(a, r) * moved(r);
            jacobian(static_cast<Eigen::Index>(a), column) += (a == count ? -1.0 : 1.0) * k * grid.step * sum;
        }
    };
    for (std::size_t c = 0; c < columns; ++c) {
        const bool pad_column = c == count;
        const double scale = pad_column ? k * pad_slope : k * points_[awake[c]].weight_m * s.slope[awake[c]];
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

template <class Matrix>
bool PointContact::solve_with_grid(State& s, const PenaltyContact& law, double k, Grid& grid, Pad* pad, bool evaluated,
                                   bool may_fail) const {
    // Newton on the points' increments r_p (and the pad's x, and the fingers' height steps), the
    // grid's equations solved inside each evaluation (w_i = f_i' / (1 + k f_i') their response
    // to a push), and the fingers' pad points too (GridPads: their forces join the grid's in R_p
    // and R_x, each finger's equation is a row; pads_jacobian their part of J):
    //     R_p = r_p + k sum_q G_pq f_q + k dx sum_i M_pi f_i + k h_p F(x) - b_p,
    //     R_x = x - w - k sum_q c_q h_q f_q - k (s . s) F(x) - k dx sum_i m_i f_i,
    //     dR_p/dr_q = delta_pq + k G_pq f_q' - k^2 dx c_q f_q' sum_i M_pi M_qi w_i,
    //     dR_p/dx = k h_p F' - k^2 dx F' sum_i M_pi m_i w_i,
    //     dR_x/dr_q = -k c_q h_q f_q' + k^2 dx c_q f_q' sum_i m_i M_qi w_i,
    //     dR_x/dx = 1 - k (s . s) F' + k^2 dx F' sum_i m_i^2 w_i.
    // evaluated: s (and grid.solutions) hold the evaluation at s.increment, pad->x and s.height.
    double scale = newton_scale(s);
    const std::vector<std::size_t>& awake = s.awake_list;
    const std::size_t count = awake.size();
    const std::size_t last = count;  // the pad's row and column, where there is one
    const std::size_t fingers = grid.pads != nullptr ? grid.pads->heights() : 0;
    for (std::size_t f = 0; f < fingers; ++f) s.height_end[f] = grid.pads->end(f);
    const std::size_t first_height = pad != nullptr ? count + 1 : count;
    const auto m = static_cast<Eigen::Index>(first_height + fingers);
    Matrix jacobian(m, m);
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, Matrix::MaxRowsAtCompileTime, 1> step(m);
    std::vector<double>& r = s.increment;
    double x = pad != nullptr ? pad->x : 0.0, pad_force = 0.0, pad_slope = 0.0, pad_residual = 0.0;
    if (pad != nullptr) scale = std::max({scale, std::abs(pad->predicted), std::abs(x)});
    const auto residual_at = [&](const std::vector<double>& at, double at_x, const std::vector<double>& at_height,
                                 bool solve) {
        for (std::size_t q : awake) s.quotient[q] = law.difference_quotient(s.eta_prev[q], at[q]);
        if (pad != nullptr) pad->press->force_and_slope(at_x, pad_force, pad_slope);
        if (solve) {
            // (the grid reads the points' forces from s.force: the quotients, for this evaluation)
            std::swap(s.force, s.quotient);
            solve_grid(s, law, k, grid, pad, pad_force, &at_height);
            std::swap(s.force, s.quotient);
        }
        double largest = 0.0;
        for (std::size_t p : awake) {
            double push = 0.0;
            for (std::size_t q : awake) push += gram(p, q) * s.quotient[q];
            s.residual[p] = at[p] + k * push + grid_push(s, k, grid, p, pad) - s.b[p];
            if (pad != nullptr) s.residual[p] += k * pad->coupling[p] * pad_force;
            largest = std::max(largest, std::abs(s.residual[p]));
        }
        if (pad != nullptr) {
            double push = 0.0;
            for (std::size_t q : awake) push += points_[q].weight_m * pad->coupling[q] * s.quotient[q];
            pad_residual = at_x - pad->predicted - k * push - k * pad->self * pad_force - grid_push(s, k, grid, size(), pad);
            largest = std::max(largest, std::abs(pad_residual));
        }
        // A finger's equation rounds relative to its own size (a stiff pad's slope times the
        // finger's height): measured against the points' scale, its floor at theirs.
        for (std::size_t f = 0; f < fingers; ++f) {
            const double size = s.height_size[f];
            largest = std::max(largest, std::abs(s.height_residual[f]) * (size > scale ? scale / size : 1.0));
        }
        return largest;
    };
    const double tolerance = 4.0 * std::numeric_limits<double>::epsilon() * scale;
    // residual_at swaps s.force with s.quotient: the trial point lives in a vector of its own.
    std::vector<double>& candidate = s.candidate;
    std::copy(r.begin(), r.end(), candidate.begin());
    double norm = residual_at(r, x, s.height, !evaluated);
    int iteration = 0;
    bool stalled = false;
    // (a start carried on from the last steps that needs more than a few iterations is a poor one)
    const int iterations = may_fail ? 8 : kMaxNewton;
    for (; iteration < iterations && norm > tolerance; ++iteration) {
        points_jacobian(s, law, k, r, jacobian);
        const auto e = static_cast<Eigen::Index>(last);
        if (pad != nullptr) pad_border(s, k, *pad, pad_slope, jacobian);
        if (fingers > 0) {
            jacobian.bottomRows(static_cast<Eigen::Index>(fingers)).setZero();
            jacobian.rightCols(static_cast<Eigen::Index>(fingers)).setZero();
        }
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
                        kkw * points_[q].weight_m * s.slope[q] * grid_coupling(p, i) * grid_coupling(q, i);
                }
            if (pad != nullptr) {
                const double m_i = pad->grid[i];
                for (std::size_t a = 0; a < count; ++a) {
                    const std::size_t p = awake[a];
                    const auto ia = static_cast<Eigen::Index>(a);
                    jacobian(ia, e) -= kkw * pad_slope * grid_coupling(p, i) * m_i;
                    jacobian(e, ia) += kkw * points_[p].weight_m * s.slope[p] * m_i * grid_coupling(p, i);
                }
                jacobian(e, e) += kkw * pad_slope * m_i * m_i;
            }
        }
        if (grid.pads != nullptr) pads_jacobian(s, k, grid, pad, pad_slope, jacobian);
        for (std::size_t a = 0; a < count; ++a) step(static_cast<Eigen::Index>(a)) = -s.residual[awake[a]];
        if (pad != nullptr) step(e) = -pad_residual;
        for (std::size_t f = 0; f < fingers; ++f) step(static_cast<Eigen::Index>(first_height + f)) = -s.height_residual[f];
        step = Eigen::PartialPivLU<Matrix>(jacobian).solve(step);
        double t = 1.0, trial_x = 0.0, trial_norm = 0.0;
        bool decreased = false;
        // Backtracking is for the kink of [eta]_+ far from the solution; near it, a full Newton
        // step that does not lower the residual finds it at its round-off floor (a stiff pad's
        // force rounds to its slope times eps |u|, far above eps times the unknowns).
        const int halvings = norm <= 1e-9 * scale ? 1 : 40;
        for (int halving = 0; halving < halvings; ++halving, t *= 0.5) {
            for (std::size_t a = 0; a < count; ++a) candidate[awake[a]] = r[awake[a]] + t * step(static_cast<Eigen::Index>(a));
            trial_x = pad != nullptr ? x + t * step(e) : 0.0;
            for (std::size_t f = 0; f < fingers; ++f)
                s.height_candidate[f] = s.height[f] + t * step(static_cast<Eigen::Index>(first_height + f));
            trial_norm = residual_at(candidate, trial_x, s.height_candidate, true);
            if (trial_norm < norm) {
                r.swap(candidate);
                s.height.swap(s.height_candidate);
                x = trial_x;
                norm = trial_norm;
                decreased = true;
                break;
            }
        }
        if (!decreased) {
            stalled = true;
            if (trial_norm <= 2.0 * norm && converged(trial_norm, step, stalled, scale)) {
                // At the round-off floor, the last trial as good as r: it is the one evaluated
                // (the fingers' state is its trial's), so it is the answer.
                r.swap(candidate);
                s.height.swap(s.height_candidate);
                x = trial_x;
                norm = trial_norm;
            } else {
                residual_at(r, x, s.height, true);  // back to r's quotients and grid solutions
            }
            break;
        }
    }
    // (a held note's start: taken only where Newton got to round-off, as it does from a good one)
    if (may_fail && !(norm <= tolerance || (stalled && converged(norm, step, stalled, scale)))) return false;
    if (!converged(norm, step, stalled, scale)) {
        throw SolverError("point contact: the joint Newton solve of " + std::to_string(count) +
                          (pad != nullptr ? " points, a pad" : " points") +
                          " and the grid's obstacle points did not converge (residual " + std::to_string(norm) + " m)");
    }
    s.iterations = std::max(s.iterations, iteration);
    for (std::size_t p : awake) s.force[p] = s.quotient[p];
    if (pad != nullptr) pad->x = x;
    return true;
}

template <class Matrix>
void PointContact::solve_coupled(State& s, const PenaltyContact& law, double k, Pad* pad) const {
    double scale = newton_scale(s);
    const std::vector<std::size_t>& awake = s.awake_list;
    const std::size_t count = awake.size();
    const std::size_t last = count;  // the pad's row and column, where there is one
    const auto m = static_cast<Eigen::Index>(pad != nullptr ? count + 1 : count);
    Matrix jacobian(m, m);
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, Matrix::MaxRowsAtCompileTime, 1> step(m);
    // The pad's unknown x, its force F(x), dF/dx and residual beside the points'.
    double x = pad != nullptr ? pad->x : 0.0, pad_force = 0.0, pad_slope = 0.0, pad_residual = 0.0;
    // residual_p = r_p + k sum_q G_pq f_q(r_q) (+ k h_p F(x)) - b_p, at increments r (and x);
    // returns the largest size of them.
    const auto residual_at = [&](const std::vector<double>& r, double at) {
        double largest = 0.0;
        for (std::size_t q : awake) s.quotient[q] = law.difference_quotient(s.eta_prev[q], r[q]);
        if (pad != nullptr) pad->press->force_and_slope(at, pad_force, pad_slope);
        for (std::size_t p : awake) {
            double push = 0.0;
            for (std::size_t q : awake) push += gram(p, q) * s.quotient[q];
            s.residual[p] = r[p] + k * push - s.b[p];
            if (pad != nullptr) s.residual[p] += k * pad->coupling[p] * pad_force;
            largest = std::max(largest, std::abs(s.residual[p]));
        }
        if (pad != nullptr) {
            double push = 0.0;
            for (std::size_t q : awake) push += points_[q].weight_m * pad->coupling[q] * s.quotient[q];
            pad_residual = at - pad->predicted - k * push - k * pad->self * pad_force;
            largest = std::max(largest, std::abs(pad_residual));
        }
        return largest;
    };
    if (pad != nullptr) scale = std::max({scale, std::abs(pad->predicted), std::abs(x)});
    const double tolerance = 4.0 * std::numeric_limits<double>::epsilon() * scale;
    std::vector<double>& r = s.increment;
    double norm = residual_at(r, x);
    std::vector<double>& trial = s.force;  // scratch until the forces are formed at the end
    int iteration = 0;
    bool stalled = false;
    for (; iteration < kMaxNewton && norm > tolerance; ++iteration) {
        // the points' Jacobian, bordered by the pad's row and column
        points_jacobian(s, law, k, r, jacobian);
        for (std::size_t a = 0; a < count; ++a) step(static_cast<Eigen::Index>(a)) = -s.residual[awake[a]];
        if (pad != nullptr) {
            pad_border(s, k, *pad, pad_slope, jacobian);
            step(static_cast<Eigen::Index>(last)) = -pad_residual;
        }
        step = Eigen::PartialPivLU<Matrix>(jacobian).solve(step);
        // Backtracking on the residual: the kink of [eta]_+ at eta = 0 can overshoot.
        double t = 1.0;
        bool decreased = false;
        for (int halving = 0; halving < 40; ++halving, t *= 0.5) {
            for (std::size_t a = 0; a < count; ++a) trial[awake[a]] = r[awake[a]] + t * step(static_cast<Eigen::Index>(a));
            const double trial_x = pad != nullptr ? x + t * step(static_cast<Eigen::Index>(last)) : 0.0;
            const double trial_norm = residual_at(trial, trial_x);
            if (trial_norm < norm) {
                r.swap(trial);
                x = trial_x;
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
        throw SolverError("point contact: the coupled Newton solve of " + std::to_string(count) +
                          (pad != nullptr ? " points and a pad" : " points") + " did not converge (residual " +
                          std::to_string(norm) + " m)");
    s.iterations = std::max(s.iterations, iteration);
    for (std::size_t p = 0; p < size(); ++p) s.force[p] = s.quotient[p];
    if (pad != nullptr) pad->x = x;
}

double PointContact::potential(const State& s, const PenaltyContact& law, bool current) const {
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

}  // namespace fretbuzz
