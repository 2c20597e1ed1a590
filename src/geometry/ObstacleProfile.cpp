#include "fretbuzz/geometry/ObstacleProfile.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

std::vector<double> sample_profile_on_grid(const std::vector<double>& x, const std::vector<double>& height,
                                           const Grid& grid, const std::string& source) {
    for (std::size_t k = 1; k < x.size(); ++k)
        if (!(x[k] > x[k - 1]))
            throw InputError(source + ": obstacle x_m must increase strictly (row " + std::to_string(k + 1) + ")");
    const double tolerance = 1e-9 * grid.length_m;
    bool on_grid = x.size() == grid.points;
    for (std::size_t i = 0; on_grid && i < grid.points; ++i) on_grid = std::abs(x[i] - grid.x(i)) <= tolerance;
    if (on_grid) return height;

    std::vector<double> sampled(grid.points);
    for (std::size_t i = 0; i < grid.points; ++i) {
        const double xi = grid.x(i);
        if (xi < x.front() - tolerance || xi > x.back() + tolerance) {
            std::ostringstream msg;
            msg << source << ": the obstacle profile covers x in [" << x.front() << ", " << x.back()
                << "] m but the grid needs x = " << xi << " m; extend the profile over (0, L)";
            throw InputError(msg.str());
        }
        const auto upper = std::upper_bound(x.begin(), x.end(), xi);
        if (upper == x.begin()) {
            sampled[i] = height.front();
        } else if (upper == x.end()) {
            sampled[i] = height.back();
        } else {
            const std::size_t k = static_cast<std::size_t>(upper - x.begin());
            const double w = (xi - x[k - 1]) / (x[k] - x[k - 1]);
            sampled[i] = (1.0 - w) * height[k - 1] + w * height[k];
        }
    }
    return sampled;
}

}  // namespace fretbuzz
