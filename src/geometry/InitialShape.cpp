#include "fretbuzz/geometry/InitialShape.hpp"

#include <cmath>
#include <numbers>

namespace fretbuzz {

std::vector<double> triangle_shape(const Grid& grid, double position, double amplitude) {
    std::vector<double> u(grid.points);
    for (std::size_t i = 0; i < grid.points; ++i) {
        const double x = grid.x(i);
        u[i] = x <= position ? amplitude * x / position : amplitude * (grid.length_m - x) / (grid.length_m - position);
    }
    return u;
}

std::vector<double> rounded_triangle_shape(const Grid& grid, double position, double width, double amplitude) {
    // A unit triangle first: slopes of its two sides and the start of the rounded part.
    const double left_slope = 1.0 / position;
    const double right_slope = -1.0 / (grid.length_m - position);
    const double start = position - 0.5 * width;
    const double start_height = start * left_slope;
    // Over the rounded part the slope goes linearly from left_slope to right_slope, which
    // meets the right side exactly at position + width/2 (the width is centred on the corner).
    auto rounded = [&](double x) {
        const double s = x - start;
        return start_height + left_slope * s + (right_slope - left_slope) * s * s / (2.0 * width);
    };
    const double top = start_height + 0.5 * left_slope * width * left_slope / (left_slope - right_slope);
    const double scale = amplitude / top;

    std::vector<double> u = triangle_shape(grid, position, 1.0);
    for (std::size_t i = 0; i < grid.points; ++i) {
        const double x = grid.x(i);
        if (std::abs(x - position) < 0.5 * width) u[i] = rounded(x);
        u[i] *= scale;
    }
    return u;
}

std::vector<double> raised_cosine_velocity(const Grid& grid, double position, double width, double peak_velocity) {
    std::vector<double> v(grid.points, 0.0);
    for (std::size_t i = 0; i < grid.points; ++i) {
        const double offset = grid.x(i) - position;
        if (std::abs(offset) < 0.5 * width)
            v[i] = 0.5 * peak_velocity * (1.0 + std::cos(2.0 * std::numbers::pi * offset / width));
    }
    return v;
}

}  // namespace fretbuzz
