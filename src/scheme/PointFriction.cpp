#include "fretbuzz/scheme/PointFriction.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Dense>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {
constexpr int kMaxNewton = 100;
constexpr int kMaxHalvings = 40;
// Newton's residual, relative to the velocities' size, that counts as converged once it stalls.
constexpr double kFloor = 1e-9;
const double kLargest = std::nextafter(1.0, 0.0);  // |g| < 1
}  // namespace

struct PointFriction::Newton {
    explicit Newton(Eigen::Index n) : jacobian(n, n), rhs(n), step(n), lu(n) {}
    Eigen::MatrixXd jacobian;
    Eigen::VectorXd rhs, step;
    Eigen::PartialPivLU<Eigen::MatrixXd> lu;
};

struct PointFriction::Step {
    const Friction& law;
    std::span<const double> v0, normal;
    double k, dt;
    double half;   // k / (2 dt): a force's velocity per unit of row product
    double scale;  // mu_f k / (2 dt)
    double v_eps;
    Grid* grid;
};

PointFriction::PointFriction() = default;
PointFriction::~PointFriction() = default;
PointFriction::PointFriction(PointFriction&&) noexcept = default;
PointFriction& PointFriction::operator=(PointFriction&&) noexcept = default;
PointFriction::PointFriction(const PointFriction& other)
    : points_(other.points_), g_(other.g_), trial_(other.trial_), r_(other.r_), trial_r_(other.trial_r_),
      grid_slope_(other.grid_slope_), newton_(other.newton_ ? std::make_unique<Newton>(*other.newton_) : nullptr),
      iterations_(other.iterations_) {}
PointFriction& PointFriction::operator=(const PointFriction& other) {
    if (this != &other) *this = PointFriction(other);
    return *this;
}

PointFriction::PointFriction(const PointContact& points)
    : points_(&points), g_(points.size()), trial_(points.size()), r_(points.size()), trial_r_(points.size()) {
    const std::size_t count = points.size();
    if (grid_coupled() && count > 0) grid_slope_.assign(points.row(0).size(), 0.0);  // (as many grid points as modes)
    if (points.coupled() || grid_coupled()) newton_ = std::make_unique<Newton>(static_cast<Eigen::Index>(count));
}

void PointFriction::solve_grid(const Step& step, const std::vector<double>& g) {
    // Grid point i's own equation, the points' forces moving it by half c_p M_pi f_p each.
    Grid& grid = *step.grid;
    const double mu_f = step.law.coefficient();
    for (std::size_t r = 0; r < grid.points.size(); ++r) {
        const std::size_t i = grid.points[r];
        double shift = 0.0;
        for (std::size_t p = 0; p < size(); ++p)
            if (step.normal[p] != 0.0) shift -= weight(p) * coupling(p, i) * mu_f * std::abs(step.normal[p]) * g[p];
        const FrictionSolution s = step.law.solve(grid.v0[r] + step.half * shift, grid.normal[r], step.k, step.dt);
        grid.velocity[r] = s.velocity;
        grid.force[r] = s.force;
        const double h = std::hypot(s.velocity, step.v_eps);
        const double slope = step.v_eps * step.v_eps / (h * h * h);  // phi'
        grid_slope_[r] = slope / (1.0 + step.half * mu_f * std::abs(grid.normal[r]) * slope);
    }
}

