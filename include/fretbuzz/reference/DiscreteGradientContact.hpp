#pragma once
// The penalty contact law of the cross-check scheme, written apart from the modal code so
// that the comparison tests two independent implementations of the same mathematics:
// f(eta) = K [eta]_+^alpha, Psi(eta) = K/(alpha+1) [eta]_+^(alpha+1), and the discrete
// gradient f = (Psi(eta^{n+1}) - Psi(eta^{n-1})) / (eta^{n+1} - eta^{n-1}) of Bilbao, Torin
// and Chatziioannou (2015), which makes the contact exchange energy exactly.
namespace fretbuzz::reference {

struct ContactStep {
    double increment = 0.0;  // r = eta^{n+1} - eta^{n-1}
    double force = 0.0;      // discrete gradient at that increment (N/m)
    int iterations = 0;
};

class DiscreteGradientContact {
public:
    DiscreteGradientContact(double stiffness, double exponent);

    double potential(double eta) const;
    double force(double eta) const;
    // (Psi(a + r) - Psi(a)) / r, accurate to round-off for any r (f(a) at r = 0).
    double gradient(double a, double r) const;
    // Root r of r + k (Psi(a + r) - Psi(a)) / r = b (unique: the left side increases with r).
    ContactStep solve(double a, double b, double k) const;

private:
    double gradient_slope(double a, double r, double g) const;

    double stiffness_;
    double exponent_;
};

}  // namespace fretbuzz::reference
