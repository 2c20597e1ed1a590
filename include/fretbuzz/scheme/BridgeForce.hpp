#pragma once
// The force of the string on its bridge end, from the modal displacements. At x = L the
// string pulls on its support with F = -(T u_x(L) - EI u_xxx(L)) (positive along +u: a
// string displaced up pulls the bridge up). For mode j, phi_j = sqrt(2/L) sin(k_j x),
// k_j = j pi / L, and T k_j + EI k_j^3 = mu omega_j^2 / k_j for the stiff string with
// simply supported ends, so
//   F = sum_j b_j q_j,   b_j = -sqrt(2/L) (-1)^j mu omega_j^2 / k_j,
// which holds for any mode table (measured frequencies included): each mode's elastic
// restoring force mu omega_j^2 q_j, taken at the end.
#include <vector>

#include "fretbuzz/Case.hpp"

namespace fretbuzz {

// b_j, j = 1..Nm (N per m of modal displacement).
std::vector<double> bridge_force_coefficients(const Case& c);

}  // namespace fretbuzz