double PointFriction::residual(const Step& step, const std::vector<double>& g, std::vector<double>& r) {
    // R_p = phi^-1(g_p) + scale sum_q G_pq |F_q| g_q - half dx sum_i M_pi f_i - v0_p at rubbing
    // points (0 elsewhere).
    if (step.grid != nullptr) solve_grid(step, g);
    const std::size_t count = size();
    double worst = 0.0;
    for (std::size_t p = 0; p < count; ++p) {
        r[p] = 0.0;
        if (step.normal[p] == 0.0) continue;
        double push = 0.0;
        for (std::size_t q = 0; q < count; ++q)
            if (step.normal[q] != 0.0) push += gram(p, q) * std::abs(step.normal[q]) * g[q];
        double from_grid = 0.0;
        if (step.grid != nullptr)
            for (std::size_t e = 0; e < step.grid->points.size(); ++e)
                from_grid += coupling(p, step.grid->points[e]) * step.grid->force[e];
        r[p] = step.v_eps * g[p] / std::sqrt((1.0 - g[p]) * (1.0 + g[p])) + step.scale * push -
               step.half * (step.grid != nullptr ? step.grid->step : 0.0) * from_grid - step.v0[p];
        worst = std::max(worst, std::abs(r[p]));
    }
    return worst;
}

double PointFriction::objective(const Step& step, const std::vector<double>& g) {
    // E = sum_a W_a (-v_eps sqrt(1 - g_a^2) - v0_a g_a + scale g_a push_a / 2) over the points
    // (W_p = c_p |F_p|) and the rubbing grid points (W_i = dx |F_i|), push_a = sum_b A_ab w_b |F_b| g_b
    // with A the rows' products and w the widths: W A W is symmetric, so E's gradient is W R, and
    // with the grid's g at their own roots (solve_grid) its gradient in the points' g is W R too.
    if (step.grid != nullptr) solve_grid(step, g);
    const double mu_f = step.law.coefficient();
    const std::size_t count = size();
    double e = 0.0;
    for (std::size_t p = 0; p < count; ++p) {
        if (step.normal[p] == 0.0) continue;
        double push = 0.0;
        for (std::size_t q = 0; q < count; ++q)
            if (step.normal[q] != 0.0) push += gram(p, q) * std::abs(step.normal[q]) * g[q];
        if (step.grid != nullptr)
            for (std::size_t r = 0; r < step.grid->points.size(); ++r)
                push -= step.grid->step * coupling(p, step.grid->points[r]) * step.grid->force[r] / mu_f;
        const double w = weight(p) * std::abs(step.normal[p]);
        e += w * (-step.v_eps * std::sqrt((1.0 - g[p]) * (1.0 + g[p])) - step.v0[p] * g[p] + 0.5 * step.scale * push * g[p]);
    }
    if (step.grid == nullptr) return e;
    const Grid& grid = *step.grid;
    for (std::size_t r = 0; r < grid.points.size(); ++r) {
        const double normal = std::abs(grid.normal[r]);
        if (normal == 0.0) continue;
        const double gr = -grid.force[r] / (mu_f * normal);
        double push = normal * gr;
        for (std::size_t p = 0; p < count; ++p)
            if (step.normal[p] != 0.0) push += weight(p) * coupling(p, grid.points[r]) * std::abs(step.normal[p]) * g[p];
        const double root = step.v_eps / std::hypot(grid.velocity[r], step.v_eps);  // sqrt(1 - g^2)
        e += grid.step * normal * (-step.v_eps * root - grid.v0[r] * gr + 0.5 * step.scale * push * gr);
    }
    return e;
}

