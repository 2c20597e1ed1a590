#pragma once
// The penalty contact law f = K [eta]_+^alpha with potential Psi = K/(alpha+1) [eta]_+^(alpha+1),
// eta = g - u (Issanchou et al. 2017, section 2.2), and the scalar implicit equation the
// energy-conserving scheme (eq. 4) reduces to at each grid point:
//     r + k (Psi(a + r) - Psi(a)) / r = b,   r = eta^{n+1} - eta^{n-1}, a = eta^{n-1}, k = dt^2/mu.
// The left side is increasing and convex in r, so the root is unique; it is found by
// Newton's method from the right (monotone for a convex function), inside a bracket that
// bisection falls back on, and it fails loudly rather than silently.
namespace fretbuzz {

struct ContactSolution {
    double increment = 0.0;  // r
    double force = 0.0;      // f = (Psi(a + r) - Psi(a)) / r  (force per unit length, N/m)
    int iterations = 0;
};

class PenaltyContact {
public:
    PenaltyContact(double stiffness, double exponent);

    double stiffness() const { return k_; }
    double exponent() const { return alpha_; }
    double potential(double eta) const;  // Psi(eta)
    double force(double eta) const;      // Psi'(eta)
    // (Psi(a + r) - Psi(a)) / r without cancellation; Psi'(a) at r = 0.
    double difference_quotient(double a, double r) const;
    // Solves the scalar equation above; throws SolverError if it cannot converge.
    ContactSolution solve(double a, double b, double k) const;
    // d/dr of difference_quotient(a, r), given that quotient (>= 0: Psi is convex).
    double slope_of_quotient(double a, double r, double quotient) const;

private:

    double k_;
    double alpha_;
};

}  // namespace fretbuzz
