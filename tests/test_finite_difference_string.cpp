// The finite-difference cross-check scheme keeps its own discrete energy: constant to
// round-off without losses, and decreasing by exactly the damping term with them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/reference/DiscreteGradientContact.hpp"
#include "fretbuzz/reference/FiniteDifferenceString.hpp"

namespace fretbuzz::reference {
namespace {

StringProblem guitar_like_problem() {
    StringProblem p;  // a guitar string over a flat fingerboard 1 mm below its rest line
    p.length_m = 0.65;
    p.tension_n = 70.0;
    p.linear_density = 4e-4;
    p.bending_stiffness = 5e-5;
    p.obstacle = [](double) { return -1e-3; };
    p.initial_shape = [](double x) { return 2e-3 * std::sin(std::numbers::pi * x / 0.65); };
    p.contact_stiffness = 1e13;
    p.contact_exponent = 1.5;
    return p;
}

struct EnergyTrace {
    double max_relative_drift = 0.0;  // max |H + dissipated - H^{1/2}| / H^{1/2}
    double max_relative_increase = 0.0;
    long contact_steps = 0;
};

EnergyTrace trace_energy(const StringProblem& p, std::size_t intervals, long steps) {
    FiniteDifferenceString string(p, intervals, 0.95 * stability_limit(p, intervals));
    EnergyTrace trace;
    string.step();
    const double initial = string.energy();
    double previous = initial;
    for (long n = 2; n <= steps; ++n) {
        string.step();
        trace.max_relative_drift =
            std::max(trace.max_relative_drift, std::abs(string.energy() + string.dissipated() - initial) / initial);
        trace.max_relative_increase = std::max(trace.max_relative_increase, (string.energy() - previous) / initial);
        previous = string.energy();
        const auto u = string.displacement();
        for (std::size_t i = 1; i < intervals; ++i)
            if (u[i] < -1e-3) {
                ++trace.contact_steps;
                break;
            }
    }
    return trace;
}

TEST(FiniteDifferenceString, LosslessEnergyIsConservedToRoundOffThroughContacts) {
    const EnergyTrace t = trace_energy(guitar_like_problem(), 400, 40000);
    EXPECT_GT(t.contact_steps, 500);  // the test means something only with contact
    EXPECT_LT(t.max_relative_drift, 1e-12);
}

TEST(FiniteDifferenceString, DampedEnergyBalanceHoldsAndEnergyNeverIncreases) {
    StringProblem p = guitar_like_problem();
    p.loss_per_s = 3.0;
    const EnergyTrace t = trace_energy(p, 400, 40000);
    EXPECT_GT(t.contact_steps, 500);
    // Measured 4e-12: the dissipated energy is a sum of 40000 rounded terms.
    EXPECT_LT(t.max_relative_drift, 2e-11);
    EXPECT_LE(t.max_relative_increase, 1e-13);
}

TEST(FiniteDifferenceString, RejectsUnstableStepsAndPenetratingStarts) {
    const StringProblem p = guitar_like_problem();
    EXPECT_THROW(FiniteDifferenceString(p, 400, 1.01 * stability_limit(p, 400)), InputError);
    StringProblem below = p;
    below.initial_shape = [](double) { return -2e-3; };
    EXPECT_THROW(FiniteDifferenceString(below, 400, 0.5 * stability_limit(p, 400)), InputError);
}

TEST(DiscreteGradientContact, SolvesTheScalarEquationToRoundOff) {
    const DiscreteGradientContact law(1e13, 1.5);
    const double k = 1e-12;
    for (const double a : {-1e-5, -1e-9, 0.0, 1e-9, 1e-6, 3e-5})
        for (const double b : {-2e-5, -1e-8, 0.0, 1e-10, 1e-7, 4e-5}) {
            const ContactStep s = law.solve(a, b, k);
            const double residual = s.increment + k * law.gradient(a, s.increment) - b;
            EXPECT_LE(std::abs(residual), 1e-14 * (std::abs(a) + std::abs(b)) + 1e-300) << a << " " << b;
            EXPECT_GE(s.force, 0.0);
        }
    // The quotient tends to f(a) as r -> 0 without losing digits.
    EXPECT_NEAR(law.gradient(1e-5, 1e-20) / law.force(1e-5), 1.0, 1e-14);
}

}  // namespace
}  // namespace fretbuzz::reference
