#pragma once
// What the scheme's contact solves need of a contact law, whatever the law: the scalar equation
// of the energy-conserving scheme (Issanchou et al. 2017, eq. 4) at one point,
//     r + k (Psi(a + r) - Psi(a)) / r = b,   r = eta^{n+1} - eta^{n-1}, a = eta^{n-1}, k = dt^2/mu,
// its discrete gradient and the gradient's slope (for the Newton solves that couple points), the
// potential Psi the energy counts. The solves are templates on the law (resolved when compiling:
// no call through a pointer at a point); PenaltyContact is the law of today. A law with a loss of
// its own (an impact law: a Hunt-Crossley term on the obstacle, as the fingers' and pluckers'
// pads have, ImpactLaw) would add the step's loss at a point to this interface, and the solves
// would hand it to the string's ledger.
#include <concepts>
#include <cstddef>
#include <span>

namespace fretbuzz {

// Marks a square root not computed (a real one is never negative).
inline constexpr double kNoRoot = -1.0;

struct ContactSolution {
    double increment = 0.0;  // r
    double force = 0.0;      // f = (Psi(a + r) - Psi(a)) / r  (force per unit length, N/m)
    int iterations = 0;
    // What the solve computed of a + r in contact, else kNoRoot: sqrt(a + r) at alpha = 3/2,
    // (a + r)^(alpha+1) for the general law. potential(a + r, root) then needs no square root
    // or pow of its own.
    double root = kNoRoot;
};

// The discrete gradient at one increment r, and its slope d/dr.
struct ForceSlope {
    double force, slope;
};

template <class Law>
concept ContactForceLaw = requires(const Law& law, double a, double b, double k, std::span<const double> as,
                              std::span<ContactSolution> out) {
    { law.solve(a, b, k) } -> std::same_as<ContactSolution>;
    // Many equations of one step at once (the same solutions as solve).
    { law.solve_all(as, as, k, out) } -> std::same_as<std::size_t>;
    { law.potential(a) } -> std::same_as<double>;
    { law.potential(a, b) } -> std::same_as<double>;  // with the solve's root of a
    { law.difference_quotient(a, b) } -> std::same_as<double>;
    { law.slope_of_quotient(a, b, k) } -> std::same_as<double>;
    // The gradient anchored at a (what one point's nested solve iterates on): g(r) -> ForceSlope.
    { law.gradient(a)(b) } -> std::same_as<ForceSlope>;
};

}  // namespace fretbuzz