void PointFriction::newton(const Step& step) {
    const std::size_t count = size();
    const double dx = step.grid != nullptr ? step.grid->step : 0.0;
    // The size the residual is relative to: the velocities and the largest friction term.
    double size_v = step.v_eps;
    for (std::size_t p = 0; p < count; ++p) {
        if (step.normal[p] == 0.0) continue;
        double reach = 0.0;
        for (std::size_t q = 0; q < count; ++q) reach += std::abs(gram(p, q) * step.normal[q]);
        if (step.grid != nullptr)
            for (std::size_t r = 0; r < step.grid->points.size(); ++r)
                reach += dx * std::abs(coupling(p, step.grid->points[r]) * step.grid->normal[r]);
        size_v = std::max(size_v, std::abs(step.v0[p]) + step.scale * reach);
    }
    const double tolerance = 1e-14 * size_v;
    double norm = residual(step, g_, r_);
    Newton& nt = *newton_;
    for (int it = 1; norm > tolerance; ++it) {
        if (it > kMaxNewton)
            throw SolverError("friction solve at the point obstacles did not converge in " + std::to_string(kMaxNewton) +
                              " iterations (residual " + std::to_string(norm) +
                              " m/s); lower contact.friction or raise contact.friction_velocity");
        iterations_ = std::max(iterations_, it);
        // J_pq = delta_pq v_eps / (1 - g_p^2)^(3/2) + scale G_pq |F_q|
        //        - scale^2 dx c_q |F_q| sum_i M_pi M_qi |F_i| phi'_i / (1 + K_i phi'_i)
        // (the grid's equations eliminated); rows of points at rest: identity.
        for (std::size_t p = 0; p < count; ++p) {
            const auto a = static_cast<Eigen::Index>(p);
            nt.rhs(a) = -r_[p];
            for (std::size_t q = 0; q < count; ++q) {
                const auto b = static_cast<Eigen::Index>(q);
                double entry = 0.0;
                if (step.normal[p] == 0.0 || step.normal[q] == 0.0) {
                    entry = p == q ? 1.0 : 0.0;
                } else {
                    entry = step.scale * gram(p, q) * std::abs(step.normal[q]);
                    if (p == q) {
                        const double room = (1.0 - g_[p]) * (1.0 + g_[p]);
                        entry += step.v_eps / (room * std::sqrt(room));
                    }
                    if (step.grid != nullptr) {
                        double through = 0.0;
                        for (std::size_t r = 0; r < step.grid->points.size(); ++r) {
                            const std::size_t i = step.grid->points[r];
                            through += coupling(p, i) * coupling(q, i) * std::abs(step.grid->normal[r]) * grid_slope_[r];
                        }
                        entry -= step.scale * step.scale * dx * weight(q) * std::abs(step.normal[q]) * through;
                    }
                }
                nt.jacobian(a, b) = entry;
            }
        }
        nt.lu.compute(nt.jacobian);
        nt.step.noalias() = nt.lu.solve(nt.rhs);
        // The longest step inside (-1, 1).
        double t = 1.0, correction = 0.0, slope = 0.0;
        for (std::size_t p = 0; p < count; ++p) {
            const double dg = nt.step(static_cast<Eigen::Index>(p));
            correction = std::max(correction, std::abs(dg));
            slope += weight(p) * std::abs(step.normal[p]) * r_[p] * dg;
            if (dg > 0.0) t = std::min(t, 0.99 * (1.0 - g_[p]) / dg);
            if (dg < 0.0) t = std::min(t, 0.99 * (-1.0 - g_[p]) / dg);
        }
        const auto try_step = [&](double length) {
            for (std::size_t p = 0; p < count; ++p)
                trial_[p] = std::clamp(g_[p] + length * nt.step(static_cast<Eigen::Index>(p)), -kLargest, kLargest);
        };
        // The whole step where it halves R (near the root, where E's changes are below its
        // round-off); otherwise backtracking until E falls enough (Armijo).
        try_step(t);
        double trial_norm = residual(step, trial_, trial_r_);
        bool accepted = trial_norm <= 0.5 * norm;
        const double e0 = accepted ? 0.0 : objective(step, g_);
        for (int h = 0; h < kMaxHalvings && !accepted; ++h, t *= 0.5) {
            try_step(t);
            accepted = objective(step, trial_) <= e0 + 1e-4 * t * slope;
        }
        if (!accepted) try_step(t);
        trial_norm = residual(step, trial_, trial_r_);
        if (!accepted && trial_norm >= norm) break;  // no step does better: the root, to round-off
        // A point sliding fast sits where phi^-1 is steep: R cannot fall below its slope times
        // g's rounding (then the force is as exact as g can be). A step that no longer halves a
        // small R has reached that floor.
        double floor = kFloor * size_v;
        for (std::size_t p = 0; p < count; ++p) {
            if (step.normal[p] == 0.0) continue;
            const double room = (1.0 - trial_[p]) * (1.0 + trial_[p]);
            floor = std::max(floor, 8.0 * std::numeric_limits<double>::epsilon() * step.v_eps / (room * std::sqrt(room)));
        }
        const bool stalled = trial_norm > 0.5 * norm && trial_norm <= floor;
        std::swap(g_, trial_);
        std::swap(r_, trial_r_);
        norm = trial_norm;
        if (stalled || correction <= 4.0 * std::numeric_limits<double>::epsilon()) break;
    }
}

