#include "fretbuzz/geometry/InitialShape.hpp"

#include <algorithm>
#include <array>
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

namespace {

// The upper concave hull of points sorted by x (Andrew's monotone chain, upper half).
std::vector<std::array<double, 2>> upper_hull(const std::vector<std::array<double, 2>>& points) {
    std::vector<std::array<double, 2>> hull;
    for (const auto& p : points) {
        while (hull.size() >= 2) {
            const auto& a = hull[hull.size() - 2];
            const auto& b = hull.back();
            // Drop b when it lies on or below the segment a-p.
            if ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) >= 0.0)
                hull.pop_back();
            else
                break;
        }
        hull.push_back(p);
    }
    return hull;
}

}  // namespace

std::vector<double> taut_over_obstacle(const Grid& grid, std::vector<double> u, const std::vector<double>& obstacle,
                                       std::span<const std::array<double, 2>> points, double position, double width) {
    constexpr double kAbove = 1e-12;  // m: round-off never puts the string into what it rests on
    const auto side = [&](std::size_t first, std::size_t last, double end_x) {  // grid points [first, last)
        if (first >= last) return;
        const std::size_t edge = end_x < grid.x(first) ? last - 1 : first;
        // The exact points between the string's end and the corner's edge, where the side is straight.
        const auto on_side = [&](double x) { return (x - end_x) * (grid.x(edge) - x) > 0.0; };
        const auto straight = [&](double x) { return u[edge] * (x - end_x) / (grid.x(edge) - end_x); };
        bool in_the_way = false;
        for (std::size_t i = first; i < last; ++i) in_the_way |= std::isfinite(obstacle[i]) && u[i] < obstacle[i] + kAbove;
        for (const auto& [x, height] : points) in_the_way |= on_side(x) && straight(x) < height + kAbove;
        if (!in_the_way) return;
        // The string's end and the corner's edge, and the obstacle's points between them.
        std::vector<std::array<double, 2>> corners{{end_x, 0.0}};
        for (std::size_t i = first; i < last; ++i)
            if (std::isfinite(obstacle[i])) corners.push_back({grid.x(i), obstacle[i] + kAbove});
        for (const auto& [x, height] : points)
            if (on_side(x)) corners.push_back({x, height + kAbove});
        corners.push_back({grid.x(edge), u[edge]});
        std::sort(corners.begin(), corners.end());
        const std::vector<std::array<double, 2>> hull = upper_hull(corners);
        for (std::size_t i = first; i < last; ++i) {
            const double x = grid.x(i);
            const auto right = std::lower_bound(hull.begin(), hull.end(), std::array<double, 2>{x, -1e300});
            if (right == hull.begin() || right == hull.end()) continue;
            const auto left = right - 1;
            const double t = ((*right)[0] - (*left)[0]) > 0.0 ? (x - (*left)[0]) / ((*right)[0] - (*left)[0]) : 0.0;
            u[i] = std::max(u[i], (*left)[1] + t * ((*right)[1] - (*left)[1]));
        }
    };
    std::size_t corner_start = 0, corner_end = grid.points;
    for (std::size_t i = 0; i < grid.points; ++i) {
        if (grid.x(i) < position - 0.5 * width) corner_start = i + 1;
        if (grid.x(i) > position + 0.5 * width && corner_end == grid.points) corner_end = i;
    }
    side(0, corner_start, 0.0);
    side(corner_end, grid.points, grid.length_m);
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
