// A finger that stops the string (Finger): the discrete energy balance stays exact with it
// (string + obstacle + finger energies - the pressing force's work + losses is constant),
// lossless and lossy, while pressing and after lifting; a stopped note sounds at the
// stopped length's pitch; and a finger changes nothing while it cannot touch.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <numbers>
#include <string>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/numerics/ModalBasis.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"
#include "SmallBass.hpp"

namespace fretbuzz {
namespace {

Case small_bass(double fs, double duration, double amplitude = 0.2e-3, std::size_t modes = 255) {
    return testing::small_bass(fs, duration, amplitude, modes);
}

struct Ledger {
    std::vector<double> energy, work, dissipated, finger_loss, contact_force;
    long contact_steps = 0;
    double scale = 0.0;  // the largest of the initial energy and the work done
};

Ledger run_ledger(const Case& c, long steps, bool screen = true) {
    c.validate();
    PlanOptions options;
    options.screen_contacts = screen;
    const Plan plan(c, 1.0 / c.run.sample_rate_hz, options);
    Stepper stepper(plan, c.initial_displacement, c.initial_velocity);
    Ledger l;
    for (long n = 1; n <= steps; ++n) {
        stepper.step();
        l.energy.push_back(stepper.energy());
        l.work.push_back(stepper.work());
        l.dissipated.push_back(stepper.dissipated());
        l.finger_loss.push_back(stepper.finger_loss());
        l.contact_force.push_back(stepper.fingers().empty() ? 0.0 : stepper.fingers().front().contact_force());
        l.scale = std::max({l.scale, std::abs(l.energy.front()), std::abs(l.work.back())});
    }
    l.contact_steps = stepper.statistics().contact_steps;
    return l;
}

// |(H - W + D)^n - (H - W + D)^1| over the run, relative to the ledger's scale.
double worst_balance_error(const Ledger& l) {
    const double start = l.energy.front() - l.work.front() + l.dissipated.front();
    double worst = 0.0;
    for (std::size_t n = 0; n < l.energy.size(); ++n)
        worst = std::max(worst, std::abs(l.energy[n] - l.work[n] + l.dissipated[n] - start));
    return worst / l.scale;
}

TEST(Finger, LosslessBalanceIsExactWhilePressingAStringOntoAFret) {
    Case c = small_bass(400000.0, 0.25);
    c.make_lossless();
    c.add_fret_finger(5, "fret");
    c.fingers.back().loss = 0.0;
    const Ledger l = run_ledger(c, 100000);
    EXPECT_GT(l.work.back(), 0.5 * l.energy.front());  // the finger does real work on the string
    // and leans on it with its 5 N: without losses the finger never settles, but its momentum
    // stays bounded, so over the second half the mean contact force is the pressing force
    // (the force at any one step depends on the bounce and on round-off).
    const auto half = l.contact_force.begin() + static_cast<std::ptrdiff_t>(l.contact_force.size() / 2);
    const double mean_force = std::accumulate(half, l.contact_force.end(), 0.0) /
                              static_cast<double>(l.contact_force.end() - half);
    EXPECT_NEAR(mean_force, 5.0, 0.25);
    EXPECT_LT(worst_balance_error(l), 1e-10);
    for (double d : l.dissipated) EXPECT_EQ(d, 0.0);
}

TEST(Finger, BalanceWithDampingAndContactLossIsExactAndLossesNeverDecrease) {
    Case c = small_bass(400000.0, 0.25);
    c.add_fret_finger(12, "fret");
    const Ledger l = run_ledger(c, 100000);
    EXPECT_LT(worst_balance_error(l), 1e-10);
    for (std::size_t n = 1; n < l.energy.size(); ++n) {
        ASSERT_GE(l.finger_loss[n], l.finger_loss[n - 1]) << "step " << n;
        ASSERT_GE(l.dissipated[n], l.dissipated[n - 1]) << "step " << n;
    }
    EXPECT_GT(l.finger_loss.back(), 0.0);
}

TEST(Finger, BalanceStaysExactWhenTheFingerIsLiftedAndFliesOff) {
    Case c = small_bass(400000.0, 0.25);
    c.make_lossless();
    c.add_fret_finger(7, "fret");
    c.fingers.back().force_profile = {{0.0, 0.0}, {0.005, 5.0}, {0.1, 5.0}, {0.11, 0.0}};
    const Ledger l = run_ledger(c, 100000);
    EXPECT_LT(worst_balance_error(l), 1e-10);
    EXPECT_GT(*std::max_element(l.contact_force.begin(), l.contact_force.end()), 4.0);
    EXPECT_EQ(l.contact_force.back(), 0.0);  // the string threw the finger off
}

TEST(Finger, ScreenedAndStraightforwardPathsAgree) {
    Case c = small_bass(400000.0, 0.05);
    c.add_fret_finger(5, "fret");
    const testing::PathComparison p = testing::compare_paths(c, 20000);
    EXPECT_GT(p.contact_steps, 0);
    // The paths round differently at every step, and the finger landing on the string amplifies
    // round-off some 1e4-fold here (a pluck 1e-15 larger moves the state by 3e-10 after these
    // steps): they agree to about 2e-9.
    EXPECT_LT(p.relative_l2, 1e-8);
}

TEST(Finger, AFingerThatNeverTouchesChangesNothing) {
    Case c = small_bass(400000.0, 0.05, 3e-3);
    // Beside a finger's pad the frets' crowns take their nearest grid points (the pad and exact
    // points are not solved together): the open reference has them there too.
    c.obstacle_height_m = c.obstacle_on_grid();
    c.point_obstacles.clear();
    const Ledger open = run_ledger(c, 20000, false);
    ASSERT_GT(open.contact_steps, 0);  // the fret contacts are there to be kept
    c.fingers.push_back(FingerSpec{});
    c.fingers.back().position_m = 0.2;
    c.fingers.back().initial_gap_m = 0.01;  // 1 cm above, never pressed
    const Ledger with_finger = run_ledger(c, 20000, false);
    EXPECT_EQ(with_finger.contact_steps, open.contact_steps);
    for (std::size_t n = 0; n < open.energy.size(); ++n)
        ASSERT_NEAR(with_finger.energy[n], open.energy[n], 1e-12 * open.energy.front()) << "step " << n;
}

// Frequency of the strongest component of u within [lo, hi] Hz: the peak of the
// Hann-windowed spectrum, found on a fine grid and refined by a parabola.
double peak_frequency(const std::vector<double>& u, double rate, double lo, double hi) {
    const std::size_t n = u.size();
    const auto magnitude = [&](double f) {
        double re = 0.0, im = 0.0;
        const double w = 2.0 * std::numbers::pi * f / rate;
        for (std::size_t k = 0; k < n; ++k) {
            const double hann = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n));
            re += hann * u[k] * std::cos(w * static_cast<double>(k));
            im -= hann * u[k] * std::sin(w * static_cast<double>(k));
        }
        return std::hypot(re, im);
    };
    const double step = 0.02;
    double best = lo, best_m = -1.0;
    for (double f = lo; f <= hi; f += step)
        if (const double m = magnitude(f); m > best_m) {
            best_m = m;
            best = f;
        }
    const double a = magnitude(best - step), b = best_m, cc = magnitude(best + step);
    return best + 0.5 * step * (a - cc) / (a - 2.0 * b + cc);
}