double PointFriction::solve(const Friction& law, std::span<const double> v0, std::span<const double> normal, double k,
                            double dt, std::span<double> force) {
    const double half = k / (2.0 * dt);
    return solve(Step{law, v0, normal, k, dt, half, law.coefficient() * half, law.regularisation_velocity(), nullptr}, force);
}

double PointFriction::solve(const Friction& law, std::span<const double> v0, std::span<const double> normal, double k,
                            double dt, std::span<double> force, Grid& grid) {
    const double half = k / (2.0 * dt);
    return solve(Step{law, v0, normal, k, dt, half, law.coefficient() * half, law.regularisation_velocity(), &grid}, force);
}

double PointFriction::solve(const Step& step, std::span<double> force) {
    // The unknowns are g_p = phi(v_p) in (-1, 1): f_p = -mu_f |F_p| g_p, and
    //     phi^-1(g_p) + scale sum_q G_pq |F_q| g_q = v0_p,   scale = mu_f k / (2 dt),
    // the gradient (times W) of the strictly convex E (objective): Newton's method with a line
    // search on E converges from anywhere inside (-1, 1)^P. (In v, phi' vanishes as a point
    // slides fast and Newton's steps overshoot.)
    const std::size_t count = size();
    const double mu_f = step.law.coefficient();
    std::size_t rubbing = 0;
    iterations_ = 0;
    // Each point's own root (the answer where the rows do not couple, or one point rubs alone).
    for (std::size_t p = 0; p < count; ++p) {
        g_[p] = 0.0;
        if (step.normal[p] == 0.0) continue;
        ++rubbing;
        const FrictionSolution s = step.law.solve(step.v0[p], std::abs(step.normal[p]) * gram(p, p), step.k, step.dt);
        g_[p] = std::clamp(step.law.phi(s.velocity), -kLargest, kLargest);
        iterations_ = std::max(iterations_, s.iterations);
    }
    const bool with_grid = step.grid != nullptr && !step.grid->points.empty();
    if (rubbing > 0 && ((rubbing > 1 && points_->coupled()) || with_grid)) newton(step);
    if (step.grid != nullptr) solve_grid(step, g_);  // the grid's forces for the points' answer
    for (std::size_t p = 0; p < count; ++p) force[p] = step.normal[p] == 0.0 ? 0.0 : -mu_f * std::abs(step.normal[p]) * g_[p];
    double work = 0.0;
    for (std::size_t p = 0; p < count; ++p) {
        if (step.normal[p] == 0.0) continue;
        // y^{n+1} - y^{n-1} = 2 dt v with v = v0 + (k / 2 dt) (sum_q G_pq f_q + dx sum_i M_pi f_i),
        // as the modes move.
        double v = step.v0[p];
        for (std::size_t q = 0; q < count; ++q) v += step.half * gram(p, q) * force[q];
        if (step.grid != nullptr)
            for (std::size_t r = 0; r < step.grid->points.size(); ++r)
                v += step.half * step.grid->step * coupling(p, step.grid->points[r]) * step.grid->force[r];
        // c_p f_p (y^{n+1} - y^{n-1}) / 2: <= 0 (v has the sign of g at the root).
        work += weight(p) * force[p] * v * step.dt;
    }
    if (step.grid != nullptr)
        for (std::size_t r = 0; r < step.grid->points.size(); ++r)
            work += step.grid->step * step.grid->force[r] * step.grid->velocity[r] * step.dt;
    return work;
}

}  // namespace fretbuzz
