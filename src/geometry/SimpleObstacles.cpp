#include "fretbuzz/geometry/SimpleObstacles.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fretbuzz {

std::vector<double> no_obstacle(const Grid& grid) {
    return std::vector<double>(grid.points, -std::numeric_limits<double>::infinity());
}

std::vector<double> flat_obstacle(const Grid& grid, double height, double start, double end) {
    std::vector<double> g = no_obstacle(grid);
    for (std::size_t i = 0; i < grid.points; ++i)
        if (grid.x(i) >= start && grid.x(i) <= end) g[i] = height;
    return g;
}

std::size_t nearest_grid_point(const Grid& grid, double x) {
    const double index = std::round(x / grid.step()) - 1.0;
    if (index <= 0.0) return 0;
    return std::min(static_cast<std::size_t>(index), grid.points - 1);
}

std::vector<double> point_obstacles(const Grid& grid, const std::vector<double>& positions,
                                    const std::vector<double>& heights) {
    std::vector<double> g = no_obstacle(grid);
    for (std::size_t k = 0; k < positions.size() && k < heights.size(); ++k) {
        double& gi = g[nearest_grid_point(grid, positions[k])];
        gi = std::max(gi, heights[k]);
    }
    return g;
}

std::vector<double> highest_of(const std::vector<std::vector<double>>& obstacles) {
    if (obstacles.empty()) return {};
    std::vector<double> g = obstacles.front();
    for (std::size_t k = 1; k < obstacles.size(); ++k)
        for (std::size_t i = 0; i < g.size() && i < obstacles[k].size(); ++i) g[i] = std::max(g[i], obstacles[k][i]);
    return g;
}

}  // namespace fretbuzz
