// Initial shapes and velocity fields, and their projection on the modes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "fretbuzz/geometry/InitialShape.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/numerics/ModalBasis.hpp"

namespace fretbuzz {
namespace {

const Grid kFine{1.0, 9999};  // dx = 0.1 mm

TEST(Excitations, RoundedTriangleReachesItsAmplitudeWithoutAKink) {
    const double position = 0.3, width = 0.05, amplitude = 2e-3;
    const std::vector<double> u = rounded_triangle_shape(kFine, position, width, amplitude);
    const double top = *std::max_element(u.begin(), u.end());
    EXPECT_NEAR(top, amplitude, 1e-9);
    // A sharp triangle's second difference spikes at its corner (|slope jump| dx ~ 1e-6 m);
    // the rounded one's stays at the parabola's (kappa dx^2 ~ 1e-9 m) everywhere.
    double largest_second_difference = 0.0;
    for (std::size_t i = 1; i + 1 < u.size(); ++i)
        largest_second_difference = std::max(largest_second_difference, std::abs(u[i + 1] - 2.0 * u[i] + u[i - 1]));
    const double slope_jump = amplitude / position + amplitude / (1.0 - position);
    const double dx = kFine.step();
    EXPECT_LT(largest_second_difference, 1.1 * slope_jump / width * dx * dx);
    // Away from the rounding it is a straight line through the ends (scaled triangle).
    const double scale = u[999] / kFine.x(999);  // x = 0.1
    EXPECT_NEAR(u[1999], scale * kFine.x(1999), 1e-15);
    EXPECT_NEAR(u[7999] / (1.0 - kFine.x(7999)), u[8999] / (1.0 - kFine.x(8999)), 1e-12);
}

TEST(Excitations, RoundedTriangleTendsToTheTriangleAsItsWidthVanishes) {
    const std::vector<double> sharp = triangle_shape(kFine, 0.4, 1e-3);
    const std::vector<double> rounded = rounded_triangle_shape(kFine, 0.4, 1e-6, 1e-3);
    for (std::size_t i = 0; i < sharp.size(); i += 97) EXPECT_NEAR(rounded[i], sharp[i], 1e-8);
}

TEST(Excitations, RaisedCosineStrikePeaksAtItsCentreAndVanishesOutside) {
    const std::vector<double> v = raised_cosine_velocity(kFine, 0.5, 0.02, 3.0);
    EXPECT_NEAR(v[4999], 3.0, 1e-12);              // x = 0.5
    EXPECT_NEAR(v[4949], 1.5, 1e-12);              // x = 0.495, a quarter width off
    EXPECT_NEAR(v[4899], 0.0, 1e-12);              // x = 0.49, the edge
    EXPECT_EQ(v[5200], 0.0);
    double integral = 0.0;
    for (double vi : v) integral += vi * kFine.step();
    EXPECT_NEAR(integral, 3.0 * 0.02 / 2.0, 1e-9);  // the mean of a raised cosine is half its peak
}

TEST(Excitations, StrikeCaseStartsAtRestWithTheVelocityField) {
    const std::string text = R"(
name = "strike"
[string]
L = 1.0
T = 100.0
mu = 1e-3
modes = 199
[modes.frequency]
model = "harmonic"
[modes.damping]
model = "none"
[obstacle]
type = "none"
[excitation]
type = "strike"
position = 0.25
width = 0.05
velocity = 2.0
[contact]
K = 1e10
alpha = 1.5
[run]
fs = 48000
duration = 0.01
[observe]
x = [0.5]
)";
    const Case c = parse_case(text, "strike.toml", DataSource::directory("."));
    c.validate();
    for (double q : c.initial_displacement) EXPECT_EQ(q, 0.0);
    const ModalBasis basis(1.0, 199);
    const std::vector<double> v = basis.displacement_at_grid(c.initial_velocity);
    const std::vector<double> expected = raised_cosine_velocity(Grid{1.0, 199}, 0.25, 0.05, 2.0);
    for (std::size_t i = 0; i < v.size(); ++i) EXPECT_NEAR(v[i], expected[i], 1e-12) << "x = " << basis.grid_point(i);
}

}  // namespace
}  // namespace fretbuzz
