// Convergence studies through the library: the modal scheme's self-convergence in dt with
// contact, and how the comparison instants are chosen.
#include <gtest/gtest.h>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/sweep/Convergence.hpp"

namespace fretbuzz {
namespace {

TEST(Convergence, ModalSchemeConvergesInTimeStepThroughFretContacts) {
    // The first 10 ms of bass-pop: the string hits the frets from 3.8 ms on.
    ConvergenceStudy study;
    study.base = load_case("bass-pop");
    study.values = {200000, 400000, 800000};
    study.reference = 3200000;
    study.window_s = 0.01;
    const ConvergenceReport r = run_convergence(study);
    ASSERT_EQ(r.levels.size(), 3u);
    // Measured: 1.39e-1, 5.43e-2, 1.67e-2 (orders 1.36, 1.70: towards 2 as the contacts are resolved).
    EXPECT_GT(*r.levels[1].observed_order, 1.1);
    EXPECT_GT(*r.levels[2].observed_order, 1.4);
    EXPECT_LT(r.levels[2].relative_error, 0.03);
    EXPECT_FALSE(r.levels[0].meets_threshold);
    EXPECT_TRUE(r.levels[1].meets_threshold);
    ASSERT_TRUE(r.threshold_met_from);
    EXPECT_EQ(*r.threshold_met_from, 400000);
    EXPECT_EQ(r.comparison_rate_hz, 40000);  // largest divisor of 200 kHz not above 48 kHz
}

TEST(Convergence, ErrorFallsAsThePenaltyStiffens) {
    ConvergenceStudy study;
    study.base = load_case("bass-pop");
    study.base.run.sample_rate_hz = 400000;
    study.parameter = ConvergenceParameter::stiffness;
    study.values = {1e11, 1e12, 1e13, 1e14};  // the largest is the reference
    study.window_s = 0.01;
    const ConvergenceReport r = run_convergence(study);
    ASSERT_EQ(r.levels.size(), 3u);
    EXPECT_EQ(r.reference, 1e14);
    EXPECT_LT(r.levels[1].relative_error, r.levels[0].relative_error);
    EXPECT_LT(r.levels[2].relative_error, r.levels[1].relative_error);
}

TEST(Convergence, ComparisonRateDividesEveryRate) {
    EXPECT_EQ(common_comparison_rate({400000, 800000, 4000000}, std::nullopt, 0.3), 40000);
    EXPECT_EQ(common_comparison_rate({44100, 88200}, std::nullopt, 0.3), 44100);
    EXPECT_EQ(common_comparison_rate({300000, 500000}, 10000.0, 0.3), 10000);
    // 100001 and 200000 share only 1 Hz: no usable common instants.
    EXPECT_THROW(common_comparison_rate({100001, 200000}, std::nullopt, 0.3), InputError);
    EXPECT_THROW(common_comparison_rate({150000.5}, std::nullopt, 0.3), InputError);
    EXPECT_THROW(common_comparison_rate({300000, 500000}, 30000.0, 0.3), InputError);
}

TEST(Convergence, RejectsStudiesThatMakeNoSense) {
    ConvergenceStudy study;
    study.base = load_case("bass-pop");
    study.window_s = 0.01;
    EXPECT_THROW(run_convergence(study), InputError);  // no levels
    study.values = {100000, -1};
    EXPECT_THROW(run_convergence(study), InputError);
    study.values = {100000, 200000};
    study.duration_s = 0.005;
    EXPECT_THROW(run_convergence(study), InputError);  // window beyond the run
    study.duration_s.reset();
    study.reference = 150000;
    EXPECT_THROW(run_convergence(study), InputError);  // a level finer than the reference
}

}  // namespace
}  // namespace fretbuzz
