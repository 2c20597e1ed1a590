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
// Up to this many points the Newton system lives on the stack.
constexpr int kSmall = 16;
using SmallMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kSmall, kSmall>;
}  // namespace

PointContact::PointContact(const ModalBasis& basis, std::vector<PointObstacle> points) : points_(std::move(points)) {
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
}

void PointContact::set_offset(double offset) {
    for (std::size_t p = 0; p < heights_.size(); ++p)
        heights_[p] = std::min(planned_heights_[p] + offset, std::max(planned_heights_[p], 0.0));
}

PointContact::State PointContact::make_state() const {
    State s;
    for (std::vector<double>* v : {&s.eta_prev, &s.eta_curr, &s.force, &s.increment, &s.b, &s.quotient, &s.slope, &s.residual})
        v->assign(size(), 0.0);
    return s;
}

void PointContact::start(State& s, std::span<const double> q, std::span<const double> d) const {
    for (std::size_t p = 0; p < size(); ++p) {
        double u_now = 0.0, u_before = 0.0;
        kernels::dot_current_previous(rows_[p].data(), q.data(), d.data(), q.size(), u_now, u_before);
        s.eta_curr[p] = heights_[p] - u_now;
        s.eta_prev[p] = heights_[p] - u_before;
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
    const std::size_t count = size();
    s.iterations = 0;
    // Each point alone first: the answer where the points do not couple, else Newton's start.
    for (std::size_t p = 0; p < count; ++p) {
        const double a = s.eta_prev[p];
        s.b[p] = heights_[p] - predicted[p] - a;
        const ContactSolution alone = law.solve(a, s.b[p], k * gram(p, p));
        s.increment[p] = alone.increment;
        s.force[p] = alone.force;
        s.iterations = std::max(s.iterations, alone.iterations);
    }
    const long touching = std::count_if(s.force.begin(), s.force.end(), [](double f) { return f != 0.0; });
    bool pressed = false;
    if (pad != nullptr) {
        double force = 0.0, slope = 0.0;
        pad->press->force_and_slope(pad->x, force, slope);
        pressed = force != 0.0;
    }
    // The pad moves every point it overlaps in mode space, and they move it.
    if (pad != nullptr && (pressed || touching > 0)) {
        if (count + 1 <= static_cast<std::size_t>(kSmall))
            solve_coupled<SmallMatrix>(s, law, k, pad);
        else
            solve_coupled<Eigen::MatrixXd>(s, law, k, pad);
    } else if (coupled_ && touching > 0 && count > 1) {
        if (count <= static_cast<std::size_t>(kSmall))
            solve_coupled<SmallMatrix>(s, law, k, nullptr);
        else
            solve_coupled<Eigen::MatrixXd>(s, law, k, nullptr);
    }
    for (std::size_t p = 0; p < count; ++p) {
        const double eta_next = s.eta_prev[p] + s.increment[p];
        s.eta_prev[p] = s.eta_curr[p];
        s.eta_curr[p] = eta_next;
    }
    return std::any_of(s.force.begin(), s.force.end(), [](double f) { return f != 0.0; });
}

template <class Matrix>
void PointContact::solve_coupled(State& s, const PenaltyContact& law, double k, Pad* pad) const {
    const std::size_t count = size();
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
        for (std::size_t q = 0; q < count; ++q) s.quotient[q] = law.difference_quotient(s.eta_prev[q], r[q]);
        if (pad != nullptr) pad->press->force_and_slope(at, pad_force, pad_slope);
        for (std::size_t p = 0; p < count; ++p) {
            double push = 0.0;
            for (std::size_t q = 0; q < count; ++q)
                push += gram(p, q) * s.quotient[q];
            s.residual[p] = r[p] + k * push - s.b[p];
            if (pad != nullptr) s.residual[p] += k * pad->coupling[p] * pad_force;
            largest = std::max(largest, std::abs(s.residual[p]));
        }
        if (pad != nullptr) {
            double push = 0.0;
            for (std::size_t q = 0; q < count; ++q) push += points_[q].weight_m * pad->coupling[q] * s.quotient[q];
            pad_residual = at - pad->predicted - k * push - k * pad->self * pad_force;
            largest = std::max(largest, std::abs(pad_residual));
        }
        return largest;
    };
    double scale = std::numeric_limits<double>::min();
    for (std::size_t p = 0; p < count; ++p)
        scale = std::max({scale, std::abs(s.b[p]), std::abs(s.eta_prev[p]), std::abs(s.increment[p])});
    if (pad != nullptr) scale = std::max({scale, std::abs(pad->predicted), std::abs(x)});
    const double tolerance = 4.0 * std::numeric_limits<double>::epsilon() * scale;
    std::vector<double>& r = s.increment;
    double norm = residual_at(r, x);
    std::vector<double>& trial = s.force;  // scratch until the forces are formed at the end
    int iteration = 0;
    for (; iteration < kMaxNewton && norm > tolerance; ++iteration) {
        // J = I + k G diag(d f_q / d r_q), bordered by the pad's row and column
        for (std::size_t q = 0; q < count; ++q) s.slope[q] = law.slope_of_quotient(s.eta_prev[q], r[q], s.quotient[q]);
        for (std::size_t p = 0; p < count; ++p)
            for (std::size_t q = 0; q < count; ++q)
                jacobian(static_cast<Eigen::Index>(p), static_cast<Eigen::Index>(q)) =
                    (p == q ? 1.0 : 0.0) + k * gram(p, q) * s.slope[q];
        for (std::size_t p = 0; p < count; ++p) step(static_cast<Eigen::Index>(p)) = -s.residual[p];
        if (pad != nullptr) {
            const auto e = static_cast<Eigen::Index>(last);
            for (std::size_t p = 0; p < count; ++p) {
                const auto i = static_cast<Eigen::Index>(p);
                jacobian(i, e) = k * pad->coupling[p] * pad_slope;
                jacobian(e, i) = -k * points_[p].weight_m * pad->coupling[p] * s.slope[p];
            }
            jacobian(e, e) = 1.0 - k * pad->self * pad_slope;
            step(e) = -pad_residual;
        }
        step = Eigen::PartialPivLU<Matrix>(jacobian).solve(step);
        // Backtracking on the residual: the kink of [eta]_+ at eta = 0 can overshoot.
        double t = 1.0;
        bool decreased = false;
        for (int halving = 0; halving < 40; ++halving, t *= 0.5) {
            for (std::size_t p = 0; p < count; ++p) trial[p] = r[p] + t * step(static_cast<Eigen::Index>(p));
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
            break;              // at the round-off floor
        }
    }
    if (!(norm <= 1e-9 * scale))
        throw SolverError("point contact: the coupled Newton solve of " + std::to_string(count) +
                          (pad != nullptr ? " points and a pad" : " points") + " did not converge (residual " +
                          std::to_string(norm) + " m)");
    s.iterations = std::max(s.iterations, iteration);
    for (std::size_t p = 0; p < count; ++p) s.force[p] = s.quotient[p];
    if (pad != nullptr) pad->x = x;
}

double PointContact::potential(const State& s, const PenaltyContact& law, bool current) const {
    double sum = 0.0;
    for (std::size_t p = 0; p < size(); ++p) sum += points_[p].weight_m * law.potential(current ? s.eta_curr[p] : s.eta_prev[p]);
    return sum;
}

void PointContact::add_impulse(const State& s, double k, std::span<double> impulse) const {
    for (std::size_t p = 0; p < size(); ++p)
        if (s.force[p] != 0.0) kernels::axpy(k * points_[p].weight_m * s.force[p], rows_[p].data(), impulse.data(), impulse.size());
}

}  // namespace fretbuzz
