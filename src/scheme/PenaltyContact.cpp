#include "fretbuzz/scheme/PenaltyContact.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {
constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr int kMaxIterations = 200;
}  // namespace

PenaltyContact::PenaltyContact(double stiffness, double exponent, bool specialise)
    : k_(stiffness), alpha_(exponent), specialise_(specialise) {
    set(stiffness, exponent);
}

void PenaltyContact::set(double stiffness, double exponent) {
    // The checks build their messages only when they fail: a real-time change stays allocation-free.
    if (!(std::isfinite(stiffness) && stiffness > 0.0)) require_positive("contact.K (penalty stiffness)", stiffness);
    if (!(std::isfinite(exponent) && exponent >= 1.0)) require_at_least("contact.alpha (penalty exponent)", exponent, 1.0);
    k_ = stiffness;
    alpha_ = exponent;
    law_ = Law::general;
    if (!specialise_) return;
    if (exponent == 1.0) law_ = Law::linear;
    if (exponent == 1.5) law_ = Law::three_halves;
    if (exponent == 2.0) law_ = Law::quadratic;
    if (exponent == 3.0) law_ = Law::cubic;
}

double PenaltyContact::power(double eta) const {
    switch (law_) {
        case Law::linear: return eta;
        case Law::three_halves: return eta * std::sqrt(eta);
        case Law::quadratic: return eta * eta;
        case Law::cubic: return eta * eta * eta;
        case Law::general: break;
    }
    return std::pow(eta, alpha_);
}

double PenaltyContact::potential(double eta, double root) const {
    if (!(eta > 0.0)) return 0.0;
    if (law_ == Law::three_halves && root != kNoRoot) return k_ / (alpha_ + 1.0) * ((eta * root) * eta);
    return law_ == Law::general ? k_ / (alpha_ + 1.0) * std::pow(eta, alpha_ + 1.0)
                                : k_ / (alpha_ + 1.0) * (power(eta) * eta);
}

double PenaltyContact::force(double eta) const { return eta > 0.0 ? k_ * power(eta) : 0.0; }

double PenaltyContact::anchor(double a) const {
    // What every quotient of one solve shares: sqrt(a) or a^(alpha+1), computed once.
    if (!(a > 0.0)) return 0.0;
    if (law_ == Law::three_halves) return std::sqrt(a);
    return law_ == Law::general ? std::pow(a, alpha_ + 1.0) : 0.0;
}

double PenaltyContact::quotient_inside(double a, double r, double anchor_a, double& root) const {
    // ((a + r)^(alpha+1) - a^(alpha+1)) / r factored so that every term is positive.
    switch (law_) {
        case Law::linear: return k_ * (a + 0.5 * r);
        case Law::quadratic: return k_ * (a * (a + r) + r * r / 3.0);
        case Law::cubic: {
            const double e = a + r;
            return 0.25 * k_ * (a + e) * (a * a + e * e);
        }
        case Law::three_halves: {  // s^5 - t^5 over s^2 - t^2, s = sqrt(a + r), t = sqrt(a)
            const double s = std::sqrt(a + r), t = anchor_a;
            root = s;  // the slope at r and the potential of a + r use it again
            const double t2 = t * t;
            const double numerator = t2 * t2 + s * (t2 * t + s * (t2 + s * (t + s)));
            return 0.4 * k_ * numerator / (s + t);
        }
        case Law::general: break;
    }
    // K/(alpha+1) a^(alpha+1) [(1 + r/a)^(alpha+1) - 1] / r, accurate for tiny r/a.
    const double growth = std::expm1((alpha_ + 1.0) * std::log1p(r / a));
    return k_ / (alpha_ + 1.0) * anchor_a * growth / r;
}

double PenaltyContact::quotient(double a, double r, double anchor_a, double& root) const {
    root = kNoRoot;
    if (r == 0.0) return force(a);
    if (a > 0.0 && a + r > 0.0) return quotient_inside(a, r, anchor_a, root);
    // At most one of the two potentials is non-zero here: no cancellation.
    return (potential(a + r) - potential(a)) / r;
}

double PenaltyContact::difference_quotient(double a, double r) const {
    double root = kNoRoot;
    return quotient(a, r, anchor(a), root);
}

double PenaltyContact::slope_of_quotient(double a, double r, double quotient_value) const {
    return slope(a, r, quotient_value, a > 0.0 ? std::sqrt(a) : 0.0, kNoRoot);
}