// The fundamental of u at 9 mm from the bridge, after `settle` seconds, near `expected` Hz.
double fundamental(const Case& c, double settle, double expected) {
    c.validate();
    PlanOptions options;
    options.screen_contacts = false;  // every point solved: the transform is cheap on 256 points
    const Plan plan(c, 1.0 / c.run.sample_rate_hz, options);
    Stepper stepper(plan, c.initial_displacement, c.initial_velocity);
    const std::vector<double> shape = plan.basis().mode_shapes_at(0.854);
    const long steps = std::lround(c.run.duration_s * c.run.sample_rate_hz);
    const long first = std::lround(settle * c.run.sample_rate_hz);
    constexpr long kDecimate = 10;  // the fundamental is far below the decimated Nyquist
    std::vector<double> u;
    for (long n = 1; n <= steps; ++n) {
        stepper.step();
        if (n >= first && n % kDecimate == 0) u.push_back(stepper.displacement(shape));
    }
    const double rate = c.run.sample_rate_hz / kDecimate;
    return peak_frequency(u, rate, 0.97 * expected, 1.03 * expected);
}

double cents(double f, double reference) { return 1200.0 * std::log2(f / reference); }

// The same bass with the stiff-string frequencies nu_j = j nu_0 sqrt(1 + B j^2) (B of its
// Table 2) in place of the measured ones: the measured nu_1 lies 4.6 cents below the series
// of the modes above it (nu_j / (j nu_1) - 1 is +4.6 cents at j = 2, +5 at j = 4), so a note
// stopped on the measured table sounds where those modes put it, up to 7 cents off
// nu_1 L / (L - x_k) (see docs/validation.md). The model table isolates the scheme.
Case small_model_bass(double fs, double duration, double kB = 3.5e-5, std::size_t modes = 255) {
    Case c = small_bass(fs, duration, 0.2e-3, modes);
    const double nu0 = std::sqrt(c.string.tension_n / c.string.linear_density) / (2.0 * c.string.length_m);
    for (std::size_t j = 0; j < c.mode_count(); ++j) {
        const double n = static_cast<double>(j + 1);
        c.modes.frequency_hz[j] = n * nu0 * std::sqrt(1.0 + kB * n * n);
    }
    return c;
}

