// A stopped note: the held string (the open string's modes with u(x_h) = 0, the string going
// on over the fret to the nut, the finger on it) against closed forms and against a
// straightforward dense reference; the pinned piece's stiffness (B' = B (L / L')^2); the
// stand-in Case that stopped_string() builds from them.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/StoppedString.hpp"
#include "fretbuzz/scheme/HeldString.hpp"
#include "fretbuzz/numerics/TimeProfile.hpp"
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
    // `fret = k`'s finger on this string's fret k, the string lying on fret k - 1 too.
    HeldString::Finger finger(int fret) const {
        const double x = fret_position(length, fret), before = fret_position(length, fret - 1);
        return HeldString::Finger::of(finger_behind_fret(x, x - before), kFretFingerForce, before);
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
    // truncation's 1 / N error away: 1.2 cents at fret 5 with 200 modes without it), and the
    // finger behind the fret, whose loss damps a stiff string's upper partials several times
    // over, cannot reach them: their dampings are the law's at k = n pi / L'.
    StiffString s;
    s.bending = 0.0;
    for (const int fret : {1, 5, 12, 15}) {
        const double held_at = fret_position(s.length, fret), piece = s.length - held_at;
        const ModeTable partials = HeldString(s.table(200), s.length, held_at).sounding_partials(20, s.finger(fret), s.density);
        for (int n = 1; n <= 20; ++n) {
            const auto i = static_cast<std::size_t>(n - 1);
            EXPECT_NEAR(cents(partials.frequency_hz[i], s.pinned(piece, n)), 0.0, 0.1) << "fret " << fret << " partial " << n;
            const double k = n * kPi / piece;
            EXPECT_NEAR(partials.sigma_per_s[i] / (s.eta0 + s.eta2 * k * k), 1.0, 0.05) << "fret " << fret << " partial " << n;
        }
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

// The E string of the Jazz Bass (cases/instruments/jazz-bass.toml): 18 times bass-neck's B.
StiffString jazz_bass_e() { return {0.863, 176.79, 0.034956, 8.5206e-3}; }

struct Partial {
    double frequency_hz = 0.0, sigma_per_s = 0.0;
};

// The straightforward reference for a stopped note with the finger: the open modes with a
// stiff spring at x_b and at x_h (the inverse of the static compliance between them of the
// modes above the table, summed explicitly to mode 10^6), their held modes from Eigen's dense
// eigenvalues (the springs' own two left out), the finger's mass one more coordinate, each
// pad point tied to it by a spring and a damper as HeldString::Finger describes, one dense
// quadratic eigenproblem in state space solved by Eigen; each partial the complex mode with
// most of its kinetic energy beyond x_h nearest to the pinned piece's partial times the last
// partial's held-to-pinned ratio.
std::vector<Partial> dense_finger_partials(const StiffString& s, const ModeTable& open, const HeldString::Finger& f, double held_at,
                                           int count) {
    const auto n = static_cast<Eigen::Index>(open.size());
    const double dx = s.length / static_cast<double>(n + 1);
    const auto phi = [&](double x) {
        Eigen::VectorXd v(n);
        for (Eigen::Index j = 0; j < n; ++j) v(j) = std::sqrt(2.0 / s.length) * std::sin(static_cast<double>(j + 1) * kPi * x / s.length);
        return v;
    };
    Eigen::MatrixXd z(n, 2);
    z << phi(f.behind_m), phi(held_at);
    Eigen::Matrix2d tail = Eigen::Matrix2d::Zero();
    for (int j = static_cast<int>(n) + 1; j <= 1000000; ++j) {
        const double k = j * kPi / s.length;
        const Eigen::Vector2d zj(std::sin(k * f.behind_m), std::sin(k * held_at));
        tail += 2.0 / s.length * zj * zj.transpose() / std::pow(2.0 * kPi * s.frequency_at(k), 2);
    }
    Eigen::MatrixXd springs = Eigen::MatrixXd::Zero(n, n);
    for (Eigen::Index j = 0; j < n; ++j) springs(j, j) = std::pow(2.0 * kPi * open.frequency_hz[static_cast<std::size_t>(j)], 2);
    springs += z * tail.inverse() * z.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> held(springs);
    const Eigen::MatrixXd q = held.eigenvectors().leftCols(n - 2);
    Eigen::VectorXd damping(n);
    for (Eigen::Index j = 0; j < n; ++j) damping(j) = 2.0 * open.sigma_per_s[static_cast<std::size_t>(j)];
    const std::vector<std::size_t> pad = pad_points(f.pad_centre_m, f.pad_width_m, dx, static_cast<std::size_t>(n));
    const auto p = static_cast<double>(pad.size());
    const double eta = std::pow(f.force_n / f.stiffness, 1.0 / f.exponent);
    const double spring = f.exponent * f.stiffness / p * std::pow(eta, f.exponent - 1.0) / s.density;
    const double damper = f.loss * f.force_n / p / s.density;
    const Eigen::Index m = n - 1;  // held coordinates, then the finger's height
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(m, m), c = Eigen::MatrixXd::Zero(m, m);
    k.topLeftCorner(m - 1, m - 1) = held.eigenvalues().head(n - 2).asDiagonal();
    c.topLeftCorner(m - 1, m - 1) = q.transpose() * damping.asDiagonal() * q;
    for (const std::size_t i : pad) {
        Eigen::VectorXd e = Eigen::VectorXd::Zero(m);  // u_i - z
        e.head(m - 1) = q.transpose() * phi(static_cast<double>(i + 1) * dx);
        e(m - 1) = -1.0;
        k += spring * e * e.transpose();
        c += damper * e * e.transpose();
    }
    Eigen::VectorXd mass = Eigen::VectorXd::Ones(m);
    mass(m - 1) = f.mass_kg / s.density;
    Eigen::MatrixXd state = Eigen::MatrixXd::Zero(2 * m, 2 * m);
    state.topRightCorner(m, m).setIdentity();
    state.bottomLeftCorner(m, m) = -(mass.cwiseInverse().asDiagonal() * k);
    state.bottomRightCorner(m, m) = -(mass.cwiseInverse().asDiagonal() * c);
    const Eigen::EigenSolver<Eigen::MatrixXd> solver(state);
    const auto far_share = [&](Eigen::Index e) {
        const Eigen::VectorXcd a = q * solver.eigenvectors().col(e).head(m - 1);
        double far = 0.0, all = 0.0;
        for (Eigen::Index i = 1; i <= n; ++i) {
            const double x = static_cast<double>(i) * dx;
            const double u = std::norm(phi(x).cast<std::complex<double>>().dot(a));
            all += u;
            if (x > held_at) far += u;
        }
        return far / all;
    };
    std::vector<Partial> out;
    double ratio = 1.0;
    for (int partial = 1; partial <= count; ++partial) {
        const double target = 2.0 * kPi * s.pinned(s.length - held_at, partial) * ratio;
        double best = 0.03;  // within 52 cents of the target
        Partial found;
        for (Eigen::Index e = 0; e < 2 * m; ++e) {
            const std::complex<double> lambda = solver.eigenvalues()(e);
            const double distance = std::abs(std::log(std::abs(lambda) / target));
            if (lambda.imag() <= 0.0 || distance >= best || far_share(e) <= 0.5) continue;
            best = distance;
            found = {std::abs(lambda) / (2.0 * kPi), -lambda.real()};
        }
        out.push_back(found);
        ratio = found.frequency_hz * 2.0 * kPi / (target / ratio);
    }
    return out;
}

TEST(HeldString, TheFingersPartialsAreThoseOfTheDenseProblem) {
    // The window of held modes with the finger attached (the other modes as their flexibility)
    // against every mode at once, on the Jazz Bass E string at frets 5, 12 and 15: the finger
    // raises its partials 16-23 cents above the pinned piece and damps partials 6-10 up to 60
    // times the string's own, the reference to 0.1 cents and 1 % in damping.
    const StiffString s = jazz_bass_e();
    const ModeTable open = s.table(200);
    for (const int fret : {5, 12, 15}) {
        const double held_at = fret_position(s.length, fret);
        const std::vector<Partial> dense = dense_finger_partials(s, open, s.finger(fret), held_at, 10);
        const ModeTable partials = HeldString(open, s.length, held_at).sounding_partials(10, s.finger(fret), s.density);
        for (std::size_t n = 0; n < 10; ++n) {
            EXPECT_NEAR(cents(partials.frequency_hz[n], dense[n].frequency_hz), 0.0, 0.1) << "fret " << fret << " partial " << n + 1;
            EXPECT_NEAR(partials.sigma_per_s[n] / dense[n].sigma_per_s, 1.0, 0.01) << "fret " << fret << " partial " << n + 1;
            std::printf("fret %d partial %zu: %+.3f cents, sigma %.3f / %.3f, %+.2f cents over the pinned piece\n", fret, n + 1,
                        cents(partials.frequency_hz[n], dense[n].frequency_hz), partials.sigma_per_s[n], dense[n].sigma_per_s,
                        cents(partials.frequency_hz[n], s.pinned(s.length - held_at, static_cast<int>(n + 1))));
        }
    }
}

TEST(HeldString, TheFingersLossDampsTheUpperPartials) {
    // The finger's Hunt-Crossley loss is where the stopped note's upper partials lose most:
    // without it (lambda = 0) the finger only stores energy and no partial loses more than the
    // string's own damping; with it, at fret 12 of the E string, partials 6 to 10 lose at least
    // 3 times as fast. The lowest partials move the finger's mass with the string and lose
    // little to it; their pitch hardly depends on it.
    const StiffString s = jazz_bass_e();
    const double held_at = fret_position(s.length, 12);
    const HeldString held(s.table(400), s.length, held_at);
    HeldString::Finger lossless = s.finger(12);
    lossless.loss = 0.0;
    HeldString::Finger doubled = s.finger(12);
    doubled.loss *= 2.0;
    const ModeTable with = held.sounding_partials(10, s.finger(12), s.density);
    const ModeTable without = held.sounding_partials(10, lossless, s.density);
    const ModeTable twice = held.sounding_partials(10, doubled, s.density);
    const ModeTable pinned = held.pinned_partials(10);
    for (std::size_t n = 0; n < 10; ++n) {
        std::printf("partial %zu: sigma %.3f without loss %.3f (pinned %.3f), doubled %.3f; %+.3f cents with the loss doubled\n", n + 1,
                    with.sigma_per_s[n], without.sigma_per_s[n], pinned.sigma_per_s[n], twice.sigma_per_s[n],
                    cents(twice.frequency_hz[n], with.frequency_hz[n]));
        EXPECT_LT(without.sigma_per_s[n], 1.01 * pinned.sigma_per_s[n]) << n + 1;
        if (n >= 5) {
            EXPECT_GT(with.sigma_per_s[n], 3.0 * without.sigma_per_s[n]) << n + 1;
        }
        if (n < 2) {
            EXPECT_NEAR(with.sigma_per_s[n] / without.sigma_per_s[n], 1.0, 0.05) << n + 1;
        }
        if (n < 3) {
            EXPECT_LT(std::abs(cents(twice.frequency_hz[n], with.frequency_hz[n])), 0.05) << n + 1;
        }
    }
}

class StandIn : public ::testing::TestWithParam<std::string> {};

TEST_P(StandIn, ItsPartialsAreTheHeldStringsWithTheFretFingerAboveThePinnedPiece) {
    // stopped_string() at frets 1, 5, 12 and 15 of the bass: the held string with `fret = k`'s
    // finger (its pad where the case's finger goes, the string on fret k - 1 too), its first
    // 10 partials 1.5-5.5 cents above the pinned piece's (the former stand-in).
    const Case open = load_case(GetParam());
    for (const int fret : {1, 5, 12, 15}) {
        const auto k = static_cast<std::size_t>(fret);
        const double stop = open.fret_positions_m[k - 1];
        const HeldString::Finger finger = stopping_finger(open, stop);
        const FingerSpec spec = open.fret_finger(k, "fret");
        EXPECT_EQ(finger.pad_centre_m, spec.position_m);
        EXPECT_EQ(finger.pad_width_m, spec.width_m);
        EXPECT_EQ(finger.behind_m, fret > 1 ? open.fret_positions_m[k - 2] : 0.0);
        const Case stopped = stopped_string(open, stop, open.mode_count());
        const HeldString held(open.modes, open.string.length_m, stop);
        const ModeTable partials = held.sounding_partials(10, finger, open.string.linear_density);
        const ModeTable pinned = held.pinned_partials(10);
        for (std::size_t n = 0; n < 10; ++n) {
            EXPECT_EQ(stopped.modes.frequency_hz[n], partials.frequency_hz[n]);
            EXPECT_EQ(stopped.modes.sigma_per_s[n], partials.sigma_per_s[n]);
            EXPECT_GT(cents(stopped.modes.frequency_hz[n], pinned.frequency_hz[n]), 1.0) << "fret " << fret << " partial " << n + 1;
            EXPECT_LT(cents(stopped.modes.frequency_hz[n], pinned.frequency_hz[n]), 6.0) << "fret " << fret << " partial " << n + 1;
        }
    }
}

TEST(StoppedString, ABareStringIsTakenAsFrettedInEqualTemperament) {
    // The set-up bench shortens a string with no obstacle at all (its neck is StringNeck's):
    // stopped at x_k = L (1 - 2^(-k/12)) it lies on fret k - 1 too, at x_(k-1), as the case's
    // own fret k - 1 would have it; a fretless neck has no fret behind.
    Case bare = load_case("bass-neck");
    bare.obstacle_height_m.assign(bare.mode_count(), -std::numeric_limits<double>::infinity());
    bare.point_obstacles.clear();
    bare.fret_positions_m.clear();
    const double length = bare.string.length_m;
    for (const int fret : {1, 5, 12}) {
        const HeldString::Finger f = stopping_finger(bare, fret_position(length, fret));
        EXPECT_NEAR(f.behind_m, fret > 1 ? fret_position(length, fret - 1) : 0.0, 1e-12) << fret;
        const FingerSpec spec = finger_behind_fret(fret_position(length, fret), fret_position(length, fret) - fret_position(length, fret - 1));
        EXPECT_NEAR(f.pad_centre_m, spec.position_m, 1e-12) << fret;
    }
    EXPECT_EQ(stopping_finger(load_case("bass-fretless"), fret_position(length, 5)).behind_m, 0.0);
}

INSTANTIATE_TEST_SUITE_P(Bass, StandIn, ::testing::Values("bass-neck", "bass-pop"));

TEST(StoppedString, TheHeldPartialsDampingIsTheStringsOwnPlusTheFingers) {
    // bass-neck's damping law sigma = eta0 + eta2 k^2 at the piece's k = n pi / L' for the
    // first partial (which moves the finger with the string), never less (the finger only takes).
    const StiffString s;
    const Case open = load_case("bass-neck");
    for (const int fret : {5, 12}) {
        const double piece = s.length - fret_position(s.length, fret);
        const Case stopped = stopped_string(open, fret_position(s.length, fret), open.mode_count());
        for (int n = 1; n <= 20; ++n) {
            const double k = n * kPi / piece, law = s.eta0 + s.eta2 * k * k;
            const double sigma = stopped.modes.sigma_per_s[static_cast<std::size_t>(n - 1)];
            EXPECT_GT(sigma / law, 0.99) << n;
            if (n == 1) {
                EXPECT_NEAR(sigma / law, 1.0, 0.02) << n;
            }
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
        const ModeTable y = HeldString(open.polarisation.table, open.string.length_m, stop)
                                .sounding_partials(modes, stopping_finger(open, stop), open.string.linear_density);
        for (std::size_t n = 0; n < 10; ++n) {
            EXPECT_EQ(stopped.polarisation.table.frequency_hz[n], y.frequency_hz[n]);
            EXPECT_NEAR(cents(stopped.polarisation.table.frequency_hz[n], stopped.modes.frequency_hz[n]), 1200 * std::log2(1.002), 0.01);
        }
    }
    EXPECT_EQ(stopped_string(open, 0.0, 300).polarisation.table.size(), 300u);
}

TEST(StoppedString, AFretStopsTheStringWhereTheCaseHasItsFret) {
    // The plugin and the real-time voices stop a note at the case's own fret, not at the
    // equal-tempered formula: bass-pop's frets stand where its obstacle has them.
    const Case open = load_case("bass-pop");
    const std::size_t frets = open.fret_positions_m.size();
    ASSERT_GE(frets, 20u);
    double largest_departure = 0.0;
    for (std::size_t k = 1; k <= frets; ++k) {
        const int fret = static_cast<int>(k);
        EXPECT_EQ(fret_stop_m(open, fret), open.fret_positions_m[k - 1]) << k;
        largest_departure = std::max(largest_departure, std::abs(fret_stop_m(open, fret) - fret_position(open.string.length_m, fret)));
    }
    // The case's frets are not the formula's (else this test could not tell them apart).
    EXPECT_GT(largest_departure, 1e-6);
    // Past its last fret, and on a case without frets, the equal-tempered stop.
    const int past = static_cast<int>(frets) + 1;
    EXPECT_EQ(fret_stop_m(open, past), fret_position(open.string.length_m, past));
    Case fretless = open;
    fretless.fret_positions_m.clear();
    EXPECT_EQ(fret_stop_m(fretless, 5), fret_position(fretless.string.length_m, 5));
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

TEST(StoppedString, RefusesAFingerThatDoesNotFitBehindTheStopNamingIt) {
    const Case open = load_case("bass-neck");
    const double stop = open.fret_positions_m[4];
    const auto message = [&](const HeldString::Finger& f) {
        try {
            stopped_string(open, stop, 100, f);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    const HeldString::Finger good = stopping_finger(open, stop);
    EXPECT_EQ(message(good), "");
    HeldString::Finger f = good;
    f.pad_centre_m = stop + 0.01;  // past the fret
    EXPECT_NE(message(f).find("finger pad point"), std::string::npos) << message(f);
    f = good;
    f.behind_m = good.pad_centre_m;  // the pad over the fret behind
    EXPECT_NE(message(f).find("finger pad point"), std::string::npos) << message(f);
    f.behind_m = stop;
    EXPECT_NE(message(f).find("fret behind the stop"), std::string::npos) << message(f);
    f = good;
    f.mass_kg = 0.0;
    EXPECT_NE(message(f).find("finger mass"), std::string::npos) << message(f);
    f = good;
    f.loss = -1.0;
    EXPECT_NE(message(f).find("finger loss"), std::string::npos) << message(f);
}

}  // namespace
}  // namespace fretbuzz
