#include "fretbuzz/geometry/InitialShape.hpp"

namespace fretbuzz {

std::vector<double> triangle_shape(const Grid& grid, double position, double amplitude) {
    std::vector<double> u(grid.points);
    for (std::size_t i = 0; i < grid.points; ++i) {
        const double x = grid.x(i);
        u[i] = x <= position ? amplitude * x / position : amplitude * (grid.length_m - x) / (grid.length_m - position);
    }
    return u;
}

}  // namespace fretbuzz
