#include "fretbuzz/geometry/Fretboard.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fretbuzz/geometry/FretPositions.hpp"
#include "fretbuzz/geometry/SimpleObstacles.hpp"

namespace fretbuzz {

NeckRelief NeckRelief::straight() { return {}; }

NeckRelief NeckRelief::bow(double depth_m) {
    NeckRelief r;
    r.bow_depth_m_ = depth_m;
    return r;
}

NeckRelief NeckRelief::curve(std::vector<double> x_m, std::vector<double> depth_m) {
    NeckRelief r;
    r.x_m_ = std::move(x_m);
    r.depth_m_ = std::move(depth_m);
    return r;
}

double NeckRelief::depth_at(double x, double last_fret_m) const {
    if (x <= 0.0 || x >= last_fret_m) return 0.0;
    if (x_m_.empty()) {
        const double s = x / last_fret_m;
        return 4.0 * bow_depth_m_ * s * (1.0 - s);
    }
    // Linear between (0, 0), the measured points and (last fret, 0).
    const auto upper = std::upper_bound(x_m_.begin(), x_m_.end(), x);
    const auto k = static_cast<std::size_t>(upper - x_m_.begin());
    const double x0 = k == 0 ? 0.0 : x_m_[k - 1];
    const double d0 = k == 0 ? 0.0 : depth_m_[k - 1];
    const double x1 = k == x_m_.size() ? last_fret_m : x_m_[k];
    const double d1 = k == x_m_.size() ? 0.0 : depth_m_[k];
    return d0 + (d1 - d0) * (x - x0) / (x1 - x0);
}

double Fretboard::fret_position(std::size_t n) const {
    return fretbuzz::fret_position(scale_length_m, n);
}

double Fretboard::fret_line_height(double x) const {
    const double last = fret_position(fret_count);
    const double action = action_at_nut_m + (action_at_last_fret_m - action_at_nut_m) * x / last;
    return -action - relief.depth_at(x, last);
}

double Fretboard::fret_top_height(std::size_t n) const {
    const auto offset = fret_height_offset_m.find(n);
    return fret_line_height(fret_position(n)) + (offset == fret_height_offset_m.end() ? 0.0 : offset->second);
}

std::vector<double> Fretboard::sample(const Grid& grid) const { return sample(grid, true); }

std::vector<double> Fretboard::sample_board(const Grid& grid) const { return sample(grid, !point_crowns()); }

std::vector<std::pair<double, double>> Fretboard::crowns() const {
    std::vector<std::pair<double, double>> out;
    for (std::size_t n = 1; n <= fret_count; ++n) out.emplace_back(fret_position(n), fret_top_height(n));
    return out;
}

std::vector<double> Fretboard::sample(const Grid& grid, bool with_point_crowns) const {
    const double nothing = -std::numeric_limits<double>::infinity();
    // Round-off in x_i must not move a grid point that sits on the end of the board.
    const double board_end = board_end_m + 1e-9 * grid.length_m;
    std::vector<double> g(grid.points);
    for (std::size_t i = 0; i < grid.points; ++i) {
        const double x = grid.x(i);
        g[i] = x <= board_end ? fret_line_height(x) - fret_height_m : body_height_m.value_or(nothing);
    }
    for (std::size_t n = 1; n <= fret_count; ++n) {
        const double xn = fret_position(n);
        const double top = fret_top_height(n);
        for (std::size_t i = 0; i < grid.points; ++i)
            if (std::abs(grid.x(i) - xn) <= 0.5 * crown_width_m) g[i] = std::max(g[i], top);
        if (!with_point_crowns) continue;
        double& nearest = g[nearest_grid_point(grid, xn)];
        nearest = std::max(nearest, top);
    }
    return g;
}

}  // namespace fretbuzz
