#pragma once
// A curved bridge such as the sitar's or the tanpura's: a parabola of curvature kappa
// with its apex (highest point) at x_apex,
//   g(x) = height - kappa (x - x_apex)^2 / 2   for x in [position, position + length],
// nothing elsewhere. The string wraps around it, which is what makes these instruments
// buzz (see e.g. van Walstijn, Chatziioannou & Bhanuprakash, "Implicit and explicit
// schemes for the simulation of string vibrations against a distributed bridge", and
// Issanchou et al., DAFx-16).
#include <vector>

#include "fretbuzz/geometry/ObstacleProfile.hpp"

namespace fretbuzz {

struct ParabolicBridge {
    double position_m = 0.0;  // start of the bridge (its end nearer x = 0)
    double length_m = 0.0;
    double height_m = 0.0;    // at the apex
    double curvature_per_m = 0.0;
    double apex_m = 0.0;      // in [position, position + length]

    double height_at(double x) const;  // -inf off the bridge
    std::vector<double> sample(const Grid& grid) const;
};

}  // namespace fretbuzz
