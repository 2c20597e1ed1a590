#pragma once
// Obstacle profiles g(x) given as points (x, height) and sampled on the scheme's grid.
// A profile that already sits on the grid is used as it is (the paper's neck data put
// each fret on exactly one grid point); otherwise it is interpolated linearly.
#include <cstddef>
#include <string>
#include <vector>

namespace fretbuzz {

struct Grid {
    double length_m;
    std::size_t points;  // interior points x_i = i L/(points+1), i = 1..points
    double step() const { return length_m / static_cast<double>(points + 1); }
    double x(std::size_t i) const { return static_cast<double>(i + 1) * step(); }
};

std::vector<double> sample_profile_on_grid(const std::vector<double>& x, const std::vector<double>& height,
                                           const Grid& grid, const std::string& source);

}  // namespace fretbuzz
