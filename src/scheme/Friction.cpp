#include "fretbuzz/scheme/Friction.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {
constexpr int kMaxIterations = 200;
}  // namespace

Friction::Friction(double coefficient, double regularisation_velocity)
    : mu_(coefficient), v_eps_(regularisation_velocity) {
    require_non_negative("contact.friction", coefficient);
    require_positive("contact.friction_velocity (m/s)", regularisation_velocity);
}

double Friction::phi(double v) const { return v / std::hypot(v, v_eps_); }

FrictionSolution Friction::solve(double v0, double normal, double k, double dt) const {
    const double big_k = k * mu_ * std::abs(normal) / (2.0 * dt);
    FrictionSolution s;
    if (big_k == 0.0 || v0 == 0.0) {
        s.velocity = v0;
        s.force = -mu_ * std::abs(normal) * phi(v0);
        return s;
    }
    // phi is odd: solve for |v0| and give the sign back.
    const double target = std::abs(v0);
    double lo = std::max(0.0, target - big_k), hi = target;
    double v = lo;
    const double eps2 = v_eps_ * v_eps_;
    for (int it = 1; it <= kMaxIterations; ++it) {
        const double r = std::hypot(v, v_eps_);
        const double g = v + big_k * v / r - target;
        if (g == 0.0) {
            lo = hi = v;
            s.iterations = it;
            break;
        }
        if (g < 0.0) lo = v; else hi = v;
        const double slope = 1.0 + big_k * eps2 / (r * r * r);
        double next = v - g / slope;
        // Concavity keeps Newton inside the bracket; round-off might not: bisect then.
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        const bool converged = std::abs(next - v) <= 1e-15 * (std::abs(v) + v_eps_) || hi - lo <= 1e-15 * (hi + v_eps_);
        v = next;
        s.iterations = it;
        if (converged) break;
        if (it == kMaxIterations)
            throw SolverError("friction solve did not converge in " + std::to_string(kMaxIterations) +
                              " iterations (v0 = " + std::to_string(v0) + " m/s, K = " + std::to_string(big_k) +
                              " m/s); lower contact.friction or raise contact.friction_velocity");
    }
    s.velocity = v0 < 0.0 ? -v : v;
    s.force = -mu_ * std::abs(normal) * phi(s.velocity);
    return s;
}

}  // namespace fretbuzz
