#pragma once
// The shape of a string pinned at both ends, u(x) = sum_j q_j phi_j(x) with
// phi_j(x) = sqrt(2/L) sin(j pi x / L), at the N interior points x_i = i L / (N + 1) of a
// string described by N modal amplitudes. The scheme computes the same with its sine
// transform (numerics/ModalBasis); this direct sum lets a case be checked before any plan
// exists (Case::validate), at O(N^2) cost, a millisecond for the paper's 862 modes.
#include <span>
#include <vector>

namespace fretbuzz {

std::vector<double> pinned_string_shape_on_grid(double length_m, std::span<const double> amplitudes);

}  // namespace fretbuzz
