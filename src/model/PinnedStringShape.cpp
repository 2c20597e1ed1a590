#include "fretbuzz/model/PinnedStringShape.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace fretbuzz {

std::vector<double> pinned_string_shape_on_grid(double length_m, std::span<const double> amplitudes) {
    const std::size_t n = amplitudes.size();
    std::vector<double> u(n, 0.0);
    const double scale = std::sqrt(2.0 / length_m);
    // Clenshaw's recurrence for sum_j q_j sin(j theta): one cosine per point, not one sine per
    // term. Each point's recurrence is a chain of dependent multiply-adds; kPoints of them run
    // side by side so that the chains overlap (the sum is O(n^2), a millisecond at 1000 modes).
    constexpr std::size_t kPoints = 8;
    for (std::size_t first = 0; first < n; first += kPoints) {
        const std::size_t count = std::min(kPoints, n - first);
        double two_cos[kPoints] = {}, b1[kPoints] = {}, b2[kPoints] = {};
        for (std::size_t p = 0; p < count; ++p)
            two_cos[p] = 2.0 * std::cos(std::numbers::pi * static_cast<double>(first + p + 1) / static_cast<double>(n + 1));
        for (std::size_t j = n; j-- > 0;) {
            for (std::size_t p = 0; p < kPoints; ++p) {
                const double b0 = amplitudes[j] + two_cos[p] * b1[p] - b2[p];
                b2[p] = b1[p];
                b1[p] = b0;
            }
        }
        for (std::size_t p = 0; p < count; ++p) {
            const double theta = std::numbers::pi * static_cast<double>(first + p + 1) / static_cast<double>(n + 1);
            u[first + p] = scale * b1[p] * std::sin(theta);
        }
    }
    return u;
}

}  // namespace fretbuzz
