#pragma once
// [obstacle] with type = "fretboard": a fretted neck from its measurements.
#include <vector>

#include "TomlSection.hpp"
#include "fretbuzz/Case.hpp"
#include "fretbuzz/geometry/ObstacleProfile.hpp"

namespace fretbuzz {

// The board on the grid; crowns of zero width, as exact points of width `grid.length_m /
// (grid.points + 1)` (one grid step), appended to `points`; the frets' exact positions x_n,
// whatever their crowns' width, appended to `frets`.
std::vector<double> read_fretboard(TomlSection& section, const Grid& grid, std::vector<PointObstacle>& points,
                                   std::vector<double>& frets);

}  // namespace fretbuzz