class StoppedNote : public ::testing::TestWithParam<int> {};

TEST_P(StoppedNote, SoundsAtTheStoppedLengthsPitch) {
    const int k = GetParam();
    Case open = small_model_bass(100000.0, 1.3);
    const double f_open = fundamental(open, 0.3, open.modes.frequency_hz[0]);
    Case stopped = open;
    stopped.add_fret_finger(static_cast<std::size_t>(k), "fret");
    const double length = open.string.length_m;
    const double x_k = open.fret_positions_m[static_cast<std::size_t>(k) - 1];
    const double expected = f_open * length / (length - x_k);
    const double f = fundamental(stopped, 0.3, expected);
    EXPECT_LT(std::abs(cents(f, expected)), 5.0) << "fret " << k << ": " << f << " Hz, expected " << expected
                                                 << " Hz (open " << f_open << " Hz)";
}

INSTANTIATE_TEST_SUITE_P(Frets, StoppedNote, ::testing::Values(1, 5, 7, 12));

// Without bending stiffness (B = 0) the stopped string is the ideal one, pinned at the fret:
// the few cents of the stiff string (the string held over the fret by the finger is partly
// clamped there, which raises a stiff string's pitch; see docs/validation.md) are gone, and
// what is left is the truncation's (the crown acts at its exact position beside the finger).
TEST(Finger, AnIdealStringStoppedAtAFretSoundsAtTheStoppedLengthsPitchWithinTheGridsError) {
    Case open = small_model_bass(100000.0, 1.3, 0.0);
    const double f_open = fundamental(open, 0.3, open.modes.frequency_hz[0]);
    const double length = open.string.length_m;
    for (const std::size_t k : {std::size_t{1}, std::size_t{12}}) {
        Case stopped = open;
        stopped.add_fret_finger(k, "fret");
        const double fret = open.fret_positions_m[k - 1];
        const double expected = f_open * length / (length - fret);
        const double f = fundamental(stopped, 0.3, expected);
        std::printf("fret %zu: %.3f cents from the exact fret's pitch\n", k, cents(f, expected));
        EXPECT_LT(std::abs(cents(f, expected)), 1.5) << "fret " << k << ": " << f << " Hz, expected " << expected;
    }
}

