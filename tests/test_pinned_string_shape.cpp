// The direct sum that checks a case's initial shape against the scheme's sine transform.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "fretbuzz/model/PinnedStringShape.hpp"
#include "fretbuzz/numerics/ModalBasis.hpp"

using namespace fretbuzz;

TEST(PinnedStringShape, EqualsTheSineTransformOnTheGrid) {
    for (const std::size_t modes : {1u, 7u, 110u, 862u}) {
        std::mt19937 random(static_cast<unsigned>(modes));
        std::normal_distribution<double> normal;
        std::vector<double> q(modes);
        for (std::size_t j = 0; j < modes; ++j) q[j] = normal(random) / static_cast<double>(j + 1);
        const ModalBasis basis(0.863, modes);
        const std::vector<double> fast = basis.displacement_at_grid(q);
        const std::vector<double> direct = pinned_string_shape_on_grid(0.863, q);
        double difference = 0.0, norm = 0.0;
        for (std::size_t i = 0; i < modes; ++i) {
            difference += (fast[i] - direct[i]) * (fast[i] - direct[i]);
            norm += fast[i] * fast[i];
        }
        EXPECT_LT(std::sqrt(difference / norm), 1e-12) << modes << " modes";
    }
}

TEST(PinnedStringShape, OneModeIsItsSine) {
    const std::vector<double> q{0.0, 0.0, 2.0};  // mode 3 only
    const std::vector<double> u = pinned_string_shape_on_grid(2.0, q);
    for (std::size_t i = 0; i < u.size(); ++i) {
        const double x = 2.0 * static_cast<double>(i + 1) / 4.0;
        EXPECT_NEAR(u[i], 2.0 * std::sin(3.0 * std::numbers::pi * x / 2.0), 1e-15);
    }
}
