#pragma once
// The contact of a played part's pad with the string (a finger's, a plucker's): the penalty law
// f = K [y]_+^alpha (PenaltyContact) with a Hunt-Crossley loss rho r per unit length (Hunt and
// Crossley, J. Appl. Mech. 1975), r = y^{n+1} - y^{n-1} over the step. Its coefficient
// rho = lambda K [y^n]_+^alpha / (2 dt) is taken at level n, so that the step's push is the
// discrete gradient of the potential plus rho r and the step loses rho r^2 / 2 per unit length,
// never negative, exactly (the discretisation of Bilbao and Torin, JAES 2015).
#include "fretbuzz/scheme/ContactForceLaw.hpp"
#include "fretbuzz/scheme/PenaltyContact.hpp"

namespace fretbuzz {

class ImpactLaw {
public:
    // loss: lambda (s/m); dt: the time step.
    ImpactLaw(double stiffness, double exponent, double loss, double dt)
        : penalty_(stiffness, exponent), loss_(loss), dt_(dt) {}
    // New K and alpha, the same loss (allocates nothing).
    void set(double stiffness, double exponent) { penalty_.set(stiffness, exponent); }

    double potential(double y) const { return penalty_.potential(y); }
    double force(double y) const { return penalty_.force(y); }
    // rho of the step from y^n.
    double damping(double y_now) const { return loss_ * penalty_.force(y_now) / (2.0 * dt_); }

    // The step's push from y^{n-1} = c with damping rho, as a callable of r: the discrete
    // gradient (Psi(c + r) - Psi(c)) / r plus rho r, and its slope in r.
    class Push {
    public:
        Push(const PenaltyContact& penalty, double c, double rho) : gradient_(penalty.gradient(c)), rho_(rho) {}
        ForceSlope operator()(double r) const {
            const ForceSlope q = gradient_(r);
            return {q.force + rho_ * r, q.slope + rho_};
        }

    private:
        PenaltyContact::Gradient gradient_;
        double rho_;
    };
    Push push(double c, double rho) const { return Push(penalty_, c, rho); }

private:
    PenaltyContact penalty_;
    double loss_, dt_;
};

}  // namespace fretbuzz