// The crown the finger presses the string onto acts at its exact position, so the stopped length
// is the same on any mode count: the note's pitch moves with the truncation alone. On its nearest
// grid point, fret 6 moves by +3.8 mm on 110 modes (7.8 mm apart) and by -1.0 mm on 400: 13.5
// cents apart on top of the truncation's.
TEST(Finger, AStoppedNotesPitchHardlyDependsOnTheModeCount) {
    constexpr std::size_t kFret = 6;
    const auto pitch = [&](std::size_t modes, bool on_grid) {
        Case c = small_model_bass(100000.0, 1.3, 0.0, modes);
        if (on_grid) {  // each crown on its nearest grid point (the obstacle as it was sampled)
            c.obstacle_height_m = c.obstacle_on_grid();
            c.point_obstacles.clear();
        }
        c.add_fret_finger(kFret, "fret");
        const double length = c.string.length_m;
        const double expected = c.modes.frequency_hz[0] * length / (length - c.fret_positions_m[kFret - 1]);
        return fundamental(c, 0.3, expected);
    };
    const double exact_110 = pitch(110, false), exact_400 = pitch(400, false);
    const double grid_110 = pitch(110, true), grid_400 = pitch(400, true);
    std::printf("fret %zu: %.4f Hz (110 modes), %.4f Hz (400): %.3f cents apart; crowns on the grid: %.4f Hz, %.4f Hz: %.3f cents\n",
                kFret, exact_110, exact_400, cents(exact_110, exact_400), grid_110, grid_400, cents(grid_110, grid_400));
    EXPECT_LT(std::abs(cents(exact_110, exact_400)), 0.25 * std::abs(cents(grid_110, grid_400)));
    EXPECT_LT(std::abs(cents(exact_110, exact_400)), 3.0);  // the truncation's: 1.9 cents at fret 5
}

// On a bare board (the frets taken away) the string leaves the board at the finger's bridge-side
// edge: over one grid step (dx = 3.4 mm) the pitch rises by the stopped length's change, about 9
// cents at fret 5. Within the step it rises in stairs: the pad's points and the board's are grid
// points, so where the string leaves the board moves by whole grid steps (measured, by quarters of
// dx: +0.00 +6.99 +1.93 +0.00 cents). A pad weighting its edge points by the part of their cells
// within it gave +1.98 +3.95 +2.72 +0.27: the board's grid still sets the stairs. On a fretted
// neck the exact crown, not the pad, sets the stopped length.
TEST(Finger, OnABareBoardThePitchFollowsTheFingerOverAGridStep) {
    Case c = small_model_bass(100000.0, 1.3);
    c.point_obstacles.clear();  // the board alone
    c.add_fret_finger(5, "fret");  // its pressing force; moved below
    const double dx = c.grid_step(), length = c.string.length_m, width = c.fingers.back().width_m;
    const double x0 = std::round(c.fingers.back().position_m / dx) * dx;
    std::vector<double> f;
    for (int quarter = 0; quarter <= 4; ++quarter) {
        Case d = c;
        d.fingers.back().position_m = x0 + 0.25 * quarter * dx;
        const double edge = d.fingers.back().position_m + 0.5 * width;
        f.push_back(fundamental(d, 0.3, c.modes.frequency_hz[0] * length / (length - edge)));
    }
    const double whole = cents(f.back(), f.front());
    const double expected = 1200.0 * std::log2((length - x0 - 0.5 * width) / (length - x0 - 0.5 * width - dx));
    std::printf("finger moved by quarters of dx on a bare board:");
    for (std::size_t q = 1; q < f.size(); ++q) std::printf(" %+.2f", cents(f[q], f[q - 1]));
    std::printf(" cents (over dx: %.2f, the stopped length's %.2f)\n", whole, expected);
    EXPECT_NEAR(whole, expected, 0.1 * expected);
    for (std::size_t q = 1; q < f.size(); ++q) EXPECT_GT(cents(f[q], f[q - 1]), -0.05) << "quarter " << q;  // never falls
}

