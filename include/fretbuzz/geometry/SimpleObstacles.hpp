#pragma once
// Elementary obstacles sampled on the grid, and their union. Heights are in m, negative
// below the string's rest line; -infinity where there is nothing to touch.
#include <vector>

#include "fretbuzz/geometry/ObstacleProfile.hpp"

namespace fretbuzz {

// Nothing anywhere.
std::vector<double> no_obstacle(const Grid& grid);
// A flat surface at height over [start, end]; nothing elsewhere.
std::vector<double> flat_obstacle(const Grid& grid, double height, double start, double end);
// Point obstacles (a tanpura's thread, a capo edge): each occupies the grid point
// nearest to its position.
std::vector<double> point_obstacles(const Grid& grid, const std::vector<double>& positions,
                                    const std::vector<double>& heights);
// Several obstacles at once: the string meets whichever is highest at each point.
std::vector<double> highest_of(const std::vector<std::vector<double>>& obstacles);
// Index of the grid point nearest to x (clamped to the grid).
std::size_t nearest_grid_point(const Grid& grid, double x);

}  // namespace fretbuzz