double PenaltyContact::slope(double a, double r, double quotient_value, double sqrt_a, double root) const {
    // d/dr of the difference quotient. The closed forms differentiate exactly; otherwise
    // (Psi'(a+r) - quotient) / r, with its limit Psi''(a + r/2) / 2 when r is too small
    // against a for the difference to be accurate.
    if (a > 0.0 && a + r > 0.0) {
        switch (law_) {
            case Law::linear: return 0.5 * k_;
            case Law::quadratic: return k_ * (a + r * (2.0 / 3.0));
            case Law::cubic: {
                const double e = a + r;
                return 0.25 * k_ * (a * a + 2.0 * a * e + 3.0 * e * e);
            }
            case Law::three_halves: {  // sqrt(a + r) as the quotient at r found it, if it did
                const double s = root == kNoRoot ? std::sqrt(a + r) : root, t = sqrt_a;
                const double sum = s + t;
                return 0.2 * k_ * (s * (s * (3.0 * s + 6.0 * t) + 4.0 * t * t) + 2.0 * t * t * t) / (sum * sum);
            }
            case Law::general: break;
        }
    }
    if (a > 0.0 && std::abs(r) < 1e-4 * a) return 0.5 * k_ * alpha_ * std::pow(a + 0.5 * r, alpha_ - 1.0);
    if (r == 0.0) return 0.0;
    return (force(a + r) - quotient_value) / r;
}

ContactSolution PenaltyContact::solve(double a, double b, double k) const {
    ContactSolution s;
    if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(k)) {
        std::ostringstream msg;
        msg << "contact solve received a non-finite state (eta^{n-1} = " << a << ", b = " << b << ", dt^2/mu = " << k
            << "): the simulation has diverged";
        throw SolverError(msg.str());
    }
    if (a <= 0.0 && a + b <= 0.0) {  // stays out of contact over both steps: no force
        s.increment = b;
        return s;
    }
    // phi(r) = r + k F(r) - b is increasing and convex. phi(b) = k F(b) >= 0 and, F being
    // non-decreasing, phi(b - k F(b)) <= 0: the root lies in [b - k F(b), b].
    const double anchor_a = anchor(a);
    const double sqrt_a = law_ == Law::three_halves ? anchor_a : 0.0;  // only the 3/2 slope reads it
    double root = kNoRoot, root_next = kNoRoot, root_mid = kNoRoot;  // sqrt(a + r) where known
    double hi = b;
    double f_hi = quotient(a, hi, anchor_a, root);
    double lo = b - k * f_hi;
    if (a <= 0.0) lo = std::max(lo, -a);  // no force while a + r <= 0, so phi < 0 there
    double r = hi;
    double f = f_hi;
    double residual = k * f;  // phi(hi)
    for (int it = 1; it <= kMaxIterations; ++it) {
        s.iterations = it;
        const double scale = std::abs(r) + std::abs(b) + k * f;
        if (std::abs(residual) <= 4.0 * kEps * scale || hi - lo <= 2.0 * kEps * std::max(std::abs(lo), std::abs(hi))) {
            s.increment = r;
            s.force = f;
            s.root = root;
            return s;
        }
        const double slope = 1.0 + k * this->slope(a, r, f, sqrt_a, root);
        double next = r - residual / slope;
        // Keep inside the bracket; bisect when Newton would leave it or stalls.
        if (!(next > lo && next < hi) || !std::isfinite(next)) next = 0.5 * (lo + hi);
        const double f_next = quotient(a, next, anchor_a, root_next);
        const double residual_next = next + k * f_next - b;
        if (residual_next > 0.0)
            hi = next;
        else
            lo = next;
        if (std::abs(next - r) <= kEps * std::abs(next) || residual_next == 0.0) {
            s.increment = next;
            s.force = f_next;
            s.root = root_next;
            s.iterations = it;
            return s;
        }
        // If Newton crawls (a strongly curved law from far away), halve the bracket too.
        if (hi - lo > 0.0 && std::abs(residual_next) > 0.5 * std::abs(residual) && it % 4 == 0) {
            const double mid = 0.5 * (lo + hi);
            const double f_mid = quotient(a, mid, anchor_a, root_mid);
            const double residual_mid = mid + k * f_mid - b;
            (residual_mid > 0.0 ? hi : lo) = mid;
            if (std::abs(residual_mid) < std::abs(residual_next)) {
                r = mid;
                f = f_mid;
                root = root_mid;
                residual = residual_mid;
                continue;
            }
        }
        r = next;
        f = f_next;
        root = root_next;
        residual = residual_next;
    }
    std::ostringstream msg;
    msg.precision(17);
    msg << "contact solve did not converge in " << kMaxIterations << " iterations (K = " << k_
        << ", alpha = " << alpha_ << ", eta^{n-1} = " << a << ", b = " << b << ", dt^2/mu = " << k
        << "); reduce contact.K or the time step";
    throw SolverError(msg.str());
}

}  // namespace fretbuzz
