#include "fretbuzz/numerics/TimeProfile.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fretbuzz {

TimeProfile::TimeProfile(std::vector<std::array<double, 2>> points) : points_(std::move(points)) {}

double TimeProfile::at(double t) const {
    if (points_.empty()) return 0.0;
    if (t <= points_.front()[0]) return points_.front()[1];
    if (t >= points_.back()[0]) return points_.back()[1];
    const auto after =
        std::upper_bound(points_.begin(), points_.end(), t, [](double v, const auto& p) { return v < p[0]; });
    const auto before = after - 1;
    const double s = (t - (*before)[0]) / ((*after)[0] - (*before)[0]);
    return (*before)[1] + s * ((*after)[1] - (*before)[1]);
}

double TimeProfile::zero_from() const {
    std::size_t k = points_.size();
    while (k > 0 && points_[k - 1][1] == 0.0) --k;
    if (k == 0) return -std::numeric_limits<double>::infinity();
    if (k == points_.size()) return std::numeric_limits<double>::infinity();
    return points_[k][0];  // the first zero after the last non-zero value
}

std::vector<std::size_t> pad_points(double centre, double width, double dx, std::size_t points) {
    std::vector<std::size_t> pad;
    pad_points(centre, width, dx, points, pad);
    return pad;
}

void pad_points(double centre, double width, double dx, std::size_t points, std::vector<std::size_t>& pad) {
    pad.clear();
    const double half = 0.5 * width * (1.0 + 1e-12);
    for (std::size_t i = 0; i < points; ++i)
        if (std::abs(static_cast<double>(i + 1) * dx - centre) <= half) pad.push_back(i);
    if (pad.empty()) {  // a pad narrower than the grid step still acts on its nearest point
        const double nearest = std::clamp(std::round(centre / dx), 1.0, static_cast<double>(points));
        pad.push_back(static_cast<std::size_t>(nearest) - 1);
    }
}

}  // namespace fretbuzz
