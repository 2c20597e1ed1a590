#include "fretbuzz/model/PinnedStringShape.hpp"

#include <cmath>
#include <numbers>

namespace fretbuzz {

std::vector<double> pinned_string_shape_on_grid(double length_m, std::span<const double> amplitudes) {
    const std::size_t n = amplitudes.size();
    std::vector<double> u(n, 0.0);
    const double scale = std::sqrt(2.0 / length_m);
    for (std::size_t i = 0; i < n; ++i) {
        const double theta = std::numbers::pi * static_cast<double>(i + 1) / static_cast<double>(n + 1);
        // Clenshaw's recurrence for sum_j q_j sin(j theta): one cosine per point, not one sine per term.
        const double two_cos = 2.0 * std::cos(theta);
        double b1 = 0.0;
        double b2 = 0.0;
        for (std::size_t j = n; j-- > 0;) {
            const double b0 = amplitudes[j] + two_cos * b1 - b2;
            b2 = b1;
            b1 = b0;
        }
        u[i] = scale * b1 * std::sin(theta);
    }
    return u;
}

}  // namespace fretbuzz
