#pragma once
// One continuous problem, stated once, that both discretisations are built from: a stiff,
// damped string with simply supported ends against an obstacle,
//     mu u_tt = T u_xx - EI u_xxxx - 2 mu sigma0 u_t + K [g - u]_+^alpha,
// released at rest from u(x, 0). The finite-difference scheme samples it on its own grid;
// to_modal_case() turns it into a Case for the modal scheme whose modes are the exact
// modes of this PDE (nu_j = j c / (2L) sqrt(1 + B j^2), sigma_j = sigma0).
#include <cstddef>
#include <functional>

#include "fretbuzz/Case.hpp"

namespace fretbuzz::reference {

struct StringProblem {
    double length_m = 1.0;
    double tension_n = 1.0;
    double linear_density = 1.0;
    double bending_stiffness = 0.0;  // EI (N m^2)
    double loss_per_s = 0.0;         // sigma0, the same for every frequency
    std::function<double(double)> obstacle;       // g(x); -infinity where there is none
    std::function<double(double)> initial_shape;  // u(x, 0), must clear the obstacle
    double contact_stiffness = 1e8;
    double contact_exponent = 1.5;

    double wave_speed() const;
    // Checks the numbers; throws InputError naming the first bad one.
    void validate() const;
};

struct ModalDiscretisation {
    std::size_t modes = 0;      // Nm (grid of Nm interior points)
    double sample_rate_hz = 0;  // Fe
    double duration_s = 0;
    double output_rate_hz = 0;  // must divide Fe
    double observation_point_m = 0;
};

Case to_modal_case(const StringProblem& problem, const ModalDiscretisation& discretisation);

}  // namespace fretbuzz::reference
