// The scalar contact solve against an independent bisection in long double, over the
// whole range the product supports: K from 1 to 1e15, alpha from 1 to 3, states deep in
// contact, grazing, leaving, and increments down to round-off.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/PenaltyContact.hpp"

namespace fretbuzz {
namespace {

using Real = long double;

// (Psi(a + r) - Psi(a)) / r in long double, by the series where r is tiny against a.
Real quotient_reference(Real k_stiff, Real alpha, Real a, Real r) {
    auto psi = [&](Real eta) { return eta > 0 ? k_stiff / (alpha + 1) * std::pow(eta, alpha + 1) : Real(0); };
    if (a > 0 && std::abs(r) < 1e-7L * a) {
        const Real d1 = k_stiff * std::pow(a, alpha), d2 = k_stiff * alpha * std::pow(a, alpha - 1),
                   d3 = k_stiff * alpha * (alpha - 1) * std::pow(a, alpha - 2);
        return d1 + d2 * r / 2 + d3 * r * r / 6;
    }
    if (r == 0) return a > 0 ? k_stiff * std::pow(a, alpha) : 0;
    return (psi(a + r) - psi(a)) / r;
}

// Root of r + k F(r) = b by plain bisection on [b - k F(b), b] (F non-decreasing).
Real bisection_root(Real k_stiff, Real alpha, Real a, Real b, Real k) {
    Real hi = b, lo = b - k * quotient_reference(k_stiff, alpha, a, b);
    for (int it = 0; it < 400 && hi > lo; ++it) {
        const Real mid = lo + (hi - lo) / 2;
        if (mid == lo || mid == hi) break;
        (mid + k * quotient_reference(k_stiff, alpha, a, mid) - b > 0 ? hi : lo) = mid;
    }
    return (lo + hi) / 2;
}

TEST(PenaltyContact, MatchesBisectionOverExtremeParameters) {
    int cases = 0, contacts = 0;
    for (double stiffness : {1.0, 1e6, 1e13, 1e15}) {
        for (double alpha : {1.0, 1.01, 1.5, 2.0, 3.0}) {
            const PenaltyContact law(stiffness, alpha);
            for (double k : {1e-14, 9.3e-12, 1e-8, 1e-3}) {  // dt^2/mu: 4 MHz bass is 9.3e-12
                for (double a : {-1e-3, -1e-9, 0.0, 1e-15, 1e-9, 1e-6, 1e-4}) {
                    for (double b : {-2e-3, -1e-7, -1e-12, -1e-18, 0.0, 1e-18, 1e-12, 1e-9, 1e-7, 1e-5, 1e-3}) {
                        const ContactSolution s = law.solve(a, b, k);
                        const Real reference = bisection_root(stiffness, alpha, a, b, k);
                        const Real scale = std::abs(reference) + std::abs(b) + std::abs(a) + 1e-300L;
                        ASSERT_LE(std::abs(s.increment - reference), 1e-12L * scale)
                            << "K=" << stiffness << " alpha=" << alpha << " k=" << k << " a=" << a << " b=" << b;
                        // The force is the difference quotient at the solution, and non-negative.
                        const Real f_ref = quotient_reference(stiffness, alpha, a, s.increment);
                        ASSERT_GE(s.force, 0.0);
                        ASSERT_LE(std::abs(s.force - f_ref), 1e-10L * f_ref + 1e-300L);
                        ASSERT_LE(s.iterations, 100);
                        ++cases;
                        if (s.force > 0.0) ++contacts;
                    }
                }
            }
        }
    }
    EXPECT_GT(contacts, cases / 3);  // the grid really exercises contact, not only free flight
}

TEST(PenaltyContact, NoForceWhenOutOfContactOnBothSides) {
    const PenaltyContact law(1e13, 1.5);
    const ContactSolution s = law.solve(-1e-4, -2e-5, 1e-11);
    EXPECT_EQ(s.force, 0.0);
    EXPECT_EQ(s.increment, -2e-5);
}

TEST(PenaltyContact, GeneralLawLandingAndLeavingUseThePotentialsOwnPowers) {
    // A landing's solve keeps the power of a + r it formed, and a leaving one takes Psi(a) from
    // a^(alpha+1): the force is the difference quotient of the potential itself, and the
    // potential from the kept power is Psi(a + r) bit for bit, so the energy balance is unchanged.
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    long landings = 0, leavings = 0;
    for (double alpha : {1.01, 1.3, 2.5}) {
        for (double stiffness : {1e9, 1e13}) {
            const PenaltyContact law(stiffness, alpha);
            for (int n = 0; n < 400; ++n) {
                const double scale = 1e-7 * std::pow(1e4, unit(random)), k = 1e-11 * std::pow(1e4, unit(random));
                const bool landing = n % 2 == 0;
                const double a = landing ? -scale * unit(random) : scale * unit(random);
                const double b = landing ? -a + scale * unit(random) : -a - scale * unit(random);
                const ContactSolution s = law.solve(a, b, k);
                const double eta = a + s.increment;
                ASSERT_EQ(s.force, law.difference_quotient(a, s.increment)) << "alpha=" << alpha << " a=" << a << " b=" << b;
                ASSERT_EQ(law.potential(eta, s.root), law.potential(eta)) << "alpha=" << alpha << " a=" << a << " b=" << b;
                if (a <= 0.0 || eta <= 0.0) {  // one side out of contact: the plain difference, bit for bit
                    const double expected = (law.potential(eta) - law.potential(a)) / s.increment;
                    ASSERT_EQ(s.force, expected) << "alpha=" << alpha << " a=" << a << " b=" << b;
                }
                landings += landing && eta > 0.0 ? 1 : 0;
                leavings += !landing && eta <= 0.0 ? 1 : 0;
            }
        }
    }
    EXPECT_GT(landings, 100);
    EXPECT_GT(leavings, 100);
}

TEST(PenaltyContact, DifferenceQuotientIsAccurateForTinyIncrements) {
    // Where (Psi(a+r) - Psi(a))/r cancels catastrophically, the quotient must still be exact.
    const PenaltyContact law(1e13, 1.5);
    for (double a : {1e-9, 1e-6}) {
        for (double ratio : {1e-16, 1e-12, 1e-8, 1e-4}) {
            const double r = ratio * a;
            const Real reference = quotient_reference(1e13L, 1.5L, a, r);
            EXPECT_LE(std::abs(law.difference_quotient(a, r) - reference), 1e-14L * reference) << a << " " << r;
        }
    }
}

TEST(PenaltyContact, RejectsBadLawsAndBadStates) {
    EXPECT_THROW(PenaltyContact(0.0, 1.5), InputError);
    EXPECT_THROW(PenaltyContact(-1.0, 1.5), InputError);
    EXPECT_THROW(PenaltyContact(1e13, 0.99), InputError);
    EXPECT_THROW(PenaltyContact(std::nan(""), 1.5), InputError);
    const PenaltyContact law(1e13, 1.5);
    EXPECT_THROW(law.solve(std::nan(""), 1e-6, 1e-11), SolverError);
    EXPECT_THROW(law.solve(1e-6, std::numeric_limits<double>::infinity(), 1e-11), SolverError);
}

TEST(PenaltyContact, ClosedFormsMatchTheGeneralLawEverywhere) {
    // alpha = 1, 3/2, 2, 3 skip pow/expm1/log1p: quotients and roots must be those of the
    // general formulas (and of the long double reference), across contact, grazing and leaving.
    for (double alpha : {1.0, 1.5, 2.0, 3.0}) {
        for (double stiffness : {1.0, 1e6, 1e13, 1e15}) {
            const PenaltyContact fast(stiffness, alpha), general(stiffness, alpha, false);
            for (double a : {-1e-4, -1e-9, 0.0, 1e-15, 1e-9, 1e-6, 1e-4}) {
                EXPECT_LE(std::abs(fast.potential(a) - general.potential(a)), 4e-16 * general.potential(a));
                EXPECT_LE(std::abs(fast.force(a) - general.force(a)), 4e-16 * general.force(a));
                for (double ratio : {-0.999, -0.5, -1e-6, -1e-12, -1e-16, 0.0, 1e-16, 1e-12, 1e-6, 0.5, 10.0}) {
                    const double r = a != 0.0 ? ratio * std::abs(a) : ratio * 1e-6;
                    // The long double reference itself cancels near |r/a| = 1e-6: 1e-12 there.
                    const Real reference = quotient_reference(stiffness, alpha, a, r);
                    const double q = fast.difference_quotient(a, r), g = general.difference_quotient(a, r);
                    EXPECT_LE(std::abs(q - reference), 1e-12L * reference + 1e-300L)
                        << "alpha=" << alpha << " a=" << a << " r=" << r;
                    EXPECT_LE(std::abs(q - g), 1e-14 * g + 1e-300) << "alpha=" << alpha << " a=" << a << " r=" << r;
                }
                for (double k : {1e-14, 9.3e-12, 1e-8, 1e-3})
                    for (double b : {-1e-7, -1e-12, 0.0, 1e-12, 1e-9, 1e-7, 1e-5, 1e-3}) {
                        const ContactSolution s = fast.solve(a, b, k), t = general.solve(a, b, k);
                        const double scale = std::abs(t.increment) + std::abs(a) + std::abs(b);
                        ASSERT_LE(std::abs(s.increment - t.increment), 1e-14 * scale)
                            << "alpha=" << alpha << " K=" << stiffness << " a=" << a << " b=" << b << " k=" << k;
                        ASSERT_LE(std::abs(s.force - t.force), 1e-12 * t.force + 1e-300);
                    }
            }
        }
    }
}

// A finger's or a gesture's own iteration forms a's power once and the quotient with its slope
// in one call: the same bits as difference_quotient and slope_of_quotient, every law and case.
TEST(PenaltyContact, AnchoredQuotientAndSlopeAreTheSeparateOnes) {
    for (double alpha : {1.0, 1.01, 1.5, 2.0, 2.7, 3.0})
        for (bool specialise : {true, false}) {
            const PenaltyContact law(1e13, alpha, specialise);
            for (double a : {-1e-4, -1e-9, 0.0, 1e-15, 1e-9, 1e-6, 1e-4}) {
                const PenaltyContact::Anchored at = law.anchored(a);
                for (double ratio : {-3.0, -1.0, -0.999, -0.5, -1e-5, -1e-12, 0.0, 1e-16, 1e-5, 0.5, 10.0}) {
                    const double r = a != 0.0 ? ratio * std::abs(a) : ratio * 1e-6;
                    const double q = law.difference_quotient(a, r);
                    const PenaltyContact::QuotientSlope both = law.quotient_and_slope(at, r);
                    EXPECT_EQ(both.quotient, q) << "alpha=" << alpha << " a=" << a << " r=" << r;
                    EXPECT_EQ(both.slope, law.slope_of_quotient(a, r, q)) << "alpha=" << alpha << " a=" << a << " r=" << r;
                }
            }
        }
}

}  // namespace
}  // namespace fretbuzz
