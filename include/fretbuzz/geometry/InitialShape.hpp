#pragma once
// Initial string shapes u(x, 0) on the grid.
#include <vector>

#include "fretbuzz/geometry/ObstacleProfile.hpp"

namespace fretbuzz {

// A pluck: straight lines from the ends to (position, amplitude).
std::vector<double> triangle_shape(const Grid& grid, double position, double amplitude);

}  // namespace fretbuzz
