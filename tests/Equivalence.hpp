#pragma once
// The stated tolerance of equivalent paths: the fast and the straightforward path, one pass
// over the modes and a pass per product, the batch and the scalar contact solve. They form the
// same quantities in other orders or forms, so they agree to round-off, far below it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <span>

namespace fretbuzz::testing {

inline constexpr double kEquivalence = 1e-12;

// |x - y| <= tolerance * scale, the scale max(|x|, |y|) unless a larger one is given (the size
// of the terms a sum was formed from, where they cancel).
inline ::testing::AssertionResult agree(double x, double y, double scale = 0.0, double tolerance = kEquivalence) {
    const double s = std::max({scale, std::abs(x), std::abs(y)});
    if (std::abs(x - y) <= tolerance * s) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << x << " and " << y << " differ by " << std::abs(x - y) / s
                                         << " relative to " << s << " (tolerance " << tolerance << ")";
}

// ||x - y|| <= tolerance ||y|| (relative L2), and the same sizes.
inline ::testing::AssertionResult agree(std::span<const double> x, std::span<const double> y,
                                        double tolerance = kEquivalence) {
    if (x.size() != y.size()) return ::testing::AssertionFailure() << "sizes " << x.size() << " and " << y.size();
    double diff = 0.0, norm = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        diff += (x[i] - y[i]) * (x[i] - y[i]);
        norm += y[i] * y[i];
    }
    if (std::sqrt(diff) <= tolerance * std::sqrt(norm)) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "relative L2 difference " << std::sqrt(diff / norm) << " (tolerance "
                                         << tolerance << ")";
}

}  // namespace fretbuzz::testing
