// The run summary's energy figures: the largest rise of H - W (the energy less the work put
// in, which the scheme never lets rise but by round-off) and the balance error, both relative
// to the larger of the initial energy and the work put in, so that a run that starts at rest
// and is played is judged like any other.
#include <gtest/gtest.h>

#include "../src/run/EnergyAudit.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/run/Simulation.hpp"

namespace fretbuzz {
namespace {

TEST(EnergyAudit, ARunDrivenFromRestShowsNoRiseWhereTheWorkAccountsForIt) {
    RunSummary s;
    EnergyAudit audit;
    // H = W - D exactly: the work goes into the string, some of it is dissipated.
    const double work[] = {0.0, 1e-9, 1e-6, 1e-3, 2e-3, 2e-3, 2e-3};
    const double lost[] = {0.0, 0.0, 1e-10, 1e-5, 2e-5, 5e-5, 9e-5};
    for (int k = 0; k < 7; ++k) audit.record(work[k] - lost[k], lost[k], work[k]);
    audit.write_to(s);
    EXPECT_EQ(s.energy_initial_j, 0.0);
    EXPECT_EQ(s.max_relative_energy_increase, 0.0);  // was 1: the first step's rise over its own work
    EXPECT_LT(s.max_relative_balance_error, 1e-15);
    EXPECT_DOUBLE_EQ(s.dissipated_j, 9e-5);
    // A rise of H - W of 1e-6 of the work put in (2e-3 J) is reported as such.
    audit.record(2e-3 - 9e-5 + 2e-9, 9e-5, 2e-3);
    EXPECT_NEAR(audit.max_relative_energy_increase(), 1e-6, 1e-12);
}

TEST(EnergyAudit, AFreeRunIsJudgedAgainstItsInitialEnergy) {
    RunSummary s;
    EnergyAudit audit;
    audit.record(1.0, 0.0);
    audit.record(0.9, 0.1);
    audit.record(0.9 + 1e-13, 0.1);  // a round-off rise
    audit.write_to(s);
    EXPECT_DOUBLE_EQ(s.energy_initial_j, 1.0);
    EXPECT_DOUBLE_EQ(s.energy_final_j, 0.9 + 1e-13);
    EXPECT_NEAR(s.max_relative_energy_increase, 1e-13, 1e-15);
    EXPECT_NEAR(s.max_relative_balance_error, 1e-13, 1e-15);
}

TEST(EnergyAudit, APluckFromRestReportsRoundOffOnly) {
    Case c = load_case("guitar-pluck");
    c.run.duration_s = 0.01;  // the plectrum pulls, lets go, and the string rings
    const RunSummary s = simulate(c, {});
    ASSERT_EQ(s.energy_initial_j, 0.0);
    ASSERT_GT(s.work_j, 0.0);
    EXPECT_LT(s.max_relative_energy_increase, 1e-10);  // was 0.9993
    EXPECT_LT(s.max_relative_balance_error, 1e-10);
}

}  // namespace
}  // namespace fretbuzz
