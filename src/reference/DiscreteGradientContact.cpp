#include "fretbuzz/reference/DiscreteGradientContact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "fretbuzz/Error.hpp"

namespace fretbuzz::reference {

namespace {
constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
constexpr int kIterationLimit = 100;
}  // namespace

DiscreteGradientContact::DiscreteGradientContact(double stiffness, double exponent)
    : stiffness_(stiffness), exponent_(exponent) {
    require_positive("contact stiffness K", stiffness);
    require_at_least("contact exponent alpha", exponent, 1.0);
}

double DiscreteGradientContact::potential(double eta) const {
    if (eta <= 0.0) return 0.0;
    return stiffness_ / (exponent_ + 1.0) * std::pow(eta, exponent_ + 1.0);
}

double DiscreteGradientContact::force(double eta) const {
    return eta > 0.0 ? stiffness_ * std::pow(eta, exponent_) : 0.0;
}

double DiscreteGradientContact::gradient(double a, double r) const {
    if (r == 0.0) return force(a);
    // The quotient is symmetric in its two end points: order them.
    const double low = std::min(a, a + r);
    const double high = std::max(a, a + r);
    const double width = std::abs(r);
    if (high <= 0.0) return 0.0;
    if (low <= 0.0) return potential(high) / width;  // only one end in contact: no cancellation
    // Both in contact: Psi(high) - Psi(low) = Psi(low) ((1 + width/low)^(alpha+1) - 1),
    // evaluated with expm1/log1p so that a tiny width loses no digits.
    const double p = exponent_ + 1.0;
    return potential(low) * std::expm1(p * std::log1p(width / low)) / width;
}

double DiscreteGradientContact::gradient_slope(double a, double r, double g) const {
    // d/dr of the quotient, (f(a + r) - g) / r; for r tiny against a it tends to f'(a)/2.
    const double mid = a + 0.5 * r;
    if (std::abs(r) <= 1e-5 * std::abs(a) || r == 0.0)
        return mid > 0.0 ? 0.5 * stiffness_ * exponent_ * std::pow(mid, exponent_ - 1.0) : 0.0;
    return (force(a + r) - g) / r;
}

ContactStep DiscreteGradientContact::solve(double a, double b, double k) const {
    // F(r) = r + k G(r) - b with G(r) >= 0 non-decreasing and convex: F(b) = k G(b) >= 0, and
    // G <= max(f(a), f(a + b)) on r <= b, so F < 0 below b - k max(f(a), f(a + b)).
    ContactStep step;
    const double g_at_b = gradient(a, b);
    if (g_at_b == 0.0) {
        step.increment = b;
        return step;
    }
    double upper = b;
    double lower = b - k * std::max(force(a), force(a + b)) - kEpsilon * std::abs(b);
    // Newton from the upper end stays above the root for a convex increasing F; the bracket
    // guards against the rare step that round-off pushes out.
    double r = upper;
    double g = g_at_b;
    for (int iteration = 1; iteration <= kIterationLimit; ++iteration) {
        const double residual = r + k * g - b;
        if (residual > 0.0) upper = r;
        else if (residual < 0.0) lower = r;
        else {
            step.iterations = iteration;
            break;
        }
        const double slope = 1.0 + k * gradient_slope(a, r, g);
        double next = r - residual / slope;
        if (!(next > lower && next < upper)) next = 0.5 * (lower + upper);
        const double tolerance = 4.0 * kEpsilon * (std::abs(a) + std::abs(b) + std::abs(next));
        const bool converged = std::abs(next - r) <= tolerance || upper - lower <= tolerance;
        r = next;
        g = gradient(a, r);
        step.iterations = iteration;
        if (converged) break;
        if (iteration == kIterationLimit) {
            std::ostringstream message;
            message.precision(17);
            message << "finite-difference contact solve did not converge (eta^{n-1} = " << a << ", b = " << b
                    << ", k = " << k << ")";
            throw SolverError(message.str());
        }
    }
    step.increment = r;
    step.force = g;
    return step;
}

}  // namespace fretbuzz::reference
