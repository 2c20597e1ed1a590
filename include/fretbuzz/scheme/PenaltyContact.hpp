#pragma once
#include <cmath>
#include <cstddef>
#include <span>

#include "fretbuzz/scheme/ContactForceLaw.hpp"

// The penalty contact law f = K [eta]_+^alpha with potential Psi = K/(alpha+1) [eta]_+^(alpha+1),
// eta = g - u (Issanchou et al. 2017, section 2.2), and the scalar implicit equation the
// energy-conserving scheme (eq. 4) reduces to at each grid point:
//     r + k (Psi(a + r) - Psi(a)) / r = b,   r = eta^{n+1} - eta^{n-1}, a = eta^{n-1}, k = dt^2/mu.
// The left side is increasing and convex in r, so the root is unique; it is found by
// Newton's method from a model of the equation (or from r = b), inside a bracket that
// bisection falls back on, and it fails loudly rather than silently.
//
// The common exponents alpha = 1, 3/2, 2, 3 have the quotient in closed form without pow,
// expm1 or log1p (polynomials in eta, or in sqrt(eta) for 3/2), free of cancellation: the
// contact solve is where contact-heavy runs spend their time.
namespace fretbuzz {

class PenaltyContact {
public:
    // specialise = false evaluates every exponent through pow/expm1/log1p (the reference
    // the closed forms are tested against).
    PenaltyContact(double stiffness, double exponent, bool specialise = true);
    // New K and alpha (same checks), allocating nothing unless they are refused.
    void set(double stiffness, double exponent);

    double stiffness() const { return k_; }
    double exponent() const { return alpha_; }
    // Psi(eta); root as ContactSolution::root for eta if known: the same value either way (to
    // round-off for the general law).
    double potential(double eta, double root = kNoRoot) const {
        // Inline out of contact and where the solve left its root: called for every point solved,
        // in every step.
        if (!(eta > 0.0)) return 0.0;
        if (root != kNoRoot) {
            if (law_ == Law::three_halves) return potential_scale_ * ((eta * root) * eta);
            if (law_ == Law::general) return potential_scale_ * root;
        }
        return potential_of(eta);
    }
    double force(double eta) const;      // Psi'(eta)
    // (Psi(a + r) - Psi(a)) / r without cancellation; Psi'(a) at r = 0.
    double difference_quotient(double a, double r) const;
    // Solves the scalar equation above; throws SolverError if it cannot converge (or is given a
    // non-finite state). Inline where the point stays out of contact over both steps (a bridge's
    // points, most steps): no force, r = b.
    ContactSolution solve(double a, double b, double k) const {
        if (a <= 0.0 && std::isfinite(a + b) && a + b <= 0.0 && std::isfinite(k)) return ContactSolution{b};
        return solve(a, b, k, true);
    }
    // The same equation by Newton's method from r = b, the plain start: what solve's model
    // start is tested against (the same root to round-off).
    ContactSolution solve_from_b(double a, double b, double k) const;
    // out[i] = solve(a[i], b[i], k) for every i, to round-off. For alpha = 3/2, the first
    // iterates and Newton's first step are computed four equations at a time (a string landing
    // on a flat obstacle: hundreds at once); the equations out of contact or solved there are
    // finished, the others go on in solve. Returns how many were finished four at a time.
    std::size_t solve_all(std::span<const double> a, std::span<const double> b, double k,
                          std::span<ContactSolution> out) const;
    // d/dr of difference_quotient(a, r), given that quotient (>= 0: Psi is convex).
    double slope_of_quotient(double a, double r, double quotient) const;
    // An equation solved at many r for one a (a finger's or a gesture's own iteration): a's
    // power (sqrt(a), a^(alpha+1)) formed once, and the quotient and its slope at r in one call,
    // the same values as difference_quotient and slope_of_quotient.
    struct Anchored {
        double a, power;
    };
    Anchored anchored(double a) const { return {a, anchor(a)}; }
    struct QuotientSlope {
        double quotient, slope;
    };
    QuotientSlope quotient_and_slope(const Anchored& a, double r) const;
    // The ContactForceLaw gradient: quotient_and_slope at a, as a callable of r.
    class Gradient {
    public:
        Gradient(const PenaltyContact& law, double a) : law_(&law), at_(law.anchored(a)) {}
        ForceSlope operator()(double r) const {
            const QuotientSlope qs = law_->quotient_and_slope(at_, r);
            return {qs.quotient, qs.slope};
        }

    private:
        const PenaltyContact* law_;
        Anchored at_;
    };
    Gradient gradient(double a) const { return Gradient(*this, a); }

private:
    enum class Law { general, linear, three_halves, quadratic, cubic };
    // (Psi(a + r) - Psi(a)) / r and its slope in r where a > 0 and a + r > 0.
    double anchor(double a) const;
    // The solve's Newton steps evaluate the quotient at r and then its slope at the same r:
    // at alpha = 3/2 both need sqrt(a + r) and sqrt(a), for the general law (a + r)^(alpha+1)
    // and a^(alpha+1), computed once (root out, anchor_a in).
    double quotient(double a, double r, double anchor_a, double& root) const;
    double quotient_inside(double a, double r, double anchor_a, double& root) const;
    double slope(double a, double r, double quotient_value, double anchor_a, double root) const;
    ContactSolution solve(double a, double b, double k, bool model_start) const;
    // Newton's first iterate from a model of the equation: leaving contact (a > 0, root where
    // a + r <= 0) exactly; staying in contact the root of phi's Taylor parabola at r = 0; landing
    // (a <= 0) the root of a quadratic with the law's power frozen. Any value is safe: solve
    // brackets the root from wherever it starts.
    double first_iterate(double a, double b, double k, double anchor_a) const;
    // The landing model's scale y0 (a <= 0 < d, c > 0): what std::max of its two pows gives, bit
    // for bit, most often from one of them.
    double landing_scale(double a, double d, double c) const;
    // What solve starts from: first_iterate where it is finite and below b, else b.
    double first_iterate_or_b(double a, double b, double k, double anchor_a) const;
    double first_iterate_or_b(double a, double b, double k) const;  // any a and b
    double power(double eta) const;  // eta^alpha for eta > 0
    double potential_of(double eta) const;  // potential at eta > 0, its power computed here

    double k_;
    double alpha_;
    double potential_scale_ = 0.0;  // K / (alpha + 1)
    Law law_ = Law::general;
    bool specialise_ = true;
};

static_assert(ContactForceLaw<PenaltyContact>);

}  // namespace fretbuzz
