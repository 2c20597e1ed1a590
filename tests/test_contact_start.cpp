// The contact solve's first iterate (a model of the equation: the exact root when leaving
// contact, the root of phi's Taylor parabola when staying, of a frozen-power quadratic when
// landing) changes where Newton's method starts, never which root it finds: the same solutions
// as Newton from r = b to round-off on random equations, hard ones included, and the discrete
// energy still conserved to round-off at the exponents that take the general law.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "Equivalence.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/scheme/PenaltyContact.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

constexpr double kEps = 2.220446049250313e-16;

// Both solutions meet the solve's stopping test (|r + k f - b| <= 4 eps (|r| + |b| + k f), with
// phi' >= 1, or Newton's step below an ulp of r): their increments differ by a few units of that
// scale at most. Each force is the difference quotient at its own increment, so the forces differ
// by what the increments do through that quotient's slope.
void expect_same_solution(const PenaltyContact& law, double a, double b, double k, const std::string& what) {
    const ContactSolution fast = law.solve(a, b, k), plain = law.solve_from_b(a, b, k);
    const double scale = std::abs(plain.increment) + std::abs(b) + k * plain.force;
    const double dr = std::abs(fast.increment - plain.increment);
    ASSERT_LE(dr, 16.0 * kEps * scale) << what << " a=" << a << " b=" << b;
    ASSERT_EQ(fast.force, law.difference_quotient(a, fast.increment)) << what;
    ASSERT_GE(fast.force, 0.0) << what;
    const double slope = law.slope_of_quotient(a, plain.increment, plain.force);
    ASSERT_LE(std::abs(fast.force - plain.force), 1e-12 * plain.force + 2.0 * slope * (dr + 4.0 * kEps * scale))
        << what << " a=" << a << " b=" << b;
}

TEST(ContactStart, SameSolutionsAsNewtonFromBOnRandomEquations) {
    std::mt19937_64 random(16);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const auto log_uniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, unit(random)); };
    const auto sign = [&] { return unit(random) < 0.5 ? -1.0 : 1.0; };
    long compared = 0, leaving = 0, landing = 0, staying = 0;
    for (double stiffness : {1.0, 1e6, 1e9, 1e11, 1e13, 1e15}) {
        for (double alpha : {1.0, 1.01, 1.3, 1.5, 2.0, 2.7, 3.0}) {
            const PenaltyContact law(stiffness, alpha);
            for (double k : {1e-14, 9.3e-12, 3.7e-7, 1e-3}) {
                for (int n = 0; n < 300; ++n) {
                    // States of every kind: a and b over 14 decades of either sign.
                    const double a = sign() * log_uniform(1e-16, 1e-2), b = sign() * log_uniform(1e-18, 1e-2);
                    const std::string what = "K=" + std::to_string(stiffness) + " alpha=" + std::to_string(alpha) +
                                             " k=" + std::to_string(k) + " n=" + std::to_string(n);
                    expect_same_solution(law, a, b, k, what);
                    // Hard ones: a point deep in contact (a far from 0) whose root r is tiny
                    // against a, of either sign, b built from that root.
                    const double deep = log_uniform(1e-6, 1e-2), tiny = sign() * deep * log_uniform(1e-15, 1e-3);
                    expect_same_solution(law, deep, tiny + k * law.difference_quotient(deep, tiny), k, what + " deep");
                    // And one leaving contact exactly where a + r crosses 0, or landing just past it.
                    const double edge = -deep * (1.0 + sign() * log_uniform(1e-14, 1e-2));
                    expect_same_solution(law, deep, edge + k * law.difference_quotient(deep, edge), k, what + " edge");
                    const double touch = -a;
                    if (a < 0.0) expect_same_solution(law, a, touch * (1.0 + log_uniform(1e-14, 1.0)), k, what + " land");
                    compared += 3;
                    if (a > 0.0 && law.solve(a, b, k).increment <= -a) ++leaving;
                    if (a <= 0.0 && a + b > 0.0) ++landing;
                    if (a > 0.0 && law.solve(a, b, k).increment > -a) ++staying;
                }
            }
        }
    }
    // The random states really exercise each of the model's three cases.
    EXPECT_GT(leaving, compared / 100);
    EXPECT_GT(landing, compared / 100);
    EXPECT_GT(staying, compared / 100);
}

