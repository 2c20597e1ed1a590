#include "fretbuzz/scheme/PointFriction.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Dense>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/Kernels.hpp"

namespace fretbuzz {

namespace {
// Rows whose product is this small against their norms are orthogonal (distinct grid points).
constexpr double kUncoupled = 1e-12;
constexpr int kMaxNewton = 100;
constexpr int kMaxHalvings = 40;
// Newton's residual, relative to the velocities' size, that counts as converged once it stalls.
constexpr double kFloor = 1e-9;
}  // namespace

struct PointFriction::Newton {
    explicit Newton(Eigen::Index n) : jacobian(n, n), rhs(n), step(n), lu(n) {}
    Eigen::MatrixXd jacobian;
    Eigen::VectorXd rhs, step;
    Eigen::PartialPivLU<Eigen::MatrixXd> lu;
};

PointFriction::PointFriction() = default;
PointFriction::~PointFriction() = default;
PointFriction::PointFriction(PointFriction&&) noexcept = default;
PointFriction& PointFriction::operator=(PointFriction&&) noexcept = default;
PointFriction::PointFriction(const PointFriction& other)
    : weights_(other.weights_), gram_(other.gram_), coupled_(other.coupled_), g_(other.g_), trial_(other.trial_),
      r_(other.r_), trial_r_(other.trial_r_), newton_(other.newton_ ? std::make_unique<Newton>(*other.newton_) : nullptr),
      iterations_(other.iterations_) {}
PointFriction& PointFriction::operator=(const PointFriction& other) {
    if (this != &other) *this = PointFriction(other);
    return *this;
}

PointFriction::PointFriction(const PointContact& points)
    : weights_(points.size()),
      gram_(points.size() * points.size()),
      g_(points.size()),
      trial_(points.size()),
      r_(points.size()),
      trial_r_(points.size()) {
    const std::size_t count = points.size();
    for (std::size_t p = 0; p < count; ++p) weights_[p] = points.weight(p);
    for (std::size_t p = 0; p < count; ++p)
        for (std::size_t q = 0; q < count; ++q) {
            const std::span<const double> a = points.row(p), b = points.row(q);
            const double product = kernels::dot(a.data(), b.data(), a.size());
            gram_[p * count + q] = weights_[q] * product;
            if (p != q) {
                const double norms = std::sqrt(kernels::dot(a.data(), a.data(), a.size()) * kernels::dot(b.data(), b.data(), b.size()));
                coupled_ = coupled_ || std::abs(product) > kUncoupled * norms;
            }
        }
    if (coupled_) newton_ = std::make_unique<Newton>(static_cast<Eigen::Index>(count));
}

double PointFriction::residual(std::span<const double> v0, std::span<const double> normal, double v_eps, double scale,
                               const std::vector<double>& g, std::vector<double>& r) const {
    // R_p = phi^-1(g_p) + sum_q K_pq g_q - v0_p at rubbing points (0 elsewhere), K_pq = scale G_pq |F_q|
    // (mu_f in `scale`).
    const std::size_t count = size();
    double worst = 0.0;
    for (std::size_t p = 0; p < count; ++p) {
        r[p] = 0.0;
        if (normal[p] == 0.0) continue;
        double push = 0.0;
        for (std::size_t q = 0; q < count; ++q)
            if (normal[q] != 0.0) push += gram(p, q) * std::abs(normal[q]) * g[q];
        r[p] = v_eps * g[p] / std::sqrt((1.0 - g[p]) * (1.0 + g[p])) + scale * push - v0[p];
        worst = std::max(worst, std::abs(r[p]));
    }
    return worst;
}

double PointFriction::objective(std::span<const double> v0, std::span<const double> normal, double v_eps, double scale,
                                const std::vector<double>& g) const {
    // E(g) = sum_p W_p (-v_eps sqrt(1 - g_p^2) - v0_p g_p) + 1/2 sum_pq W_p K_pq g_p g_q, W_p = c_p |F_p|:
    // W K is symmetric (c_p |F_p| c_q |F_q| phi(x_p) . phi(x_q)), so E's gradient is W R.
    const std::size_t count = size();
    double e = 0.0;
    for (std::size_t p = 0; p < count; ++p) {
        if (normal[p] == 0.0) continue;
        double push = 0.0;
        for (std::size_t q = 0; q < count; ++q)
            if (normal[q] != 0.0) push += gram(p, q) * std::abs(normal[q]) * g[q];
        const double w = weights_[p] * std::abs(normal[p]);
        e += w * (-v_eps * std::sqrt((1.0 - g[p]) * (1.0 + g[p])) - v0[p] * g[p] + 0.5 * scale * push * g[p]);
    }
    return e;
}

double PointFriction::solve(const Friction& law, std::span<const double> v0, std::span<const double> normal, double k,
                            double dt, std::span<double> force) {
    const std::size_t count = size();
    const double mu_f = law.coefficient(), v_eps = law.regularisation_velocity();
    // The unknowns are g_p = phi(v_p) in (-1, 1): f_p = -mu_f |F_p| g_p, and
    //     phi^-1(g_p) + scale sum_q G_pq |F_q| g_q = v0_p,   scale = mu_f k / (2 dt),
    // the gradient (times W) of the strictly convex E above: Newton's method with a line
    // search on E converges from anywhere inside (-1, 1)^P. (In v, phi' vanishes as a point
    // slides fast and Newton's steps overshoot.)
    const double scale = mu_f * k / (2.0 * dt);
    const double largest = std::nextafter(1.0, 0.0);
    std::size_t rubbing = 0;
    iterations_ = 0;
    // Each point's own root (the answer where the rows do not couple, or one point rubs).
    for (std::size_t p = 0; p < count; ++p) {
        g_[p] = 0.0;
        if (normal[p] == 0.0) continue;
        ++rubbing;
        const FrictionSolution s = law.solve(v0[p], std::abs(normal[p]) * gram(p, p), k, dt);
        g_[p] = std::clamp(law.phi(s.velocity), -largest, largest);
        iterations_ = std::max(iterations_, s.iterations);
    }
    if (rubbing > 1 && coupled_) {
        double size_v = v_eps;
        for (std::size_t p = 0; p < count; ++p) {
            if (normal[p] == 0.0) continue;
            double reach = 0.0;
            for (std::size_t q = 0; q < count; ++q) reach += std::abs(gram(p, q) * normal[q]);
            size_v = std::max(size_v, std::abs(v0[p]) + scale * reach);
        }
        const double tolerance = 1e-14 * size_v;
        double norm = residual(v0, normal, v_eps, scale, g_, r_);
        Newton& nt = *newton_;
        for (int it = 1; norm > tolerance; ++it) {
            if (it > kMaxNewton)
                throw SolverError("friction solve at the point obstacles did not converge in " + std::to_string(kMaxNewton) +
                                  " iterations (residual " + std::to_string(norm) +
                                  " m/s); lower contact.friction or raise contact.friction_velocity");
            iterations_ = std::max(iterations_, it);
            // J_pq = delta_pq v_eps / (1 - g_p^2)^(3/2) + K_pq; rows of points at rest: identity.
            for (std::size_t p = 0; p < count; ++p) {
                const auto a = static_cast<Eigen::Index>(p);
                nt.rhs(a) = -r_[p];
                for (std::size_t q = 0; q < count; ++q) {
                    const auto b = static_cast<Eigen::Index>(q);
                    double entry = 0.0;
                    if (normal[p] == 0.0 || normal[q] == 0.0) {
                        entry = p == q ? 1.0 : 0.0;
                    } else {
                        entry = scale * gram(p, q) * std::abs(normal[q]);
                        if (p == q) {
                            const double room = (1.0 - g_[p]) * (1.0 + g_[p]);
                            entry += v_eps / (room * std::sqrt(room));
                        }
                    }
                    nt.jacobian(a, b) = entry;
                }
            }
            nt.lu.compute(nt.jacobian);
            nt.step.noalias() = nt.lu.solve(nt.rhs);
            // The longest step inside (-1, 1), then backtracking until E falls enough (Armijo).
            double t = 1.0, correction = 0.0, slope = 0.0;
            for (std::size_t p = 0; p < count; ++p) {
                const double dg = nt.step(static_cast<Eigen::Index>(p));
                correction = std::max(correction, std::abs(dg));
                slope += weights_[p] * std::abs(normal[p]) * r_[p] * dg;
                if (dg > 0.0) t = std::min(t, 0.99 * (1.0 - g_[p]) / dg);
                if (dg < 0.0) t = std::min(t, 0.99 * (-1.0 - g_[p]) / dg);
            }
            const auto try_step = [&](double length) {
                for (std::size_t p = 0; p < count; ++p)
                    trial_[p] = std::clamp(g_[p] + length * nt.step(static_cast<Eigen::Index>(p)), -largest, largest);
            };
            // The whole step where it halves R (near the root, where E's changes are below its
            // round-off); otherwise backtracking until E falls enough (Armijo).
            try_step(t);
            double trial_norm = residual(v0, normal, v_eps, scale, trial_, trial_r_);
            bool accepted = trial_norm <= 0.5 * norm;
            const double e0 = accepted ? 0.0 : objective(v0, normal, v_eps, scale, g_);
            for (int h = 0; h < kMaxHalvings && !accepted; ++h, t *= 0.5) {
                try_step(t);
                accepted = objective(v0, normal, v_eps, scale, trial_) <= e0 + 1e-4 * t * slope;
            }
            if (!accepted) try_step(t);
            trial_norm = residual(v0, normal, v_eps, scale, trial_, trial_r_);
            if (!accepted && trial_norm >= norm) break;  // no step does better: the root, to round-off
            // A point sliding fast sits where phi^-1 is steep: R cannot fall below its slope times
            // g's rounding. A step that no longer halves a small R has reached that floor.
            const bool stalled = trial_norm > 0.5 * norm && trial_norm <= kFloor * size_v;
            std::swap(g_, trial_);
            std::swap(r_, trial_r_);
            norm = trial_norm;
            if (stalled || correction <= 4.0 * std::numeric_limits<double>::epsilon()) break;
        }
    }
    for (std::size_t p = 0; p < count; ++p) force[p] = normal[p] == 0.0 ? 0.0 : -mu_f * std::abs(normal[p]) * g_[p];
    double work = 0.0;
    for (std::size_t p = 0; p < count; ++p) {
        if (normal[p] == 0.0) continue;
        // y^{n+1} - y^{n-1} = 2 dt v with v = v0 + (k / 2 dt) sum_q G_pq f_q, as the modes move.
        double v = v0[p];
        for (std::size_t q = 0; q < count; ++q) v += k / (2.0 * dt) * gram(p, q) * force[q];
        // c_p f_p (y^{n+1} - y^{n-1}) / 2: <= 0 (v has the sign of g at the root).
        work += weights_[p] * force[p] * v * dt;
    }
    return work;
}

}  // namespace fretbuzz
