// The scheme's defining properties (Issanchou et al. 2017, section 3): without losses
// the discrete energy H^{n+1/2} is conserved to round-off through many contacts; with
// losses, H + (energy dissipated by damping) is constant and H never increases.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <cmath>
#include <vector>

#include "TestSupport.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

struct EnergyTrace {
    std::vector<double> energy, dissipated, displacement;
    long contact_steps = 0;
    std::size_t most_points_in_contact = 0;
};

EnergyTrace trace(const Case& c, double fs, long steps, bool screen = true, bool closed_form = true) {
    PlanOptions options;
    options.screen_contacts = screen;
    options.closed_form_contact = closed_form;
    const Plan plan(c, 1.0 / fs, options);
    const std::vector<double> probe = plan.basis().mode_shapes_at(0.37 * c.string.length_m);
    Stepper stepper(plan, c.initial_displacement, c.initial_velocity);
    EnergyTrace t;
    for (long n = 1; n <= steps; ++n) {
        stepper.step();
        t.energy.push_back(stepper.energy());
        t.dissipated.push_back(stepper.dissipated());
        t.displacement.push_back(stepper.displacement(probe));
        t.most_points_in_contact = std::max(t.most_points_in_contact, stepper.forces().size());
    }
    t.contact_steps = stepper.statistics().contact_steps;
    return t;
}

double max_relative_drift(const EnergyTrace& t) {
    double worst = 0.0;
    for (double h : t.energy) worst = std::max(worst, std::abs(h - t.energy.front()) / t.energy.front());
    return worst;
}

TEST(Energy, ConservedThroughContactsAlongAFlatObstacle) {
    const Case c = load_case("flat-obstacle");
    const EnergyTrace t = trace(c, c.run.sample_rate_hz, 40000);  // 4 s, two periods of the fundamental
    EXPECT_GT(t.contact_steps, 2000);
    EXPECT_GT(t.most_points_in_contact, 100u);  // a long stretch of string lies on the obstacle
    EXPECT_LT(max_relative_drift(t), 1e-10);
}

TEST(Energy, ConservedThroughFretContactsOfTheLosslessBass) {
    Case c = load_case("bass-pop");
    c.make_lossless();
    const EnergyTrace t = trace(c, 400000.0, 16000);  // 40 ms: the string slaps on the frets
    EXPECT_GT(t.contact_steps, 300);
    EXPECT_LT(max_relative_drift(t), 1e-10);
    for (double d : t.dissipated) EXPECT_EQ(d, 0.0);
}

TEST(Energy, BalanceWithDampingIsExactAndEnergyNeverGrows) {
    const Case c = load_case("bass-pop");
    const EnergyTrace t = trace(c, 400000.0, 16000);
    ASSERT_GT(t.contact_steps, 300);
    const double h0 = t.energy.front();
    for (std::size_t n = 1; n < t.energy.size(); ++n) {
        const double balance_change = (t.energy[n] + t.dissipated[n]) - (t.energy[n - 1] + t.dissipated[n - 1]);
        ASSERT_LE(std::abs(balance_change), 1e-12 * h0) << "step " << n;
        ASSERT_LE(t.energy[n], t.energy[n - 1] + 1e-14 * h0) << "step " << n;
    }
    EXPECT_LT(t.energy.back(), 0.8 * h0);  // and the damping does take energy out
}

TEST(Energy, StaysBoundedAtHugeTimeSteps) {
    // Unconditional stability: dt far above the highest mode's period and a stiff contact.
    Case c = load_case("bass-pop");
    c.make_lossless();
    c.run.allow_aliasing = true;  // the energy stays bounded even where the contact result is wrong
    const EnergyTrace t = trace(c, 20000.0, 4000);  // dt = 50 us, 60 periods of the top mode
    EXPECT_GT(t.contact_steps, 10);
    EXPECT_LT(max_relative_drift(t), 1e-10);
}

TEST(Energy, ClosedFormContactLawsConserveEnergyAndMatchTheGeneralLaw) {
    // alpha = 1, 3/2, 2, 3 use closed-form quotients: the energy must still be conserved to
    // round-off up to K = 1e15, and the motion be that of the pow/expm1/log1p law.
    Case c = load_case("bass-pop");
    c.make_lossless();
    for (double alpha : {1.0, 1.5, 2.0, 3.0}) {
        for (double stiffness : {1e9, 1e13, 1e15}) {
            c.contact.exponent = alpha;
            c.contact.stiffness = stiffness;
            const EnergyTrace fast = trace(c, 400000.0, 6000);  // 15 ms: the first slaps on the frets
            const EnergyTrace general = trace(c, 400000.0, 6000, true, false);
            EXPECT_GT(fast.contact_steps, 10) << "alpha=" << alpha << " K=" << stiffness;
            EXPECT_LT(max_relative_drift(fast), 1e-10) << "alpha=" << alpha << " K=" << stiffness;
            double diff = 0.0, norm = 0.0;
            for (std::size_t n = 0; n < fast.displacement.size(); ++n) {
                diff += std::pow(fast.displacement[n] - general.displacement[n], 2);
                norm += std::pow(general.displacement[n], 2);
            }
            EXPECT_LE(std::sqrt(diff / norm), 1e-12) << "alpha=" << alpha << " K=" << stiffness;
        }
    }
}

using testing::relative_l2;

TEST(Energy, BridgeAtAnAudioRateConservesEnergyAtEveryCommonExponent) {
    // Several points of a bridge in contact at once, at 48 kHz with the modes below 24 kHz:
    // energy conserved to round-off up to K = 1e15 with the closed-form quotients (and the
    // solve's shared square roots at alpha = 3/2), the motion that of the pow/expm1/log1p law.
    Case sitar = with_mode_count(read_case_text("sitar"), 145);
    sitar.make_lossless();
    for (double alpha : {1.0, 1.5, 2.0, 3.0}) {
        for (double stiffness : {1e9, 1e13, 1e15}) {
            sitar.contact.exponent = alpha;
            sitar.contact.stiffness = stiffness;
            const EnergyTrace fast = trace(sitar, 48000.0, 4800);
            const EnergyTrace general = trace(sitar, 48000.0, 4800, true, false);
            const std::string what = "alpha=" + std::to_string(alpha) + " K=" + std::to_string(stiffness);
            EXPECT_GT(fast.contact_steps, 10) << what;
            EXPECT_GT(fast.most_points_in_contact, 1u) << what;
            EXPECT_LT(max_relative_drift(fast), 1e-10) << what;
            EXPECT_LE(relative_l2(fast.displacement, general.displacement), 1e-12) << what;
        }
    }
}

}  // namespace
}  // namespace fretbuzz
