#pragma once
// [obstacle] with type = "fretboard": a fretted neck from its measurements.
#include <vector>

#include "TomlSection.hpp"
#include "fretbuzz/Case.hpp"
#include "fretbuzz/geometry/ObstacleProfile.hpp"

namespace fretbuzz {

// The board on the grid; crowns of zero width, as exact points of width `grid.length_m /
// (grid.points + 1)` (one grid step), appended to `points`.
std::vector<double> read_fretboard(TomlSection& section, const Grid& grid, std::vector<PointObstacle>& points);

}  // namespace fretbuzz
