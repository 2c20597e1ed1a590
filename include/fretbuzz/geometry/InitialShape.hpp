#pragma once
// Initial string shapes u(x, 0) and velocity fields du/dt(x, 0) on the grid.
#include <array>
#include <span>
#include <vector>

#include "fretbuzz/geometry/ObstacleProfile.hpp"

namespace fretbuzz {

// A pluck: straight lines from the ends to (position, amplitude).
std::vector<double> triangle_shape(const Grid& grid, double position, double amplitude);

// A pluck by a finger or a wire of finite width (the "rounded triangle" of Issanchou et
// al. 2017): a triangle whose corner at `position` is replaced, over [position - width/2,
// position + width/2], by the parabola tangent to both sides. Scaled so that its maximum
// is `amplitude`. Needs 0 < position - width/2 and position + width/2 < L.
std::vector<double> rounded_triangle_shape(const Grid& grid, double position, double width, double amplitude);

// A string pulled toward an obstacle below it and held there, as `shape` (a pluck with its
// corner rounded over [position - width/2, position + width/2]) would have it but lying taut
// over what it meets: on each side of the corner, where the straight string would pass below
// the obstacle, it bends over the obstacle's points instead (the upper concave hull of the
// string's end, those points and the corner's edge), a picometre above them. `obstacle`: the
// heights at the grid points (-inf: none); `points`: obstacle points at their exact x, as
// {x, height} (frets that act off the grid). Unchanged where nothing is in the way.
std::vector<double> taut_over_obstacle(const Grid& grid, std::vector<double> shape, const std::vector<double>& obstacle,
                                       std::span<const std::array<double, 2>> points, double position, double width);

// A strike (a hammer or a slap): a raised-cosine velocity distribution
// v(x) = v_peak (1 + cos(2 pi (x - position) / width)) / 2 for |x - position| < width/2,
// zero elsewhere.
std::vector<double> raised_cosine_velocity(const Grid& grid, double position, double width, double peak_velocity);

}  // namespace fretbuzz