TEST(ContactStart, ModelStartIsExactWhereTheEquationIsQuadratic) {
    // Staying in contact at alpha = 1 and 2 the equation is a quadratic in r, and leaving contact
    // it is one for every law: there the first iterate already meets the stopping test.
    for (double alpha : {1.0, 1.5, 2.0, 3.0, 1.3}) {
        const PenaltyContact law(1e13, alpha);
        const double k = 9.3e-12;
        for (double a : {1e-9, 1e-7, 1e-5}) {
            // Leaving: the root r = -2a, eta^{n+1} = -a.
            const double r = -2.0 * a;
            const ContactSolution leave = law.solve(a, r + k * law.difference_quotient(a, r), k);
            EXPECT_EQ(leave.iterations, 1) << "alpha=" << alpha << " a=" << a;
            if (alpha != 1.0 && alpha != 2.0) continue;
            // A stiff enough contact (k Psi''(a) >= 0.01: softer ones start from b, as good there).
            const double stay = 0.3 * a, stiff_k = 1e-3;
            const ContactSolution s = law.solve(a, stay + stiff_k * law.difference_quotient(a, stay), stiff_k);
            EXPECT_EQ(s.iterations, 1) << "alpha=" << alpha << " a=" << a;
        }
    }
}

TEST(ContactStart, ClosedFormLawsLandFromTheSameModelAsTheGeneralLaw) {
    // A firm landing starts from the root of a quadratic with the law's power frozen at a scale
    // y0. The closed-form laws (alpha = 3/2, 2, 3) form y0^(alpha-1) without the general law's
    // pow but from the same model: they need no more Newton steps than it does (a start from a
    // cruder model, y0^(alpha-1) taken as 1, needs several more on these landings).
    std::mt19937_64 rng(20261124);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const auto log_uniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, unit(rng)); };
    for (double alpha : {1.5, 2.0, 3.0}) {
        const PenaltyContact closed_form(1e13, alpha), general(1e13, alpha, false);
        long steps_closed = 0, steps_general = 0;
        for (int i = 0; i < 400; ++i) {
            const double a = -log_uniform(1e-6, 1e-4), b = -a + log_uniform(1e-4, 1e-2), k = log_uniform(1e-9, 1e-6);
            steps_closed += closed_form.solve(a, b, k).iterations;
            steps_general += general.solve(a, b, k).iterations;
        }
        // (The two forms of y0^(alpha-1) differ in their last bits, which can move a stopping
        // test by one step now and then.)
        EXPECT_LE(steps_closed, steps_general + steps_general / 20) << "alpha=" << alpha;
    }
}

