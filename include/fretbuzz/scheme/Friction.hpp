#pragma once
// Regularised Coulomb friction along y at a point in contact along z: the force per unit
// length f = -mu_f F_n phi(v), phi(v) = v / sqrt(v^2 + v_eps^2) (odd, increasing, |phi| < 1),
// with v = (y^{n+1} - y^{n-1}) / (2 dt) the centred sliding velocity. In the scheme
// y^{n+1} = w + k f at that point only (k = dt^2/mu, w the prediction without the force),
// so v solves the scalar equation
//     v + K phi(v) = v0,   v0 = (w - y^{n-1}) / (2 dt),   K = k mu_f F_n / (2 dt) >= 0,
// whose left side is increasing: one root, between v0 - K and v0, on the side of v0.
// On v >= 0 the left side is concave, so Newton's method from the bracket's low end climbs
// monotonically to the root. The work f (y^{n+1} - y^{n-1}) / 2 = -mu_f F_n phi(v) v dt is
// never positive: friction only dissipates.
namespace fretbuzz {

struct FrictionSolution {
    double velocity = 0.0;  // v
    double force = 0.0;     // f (N/m)
    int iterations = 0;
};

class Friction {
public:
    Friction(double coefficient, double regularisation_velocity);

    double coefficient() const { return mu_; }
    double regularisation_velocity() const { return v_eps_; }
    double phi(double v) const;
    // Solves the equation above for normal force density |F_n| = normal; throws SolverError
    // if Newton's method fails to converge.
    FrictionSolution solve(double v0, double normal, double k, double dt) const;

private:
    double mu_;
    double v_eps_;
};

}  // namespace fretbuzz