TEST(Finger, TheOpenStringReturnsWhenTheFingerLifts) {
    Case c = small_model_bass(100000.0, 1.6);
    const double f_open = fundamental(c, 0.3, c.modes.frequency_hz[0]);
    c.add_fret_finger(5, "fret");
    // Pressed for 0.2 s, then lifted: the string throws the finger off and rings open.
    c.fingers.back().force_profile = {{0.0, 0.0}, {0.005, 5.0}, {0.2, 5.0}, {0.21, 0.0}};
    const double f = fundamental(c, 0.3, f_open);
    EXPECT_LT(std::abs(cents(f, f_open)), 5.0) << f << " Hz against the open string's " << f_open << " Hz";
}

TEST(Finger, FretPlacesTheFingerJustBehindTheFret) {
    const Case c = small_bass(100000.0, 0.1);
    ASSERT_EQ(c.fret_positions_m.size(), 20u);
    for (std::size_t k = 1; k <= 20; ++k) {
        Case d = c;
        d.add_fret_finger(k, "fret");
        const FingerSpec& f = d.fingers.back();
        const double before = k > 1 ? c.fret_positions_m[k - 2] : 0.0;
        EXPECT_LT(f.position_m + 0.5 * f.width_m, c.fret_positions_m[k - 1]) << k;
        EXPECT_GT(f.position_m - 0.5 * f.width_m, before) << k;
    }
    Case fretless = load_case("bass-fretless");
    EXPECT_TRUE(fretless.fret_positions_m.empty());
    EXPECT_THROW(fretless.add_fret_finger(5, "fret"), InputError);
}

TEST(Finger, BuiltinFingerCasesPutTheirFingersWhereTheySay) {
    for (const auto& [name, fret] : std::vector<std::pair<std::string, std::size_t>>{
             {"bass-fret1-pop", 1}, {"bass-fret5-pop", 5}, {"bass-fret12-pop", 12}, {"bass-fret5-lift", 5}}) {
        SCOPED_TRACE(name);
        const Case c = load_case(name);
        EXPECT_NO_THROW(c.validate());
        ASSERT_EQ(c.fret_positions_m.size(), 20u);  // the measured neck's 20 frets, found on its profile
        ASSERT_EQ(c.fingers.size(), 1u);
        const FingerSpec& f = c.fingers.front();
        EXPECT_LT(f.position_m, c.fret_positions_m[fret - 1]);
        EXPECT_GT(f.position_m, fret > 1 ? c.fret_positions_m[fret - 2] : 0.0);
        EXPECT_EQ(f.force_profile.back()[1] > 0.0, name != "bass-fret5-lift");  // lifted: ends at 0 N
        // Popped once the finger has settled: after its ramp to full force, at rest before.
        ASSERT_EQ(c.plucks.size(), 1u);
        EXPECT_TRUE(c.plucks.front().pop);
        EXPECT_GT(c.plucks.front().start_s, 2.0 * f.force_profile[1][0]);
        for (double q : c.initial_displacement) EXPECT_EQ(q, 0.0);
    }
    const Case guitar = load_case("guitar-pluck");
    ASSERT_EQ(guitar.plucks.size(), 1u);
    EXPECT_GT(guitar.plucks.front().release_force_n, 0.0);  // the string slips off the plectrum
    const Case slap = load_case("bass-slap");
    EXPECT_NO_THROW(slap.validate());
    ASSERT_EQ(slap.fingers.size(), 1u);
    EXPECT_TRUE(slap.fingers.front().force_profile.empty());
    EXPECT_GT(slap.fingers.front().initial_velocity, 0.0);
}

}  // namespace
}  // namespace fretbuzz
