// The modal scheme against an independent finite-difference scheme (Bilbao, Torin and
// Chatziioannou 2015) on the same PDE: a lossless ideal string, released from a sine bump,
// slapping a flat obstacle over most of its length. Both must converge to the same solution.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "fretbuzz/reference/CrossCheck.hpp"

namespace fretbuzz::reference {
namespace {

StringProblem flat_obstacle_problem() { return slapping_string_problem(); }

constexpr double kDuration = 2.0;  // one period: a whole contact episode and the rebound
constexpr double kRate = 100.0;    // comparison samples per second
constexpr double kObserve = 0.25;  // a grid point of every grid below

TEST(CrossCheck, FiniteDifferenceAndModalSchemesConvergeToTheSameSolution) {
    // N = 80, 160, 320, 640 at Courant number 0.8 (dt = 0.8 h / c refines with the grid), the
    // modal scheme on the same grid and step, and a modal run far finer than any of them
    // (1279 modes, 6400 Hz) standing in for the exact solution.
    const CrossCheckReport r = run_cross_check(CrossCheckStudy{});
    ASSERT_EQ(r.levels.size(), 4u);
    // Measured: FD against the reference 2.8e-2, 9.0e-3, 2.7e-3, 7.5e-4 (orders 1.6 -> 1.8);
    // FD against modal on the same grid and step 4.8e-3, 2.4e-3, 1.2e-3, 4.4e-4.
    for (std::size_t k = 1; k < r.levels.size(); ++k) {
        EXPECT_GT(observed_order(1.0, r.levels[k - 1].fd_to_reference, 2.0, r.levels[k].fd_to_reference), 1.4) << k;
        EXPECT_GT(observed_order(1.0, r.levels[k - 1].modal_to_reference, 2.0, r.levels[k].modal_to_reference), 1.4)
            << k;
        EXPECT_LT(r.levels[k].fd_to_modal, 0.75 * r.levels[k - 1].fd_to_modal) << k;
    }
    EXPECT_LT(r.levels.back().fd_to_reference, 1.2e-3);
    EXPECT_LT(r.levels.back().fd_to_modal, 7e-4);
    for (const CrossCheckLevel& level : r.levels) EXPECT_LT(level.fd_energy_drift, 1e-12);
}

TEST(CrossCheck, WeaklyStiffStringAgreesToo) {
    StringProblem p = flat_obstacle_problem();
    p.bending_stiffness = 1e-7;  // B = pi^2 EI / (T L^2) ~ 1e-6
    const SampledSignal reference = run_modal(p, {1279, 6400.0, kDuration, kRate, kObserve});
    const FiniteDifferenceResult coarse = run_finite_difference(p, {160, 0.8, kDuration, kRate, kObserve});
    const FiniteDifferenceResult fine = run_finite_difference(p, {640, 0.8, kDuration, kRate, kObserve});
    const double coarse_error = relative_l2_error(coarse.signal.values, reference.values);
    const double fine_error = relative_l2_error(fine.signal.values, reference.values);
    // Measured: 5.7e-3 and 6.3e-4.
    EXPECT_LT(fine_error, 0.25 * coarse_error);
    EXPECT_LT(fine_error, 1.2e-3);
}

}  // namespace
}  // namespace fretbuzz::reference
