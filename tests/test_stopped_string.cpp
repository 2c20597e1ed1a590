// A stopped note: the held string (the open string's modes with u(x_h) = 0, the string going
// on over the fret to the nut, its near side damped) against closed forms and against a
// straightforward dense reference; the pinned piece's stiffness (B' = B (L / L')^2); the
// stand-in Case that stopped_string() builds from them.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/StoppedString.hpp"
#include "fretbuzz/scheme/HeldString.hpp"
#include "fretbuzz/model/StringDispersion.hpp"

namespace fretbuzz {
namespace {

constexpr double kPi = std::numbers::pi;

double cents(double f, double reference) { return 1200.0 * std::log2(f / reference); }

// The Jazz Bass string of bass-neck: L, T, mu and the core's E I.
struct StiffString {
    double length = 0.863, tension = 191.6, density = 6.69e-3, bending = 5.24e-4;
    double eta0 = 0.711, eta2 = 2.99e-4;  // sigma = eta0 + eta2 k^2

    double frequency_at(double k) const { return k / (2.0 * kPi) * std::sqrt((tension + bending * k * k) / density); }
    double inharmonicity(double l) const { return kPi * kPi * bending / (tension * l * l); }
    // Mode n of the piece of length l pinned at both ends: n c / (2 l) sqrt(1 + B' n^2).
    double pinned(double l, int n) const {
        return n * std::sqrt(tension / density) / (2.0 * l) * std::sqrt(1.0 + inharmonicity(l) * n * n);
    }
    // Mode n of the piece of length l pinned at one end and clamped at the other: with
    // u = A sin(k1 x) + C sinh(k2 x), k2^2 = k1^2 + T / E I, clamping gives
    // k2 tan(k1 l) = k1 tanh(k2 l), one root k1 l in (n pi, (n + 1/2) pi).
    double clamped(double l, int n) const {
        const auto g = [&](double k1) {
            const double k2 = std::sqrt(k1 * k1 + tension / bending);
            return k2 * std::sin(k1 * l) - k1 * std::cos(k1 * l) * std::tanh(k2 * l);
        };
        double lo = n * kPi / l, hi = (n + 0.5) * kPi / l;
        const bool rising = g(lo) < 0.0;
        for (int i = 0; i < 200; ++i) {
            const double mid = 0.5 * (lo + hi);
            ((g(mid) < 0.0) == rising ? lo : hi) = mid;
        }
        return frequency_at(0.5 * (lo + hi));
    }
    ModeTable table(std::size_t modes) const {
        ModeTable t;
        for (std::size_t j = 1; j <= modes; ++j) {
            const double k = static_cast<double>(j) * kPi / length;
            t.frequency_hz.push_back(frequency_at(k));
            t.sigma_per_s.push_back(eta0 + eta2 * k * k);
            t.source.push_back(ModeSource::model);
        }
        return t;
    }
};

TEST(StringDispersion, AShorterPieceOfAStiffStringHasItsInharmonicityScaledByTheSquaredLengthRatio) {
    // B' = B (L / L')^2 for the same E I and T: n c / (2 L') sqrt(1 + B' n^2), within the table
    // and beyond it (the extrapolated line is exact for the stiff string).
    const StiffString s;
    const StringDispersion dispersion(s.table(300), s.length);
    for (const int fret : {1, 5, 12, 15}) {
        const double piece = s.length - fret_position(s.length, fret);
        const ModeTable pinned = dispersion.pinned_modes(piece, 600);
        for (int n = 1; n <= 600; ++n) {
            EXPECT_NEAR(pinned.frequency_hz[static_cast<std::size_t>(n - 1)] / s.pinned(piece, n), 1.0, 1e-11) << fret << " " << n;
            const double k = n * kPi / piece;
            EXPECT_NEAR(pinned.sigma_per_s[static_cast<std::size_t>(n - 1)], s.eta0 + s.eta2 * k * k, 1e-9 * (s.eta0 + s.eta2 * k * k));
        }
    }
    // Every frequency scaled by L / L' keeps B: flat by 2 cents at partial 5 of fret 12.
    const double piece = s.length / 2.0;
    const double kept_b = 5.0 * s.pinned(s.length, 1) * std::sqrt(1.0 + s.inharmonicity(s.length) * 25.0) /
                          std::sqrt(1.0 + s.inharmonicity(s.length)) * s.length / piece;
    EXPECT_GT(cents(dispersion.pinned_modes(piece, 5).frequency_hz[4], kept_b), 1.5);
}

// The held string as a straightforward dense eigenproblem: the open modes with a spring of
// stiffness 1 / R at x_h (R: HeldString's static compliance of the modes above the table),
// K + z z^T / R, solved by Eigen; its secular equation is HeldString's.
std::vector<double> dense_held_frequencies(const ModeTable& open, double length, double held_at, double compliance) {
    const auto n = static_cast<Eigen::Index>(open.size());
    Eigen::VectorXd z(n);
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n, n);
    for (Eigen::Index j = 0; j < n; ++j) {
        z(j) = std::sqrt(2.0 / length) * std::sin(static_cast<double>(j + 1) * kPi * held_at / length);
        k(j, j) = std::pow(2.0 * kPi * open.frequency_hz[static_cast<std::size_t>(j)], 2);
    }
    k += z * z.transpose() / compliance;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(k, Eigen::EigenvaluesOnly);
    std::vector<double> f;
    for (Eigen::Index i = 0; i + 1 < n; ++i) f.push_back(std::sqrt(solver.eigenvalues()(i)) / (2.0 * kPi));
    return f;
}

TEST(HeldString, ItsModesAreTheEigenvaluesOfTheDenseProblem) {
    const StiffString s;
    ModeTable repeated = s.table(200);
    repeated.frequency_hz[40] = repeated.frequency_hz[41];  // two open modes at one frequency
    struct Setup {
        ModeTable table;
        double held_at;
    };
    for (const Setup& setup : {Setup{s.table(200), fret_position(s.length, 5)}, Setup{s.table(200), 0.3},
                               Setup{s.table(200), s.length / 2.0},  // a node of every even mode
                               Setup{repeated, fret_position(s.length, 7)}}) {
        const HeldString held(setup.table, s.length, setup.held_at);
        const std::vector<double> dense = dense_held_frequencies(setup.table, s.length, setup.held_at, held.static_compliance());
        ASSERT_GT(held.modes().size(), 100u);
        for (std::size_t m = 0; m < held.modes().size(); ++m)
            EXPECT_NEAR(held.modes()[m].frequency_hz / dense[m], 1.0, 1e-9) << setup.held_at << " mode " << m;
    }
}

TEST(HeldString, TheStaticComplianceIsThatOfTheModesAboveTheTable) {
    // Summed explicitly far past the table from the stiff string's own frequencies.
    const StiffString s;
    const double held_at = fret_position(s.length, 5);
    double sum = 0.0;
    for (int j = 201; j < 2000000; ++j) {
        const double k = j * kPi / s.length;
        const double z = std::sqrt(2.0 / s.length) * std::sin(k * held_at);
        sum += z * z / std::pow(2.0 * kPi * s.frequency_at(k), 2);
    }
    EXPECT_NEAR(HeldString(s.table(200), s.length, held_at).static_compliance() / sum, 1.0, 1e-4);
}

TEST(HeldString, AFlexibleStringSoundsAsThePinnedPieceOnItsFarSide) {
    // Without stiffness nothing but the length is left: the far side's partials are exactly
    // those of the piece pinned at x_h (the static compliance above the table takes the
    // truncation's 1 / N error away: 1.2 cents at fret 5 with 200 modes without it).
    StiffString s;
    s.bending = 0.0;
    for (const int fret : {1, 5, 12, 15}) {
        const double held_at = fret_position(s.length, fret);
        const ModeTable partials = HeldString(s.table(200), s.length, held_at).sounding_partials(20);
        for (int n = 1; n <= 20; ++n)
            EXPECT_NEAR(cents(partials.frequency_hz[static_cast<std::size_t>(n - 1)], s.pinned(s.length - held_at, n)), 0.0, 0.05)
                << "fret " << fret << " partial " << n;
    }
}

TEST(HeldString, AStiffStringHeldAtItsMiddleSplitsIntoThePinnedAndTheClampedHalf) {
    // Held at L / 2 a uniform string's modes are odd (u'' = 0 there: the half pinned at both
    // ends) or even (u' = 0: the half clamped at the middle), each with half its energy on either
    // side. The clamped end raises the partials by about sqrt(B') / pi (Fletcher).
    const StiffString s;
    const double half = s.length / 2.0;
    const HeldString held(s.table(400), s.length, half);
    const auto nearest = [&](double f) {
        return *std::min_element(held.modes().begin(), held.modes().end(), [&](const auto& a, const auto& b) {
            return std::abs(a.frequency_hz - f) < std::abs(b.frequency_hz - f);
        });
    };
    for (int n = 1; n <= 10; ++n) {
        const HeldString::Mode pinned = nearest(s.pinned(half, n)), clamped = nearest(s.clamped(half, n));
        EXPECT_NEAR(cents(pinned.frequency_hz, s.pinned(half, n)), 0.0, 0.01) << n;
        EXPECT_NEAR(cents(clamped.frequency_hz, s.clamped(half, n)), 0.0, 0.01) << n;
        EXPECT_NEAR(pinned.near_share, 0.5, 0.01);
        EXPECT_NEAR(clamped.near_share, 0.5, 0.01);
        const double first_order = std::sqrt(s.inharmonicity(half)) / kPi;
        EXPECT_NEAR((s.clamped(half, n) / s.pinned(half, n) - 1.0) / first_order, 1.0, 0.05) << n;
    }
}

TEST(HeldString, ItsSoundingPartialsLieHalfwayBetweenThePinnedAndTheClampedPiece) {
    // The near side resists the slope at the fret as much as the far side does: the held
    // string is half clamped, whatever the fret (frets 1-15 of the bass: 1.8 to 4 cents).
    const StiffString s;
    for (const int fret : {1, 5, 12, 15}) {
        const double held_at = fret_position(s.length, fret), piece = s.length - held_at;
        const ModeTable partials = HeldString(s.table(862), s.length, held_at).sounding_partials(10);
        for (int n = 1; n <= 10; ++n) {
            const double share = (partials.frequency_hz[static_cast<std::size_t>(n - 1)] - s.pinned(piece, n)) /
                                 (s.clamped(piece, n) - s.pinned(piece, n));
            EXPECT_GT(share, 0.4) << "fret " << fret << " partial " << n;
            EXPECT_LT(share, 0.6) << "fret " << fret << " partial " << n;
        }
    }
}

// The straightforward reference for the first partials of a stopped note: the held modes from
// Eigen's dense eigenvalues (vectors a_j = z_j / (omega_j^2 - omega^2)), their near-side
// overlaps integrated exactly, and the near side damped (zeta = 0.2) over all the held modes
// up to 1.5 times the partial's frequency at once.
std::vector<double> reference_partials(const Case& open, double held_at, int count) {
    const double length = open.string.length_m;
    const HeldString held(open.modes, length, held_at);
    const std::vector<double> all = dense_held_frequencies(open.modes, length, held_at, held.static_compliance());
    const ModeTable pinned = held.pinned_partials(static_cast<std::size_t>(count));
    const auto n_open = static_cast<Eigen::Index>(open.mode_count());
    Eigen::VectorXd z(n_open), d(n_open), sigma(n_open);
    for (Eigen::Index j = 0; j < n_open; ++j) {
        z(j) = std::sqrt(2.0 / length) * std::sin(static_cast<double>(j + 1) * kPi * held_at / length);
        d(j) = std::pow(2.0 * kPi * open.modes.frequency_hz[static_cast<std::size_t>(j)], 2);
        sigma(j) = open.modes.sigma_per_s[static_cast<std::size_t>(j)];
    }
    // Near-side overlaps of the open modes: (1 / pi) [sin((i - j) t) / (i - j) - sin((i + j) t) / (i + j)], t = pi x_h / L.
    const double t = kPi * held_at / length;
    const auto overlap = [&](double i, double j) {
        const double plus = std::sin((i + j) * t) / (i + j);
        return (i == j ? t - plus : std::sin((i - j) * t) / (i - j) - plus) / kPi;
    };
    Eigen::MatrixXd g(n_open, n_open);
    for (Eigen::Index i = 0; i < n_open; ++i)
        for (Eigen::Index j = 0; j < n_open; ++j) g(i, j) = overlap(static_cast<double>(i + 1), static_cast<double>(j + 1));
    std::vector<double> out;
    for (int n = 1; n <= count; ++n) {
        const double guess = pinned.frequency_hz[static_cast<std::size_t>(n - 1)];
        Eigen::Index m = 0;
        while (m < static_cast<Eigen::Index>(all.size()) && all[static_cast<std::size_t>(m)] < 1.5 * guess) ++m;
        Eigen::MatrixXd a(n_open, m);
        for (Eigen::Index c = 0; c < m; ++c) {
            const double x = std::pow(2.0 * kPi * all[static_cast<std::size_t>(c)], 2);
            a.col(c) = (z.array() / (d.array() - x)).matrix().normalized();
        }
        const Eigen::MatrixXd near = a.transpose() * g * a;
        const Eigen::MatrixXd damping = a.transpose() * sigma.asDiagonal() * a;
        const double omega = 2.0 * kPi * guess;
        Eigen::MatrixXd state = Eigen::MatrixXd::Zero(2 * m, 2 * m);
        state.topRightCorner(m, m).setIdentity();
        for (Eigen::Index r = 0; r < m; ++r) state(m + r, r) = -std::pow(all[static_cast<std::size_t>(r)] / guess, 2);
        state.bottomRightCorner(m, m) = -(2.0 / omega) * damping - 2.0 * HeldString::kNearSideDampingRatio * near;
        const Eigen::EigenSolver<Eigen::MatrixXd> solver(state);
        double best = 1e300, f_best = 0.0;
        for (Eigen::Index k = 0; k < 2 * m; ++k) {
            const std::complex<double> lambda = solver.eigenvalues()(k);
            const Eigen::VectorXcd v = solver.eigenvectors().col(k).head(m);
            if (lambda.imag() <= 0.0 || (v.adjoint() * near * v)(0).real() / v.squaredNorm() >= 0.5) continue;
            const double f = std::abs(lambda) * guess;
            if (std::abs(std::log(f / guess)) < best) {
                best = std::abs(std::log(f / guess));
                f_best = f;
            }
        }
        out.push_back(f_best);
    }
    return out;
}

class StandIn : public ::testing::TestWithParam<std::string> {};

TEST_P(StandIn, ItsPartialsAreTheHeldStringsWithinACent) {
    // The first 10 partials of stopped_string() at frets 1, 5, 12 and 15 of the bass against
    // the dense reference; and 1.5-4 cents above the pinned piece's (the former stand-in).
    const Case open = load_case(GetParam());
    for (const int fret : {1, 5, 12, 15}) {
        const double stop = fret_position(open.string.length_m, fret);
        const Case stopped = stopped_string(open, stop, open.mode_count());
        const std::vector<double> reference = reference_partials(open, stop, 10);
        const ModeTable pinned = HeldString(open.modes, open.string.length_m, stop).pinned_partials(10);
        for (std::size_t n = 0; n < 10; ++n) {
            EXPECT_NEAR(cents(stopped.modes.frequency_hz[n], reference[n]), 0.0, 1.0) << "fret " << fret << " partial " << n + 1;
            EXPECT_GT(cents(stopped.modes.frequency_hz[n], pinned.frequency_hz[n]), 1.0) << "fret " << fret << " partial " << n + 1;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Bass, StandIn, ::testing::Values("bass-neck", "bass-pop"));

TEST(StoppedString, TheHeldPartialsDampingFollowsTheShorterWavelength) {
    // bass-neck's damping law sigma = eta0 + eta2 k^2 at the piece's k = n pi / L'.
    const StiffString s;
    const Case open = load_case("bass-neck");
    for (const int fret : {5, 12}) {
        const double piece = s.length - fret_position(s.length, fret);
        const Case stopped = stopped_string(open, fret_position(s.length, fret), open.mode_count());
        for (int n = 1; n <= 20; ++n) {
            const double k = n * kPi / piece;
            EXPECT_NEAR(stopped.modes.sigma_per_s[static_cast<std::size_t>(n - 1)] / (s.eta0 + s.eta2 * k * k), 1.0, 0.01) << n;
        }
    }
}

TEST(StoppedString, UnstoppedItIsTheOpenStringWithFewerModes) {
    const Case open = load_case("bass-pop");
    const Case c = stopped_string(open, 0.0, 300);
    ASSERT_EQ(c.mode_count(), 300u);
    for (std::size_t j = 0; j < 300; ++j) {
        EXPECT_EQ(c.modes.frequency_hz[j], open.modes.frequency_hz[j]);
        EXPECT_EQ(c.modes.sigma_per_s[j], open.modes.sigma_per_s[j]);
        EXPECT_EQ(c.modes.source[j], open.modes.source[j]);
        EXPECT_EQ(c.initial_displacement[j], open.initial_displacement[j]);
    }
}

TEST(StoppedString, HoldsTheSecondPolarisationsOwnTableToo) {
    // A measured y table (as many modes as z): held mode for mode like the z one, so the
    // stopped case keeps one basis for both polarisations.
    Case open = load_case("bass-neck");
    open.polarisation.count = 2;
    open.polarisation.table = open.modes;
    for (double& f : open.polarisation.table.frequency_hz) f *= 1.002;
    const double stop = fret_position(open.string.length_m, 7);
    for (const std::size_t modes : {open.mode_count(), std::size_t{300}}) {
        const Case stopped = stopped_string(open, stop, modes);
        ASSERT_EQ(stopped.polarisation.table.size(), stopped.mode_count());
        const ModeTable y = HeldString(open.polarisation.table, open.string.length_m, stop).sounding_partials(modes);
        for (std::size_t n = 0; n < 10; ++n) {
            EXPECT_EQ(stopped.polarisation.table.frequency_hz[n], y.frequency_hz[n]);
            EXPECT_NEAR(cents(stopped.polarisation.table.frequency_hz[n], stopped.modes.frequency_hz[n]), 1200 * std::log2(1.002), 0.01);
        }
    }
    EXPECT_EQ(stopped_string(open, 0.0, 300).polarisation.table.size(), 300u);
}

TEST(StoppedString, RefusesAStopOffTheStringNamingIt) {
    const Case open = load_case("bass-neck");
    const auto message = [&](double stop, std::size_t modes) {
        try {
            stopped_string(open, stop, modes);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_NE(message(-0.01, 10).find("stop position"), std::string::npos);
    EXPECT_NE(message(0.7, 10).find("stop position"), std::string::npos);
    EXPECT_NE(message(0.2, 0).find("modes"), std::string::npos);
    EXPECT_THROW(HeldString(open.modes, 0.863, 0.0), InputError);
    EXPECT_THROW(HeldString(open.modes, 0.863, 0.863), InputError);
}

}  // namespace
}  // namespace fretbuzz