TEST(ContactStart, BatchStartsEveryKindOfLaneAsTheScalarSolve) {
    // PenaltyContact::solve_all at alpha = 3/2 computes the model start in the lanes: each kind of
    // start (leaving in closed form, staying from the Taylor parabola, soft from b, a light landing
    // from b, a firm landing by the scalar model), in groups of one kind and mixed, over several
    // blocks, must give the scalar solve's solution (within the stated tolerance).
    const PenaltyContact law(1e13, 1.5);
    const double k = 1e-11;  // k K = 100: stiff, except where a < 4e-9 (k Psi''(a) < 0.01)
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const auto log_uniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, unit(random)); };
    enum Kind { leaving, staying, soft, light_landing, firm_landing, apart, kinds };
    const auto state_of = [&](int kind, double& a, double& b) {
        switch (kind) {
            case leaving: a = log_uniform(1e-8, 1e-4); b = -a * (2.0 + log_uniform(1e-3, 1e2)); break;
            case staying: a = log_uniform(1e-7, 1e-3); b = a * (unit(random) - 0.5) * log_uniform(1e-9, 1.0); break;
            case soft: a = log_uniform(1e-14, 1e-10); b = a * (unit(random) - 0.5); break;
            case light_landing: a = -log_uniform(1e-12, 1e-9); b = -a + log_uniform(1e-12, 1e-9); break;
            case firm_landing: a = -log_uniform(1e-6, 1e-4); b = -a + log_uniform(1e-3, 1e-2); break;
            default: a = -log_uniform(1e-9, 1e-3); b = -a * unit(random); break;
        }
    };
    std::vector<double> a, b;
    for (int kind = 0; kind < kinds; ++kind)  // groups of four of one kind
        for (int l = 0; l < 8; ++l) {
            double x = 0.0, y = 0.0;
            state_of(kind, x, y);
            a.push_back(x);
            b.push_back(y);
        }
    for (int n = 0; n < 400; ++n) {  // then mixed, and a tail that is not a multiple of four
        double x = 0.0, y = 0.0;
        state_of(static_cast<int>(random() % kinds), x, y);
        a.push_back(x);
        b.push_back(y);
    }
    a.push_back(1e-6);
    b.push_back(1e-9);
    std::vector<ContactSolution> together(a.size());
    const std::size_t in_lanes = law.solve_all(a, b, k, together);
    long leaving_seen = 0, firm_seen = 0, staying_seen = 0;
    std::size_t first_step = 0;  // the lanes' share: apart, or solved at Newton's first iterate
    for (std::size_t i = 0; i < a.size() / 4 * 4; ++i)
        if ((a[i] <= 0.0 && a[i] + b[i] <= 0.0) || law.solve(a[i], b[i], k).iterations == 1) ++first_step;
    // The lanes start where the scalar solve does: each equation it finishes in one step, they do.
    EXPECT_EQ(in_lanes, first_step);
    EXPECT_GT(in_lanes, a.size() / 4);
    for (std::size_t i = 0; i < a.size(); ++i) {
        const ContactSolution alone = law.solve(a[i], b[i], k);
        const double size = std::abs(a[i]) + std::abs(b[i]);
        ASSERT_TRUE(testing::agree(together[i].increment, alone.increment, size)) << i << " a=" << a[i] << " b=" << b[i];
        ASSERT_TRUE(testing::agree(together[i].force, alone.force)) << i;
        ASSERT_TRUE(testing::agree(together[i].root, alone.root)) << i;
        ASSERT_LE(std::abs(together[i].iterations - alone.iterations), 1) << i;
        if (a[i] > 0.0 && alone.increment <= -a[i]) ++leaving_seen;
        if (a[i] > 4e-9 && alone.increment > -a[i]) ++staying_seen;
        if (a[i] <= 0.0 && k * law.potential(a[i] + b[i]) > 0.01 * b[i] * b[i]) ++firm_seen;
    }
    EXPECT_GT(leaving_seen, 20);
    EXPECT_GT(staying_seen, 20);
    EXPECT_GT(firm_seen, 20);
}

double max_relative_drift(const std::vector<double>& energy) {
    double worst = 0.0;
    for (double h : energy) worst = std::max(worst, std::abs(h - energy.front()) / energy.front());
    return worst;
}

TEST(ContactStart, GeneralLawConservesEnergyThroughBridgeAndFretContacts) {
    // Exponents without a closed form (the sitar's 1.01, and 1.3): the quotient and its slope by
    // expm1/log1p from shared powers, the potential from the power the solve left. Lossless: the
    // discrete energy constant to round-off up to K = 1e15, on a bridge at an audio rate (several
    // points in contact) and on the bass's frets at 400 kHz.
    const Case sitar = with_mode_count(read_case_text("sitar"), 145);
    Case bass = load_case("bass-pop");
    for (double alpha : {1.01, 1.3}) {
        for (double stiffness : {1e9, 1e13, 1e15}) {
            for (int which = 0; which < 2; ++which) {
                Case c = which == 0 ? sitar : bass;
                c.make_lossless();
                c.contact.exponent = alpha;
                c.contact.stiffness = stiffness;
                const double fs = which == 0 ? 48000.0 : 400000.0;
                const Plan plan(c, 1.0 / fs);
                Stepper stepper(plan, c.initial_displacement, c.initial_velocity);
                std::vector<double> energy;
                for (long n = 0; n < 4800; ++n) {
                    stepper.step();
                    energy.push_back(stepper.energy());
                }
                const std::string what = std::string(which == 0 ? "sitar" : "bass") +
                                         " alpha=" + std::to_string(alpha) + " K=" + std::to_string(stiffness);
                EXPECT_GT(stepper.statistics().contact_steps, 10) << what;
                EXPECT_LT(max_relative_drift(energy), 1e-10) << what;
            }
        }
    }
}

}  // namespace
}  // namespace fretbuzz
