#include "fretbuzz/geometry/ParabolicBridge.hpp"

#include <limits>

namespace fretbuzz {

double ParabolicBridge::height_at(double x) const {
    if (x < position_m || x > position_m + length_m) return -std::numeric_limits<double>::infinity();
    const double offset = x - apex_m;
    return height_m - 0.5 * curvature_per_m * offset * offset;
}

std::vector<double> ParabolicBridge::sample(const Grid& grid) const {
    std::vector<double> g(grid.points);
    for (std::size_t i = 0; i < grid.points; ++i) g[i] = height_at(grid.x(i));
    return g;
}

}  // namespace fretbuzz
