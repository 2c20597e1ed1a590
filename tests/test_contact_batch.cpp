// Many contact equations solved together (PenaltyContact::solve_all: the start of Newton's
// method four equations at a time for alpha = 3/2) give the scalar solve's solutions within the
// stated tolerance, and a string landing on a long flat obstacle, where that path runs, conserves energy to
// round-off at every common exponent up to K = 1e15.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "Equivalence.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/scheme/PenaltyContact.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

using testing::agree;

TEST(ContactBatch, SolveAllAgreesWithTheScalarSolve) {
    std::mt19937_64 random(12);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    long compared = 0, in_contact = 0;
    for (double stiffness : {1.0, 1e6, 1e13, 1e15}) {
        for (double alpha : {1.0, 1.01, 1.5, 2.0, 3.0}) {
            const PenaltyContact law(stiffness, alpha);
            for (double k : {1e-14, 9.3e-12, 1e-8, 1e-3}) {
                for (std::size_t count : {0, 1, 3, 4, 5, 8, 37, 200}) {
                    // States from far apart to deep in contact, grazing ones and exact zeros.
                    std::vector<double> a(count), b(count);
                    for (std::size_t i = 0; i < count; ++i) {
                        a[i] = i % 11 == 0 ? 0.0 : unit(random) * std::pow(10.0, -12.0 * std::abs(unit(random)) - 3.0);
                        b[i] = i % 13 == 0 ? 0.0 : unit(random) * std::pow(10.0, -14.0 * std::abs(unit(random)) - 3.0);
                    }
                    std::vector<ContactSolution> together(count);
                    law.solve_all(a, b, k, together);
                    for (std::size_t i = 0; i < count; ++i) {
                        const ContactSolution alone = law.solve(a[i], b[i], k);
                        const std::string what = "K=" + std::to_string(stiffness) + " alpha=" + std::to_string(alpha) +
                                                 " k=" + std::to_string(k) + " i=" + std::to_string(i);
                        // The increment next to the state it changes (a + increment is eta^{n+1}).
                        const double size = std::abs(a[i]) + std::abs(b[i]);
                        ASSERT_TRUE(agree(together[i].increment, alone.increment, size)) << what;
                        ASSERT_TRUE(agree(together[i].force, alone.force)) << what;
                        ASSERT_TRUE(agree(together[i].root, alone.root)) << what;
                        ASSERT_LE(std::abs(together[i].iterations - alone.iterations), 1) << what;
                        ++compared;
                        if (alone.force > 0.0) ++in_contact;
                    }
                }
            }
        }
    }
    EXPECT_GT(in_contact, compared / 4);  // the states really exercise contact
}

TEST(ContactBatch, NonFiniteStatesAreStillReported) {
    const PenaltyContact law(1e13, 1.5);
    std::vector<double> a(8, 1e-9), b(8, 1e-9);
    b[5] = std::nan("");
    std::vector<ContactSolution> out(8);
    EXPECT_THROW(law.solve_all(a, b, 1e-11, out), SolverError);
}

TEST(ContactBatch, FlatObstacleLandingConservesEnergyAtEveryCommonExponent) {
    // The flat obstacle's onset: hundreds of points solved together in each step (the
    // transform path). Lossless: the discrete energy must stay constant to round-off.
    Case c = load_case("flat-obstacle");
    c.run.duration_s = 0.8;
    for (double alpha : {1.0, 1.5, 2.0, 3.0}) {
        for (double stiffness : {1e3, 1e9, 1e15}) {
            c.contact.exponent = alpha;
            c.contact.stiffness = stiffness;
            const Plan plan(c, 1.0 / c.run.sample_rate_hz);
            Stepper stepper(plan, c.initial_displacement, c.initial_velocity);
            std::vector<double> energy;
            std::size_t most = 0;
            for (long n = 0; n < 8000; ++n) {
                stepper.step();
                energy.push_back(stepper.energy());
                most = std::max(most, stepper.forces().size());
            }
            const std::string what = "alpha=" + std::to_string(alpha) + " K=" + std::to_string(stiffness);
            EXPECT_GT(stepper.statistics().contact_steps, 2) << what;  // stiff laws bounce off within a few steps
            EXPECT_GT(most, plan.transform_threshold()) << what;  // the points were solved together
            double drift = 0.0;
            for (double h : energy) drift = std::max(drift, std::abs(h - energy.front()) / energy.front());
            EXPECT_LT(drift, 1e-10) << what;
        }
    }
}

}  // namespace
}  // namespace fretbuzz
