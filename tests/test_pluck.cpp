// Plucks and pops (Pluck): a plucker on a prescribed path drags the string through its own
// penalty contact and lets it go. The work of its motion enters the discrete balance exactly
// (H - work + losses constant to round-off over 1e5 steps, lossless and lossy), it lets go
// at the set displacement or force, a slow pull holds the string at the taut string's static
// force, the screened path equals the straightforward one, and bad input is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "SmallBass.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

PluckSpec plucker(double x, double direction, double speed) {
    PluckSpec p;
    p.position_m = x;
    p.direction = direction;
    p.speed = speed;
    return p;
}

struct PluckRun {
    double worst = 0.0;      // max |H - W + D - (H - W + D)_1| / max(|H|, |W|)
    double work = 0.0;
    long release_step = -1;
    long first_contact_step = -1;  // the first level at which the plucker pushes
    double force_at_release = 0.0, force_before_release = 0.0;
    double height_at_release = 0.0;  // the plucker's, at the release level
    double string_at_release = 0.0;  // u at the pad's centre then
    bool losses_never_fall = true;
    double contact_loss = 0.0;
    bool gone = false;
    long contact_steps = 0;  // with the obstacle
    long played_steps = 0;   // with the plucker
};

PluckRun play(const Case& c, long steps) {
    c.validate();
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    Stepper s(plan, c.initial_displacement, c.initial_velocity);
    const std::vector<double> centre = plan.basis().mode_shapes_at(c.plucks.front().position_m);
    PluckRun r;
    std::vector<double> ledger;
    double scale = 0.0, previous_force = 0.0, previous_loss = 0.0;
    for (long n = 1; n <= steps; ++n) {
        s.step();
        ledger.push_back(s.energy() - s.work() + s.dissipated());
        scale = std::max({scale, std::abs(s.energy()), std::abs(s.work())});
        const Pluck& p = s.plucks().front();
        if (r.first_contact_step < 0 && p.contact_force() != 0.0) r.first_contact_step = n;
        if (r.release_step < 0 && p.release_step() >= 0) {
            r.release_step = p.release_step();
            r.force_at_release = p.contact_force();
            r.force_before_release = previous_force;
            r.height_at_release = p.height();
            r.string_at_release = s.displacement(centre);
        }
        previous_force = p.contact_force();
        if (s.dissipated() < previous_loss) r.losses_never_fall = false;
        previous_loss = s.dissipated();
    }
    for (double v : ledger) r.worst = std::max(r.worst, std::abs(v - ledger.front()) / scale);
    r.work = s.work();
    r.contact_loss = s.finger_loss();
    r.gone = s.plucks().front().stage() == Pluck::Stage::gone;
    r.contact_steps = s.statistics().contact_steps;
    r.played_steps = s.statistics().played_steps;
    return r;
}

TEST(Pluck, APopLetsGoAtItsDisplacementAndTheLosslessBalanceIsExact) {
    // Popped 2 mm away from the neck at 0.5 m/s from t = 1 ms, released, then slapping into
    // the frets: 1e5 steps at 400 kHz.
    Case c = testing::small_bass(400000.0, 0.25, 0.0);
    c.make_lossless();
    PluckSpec p = plucker(0.637, -1.0, 0.5);
    p.start_s = 1e-3;
    p.release_displacement_m = 2e-3;
    c.plucks.push_back(p);
    const PluckRun r = play(c, 100000);
    // The plucker appears at step 400, level with the string at rest, and moves v dt a step:
    // it reaches 2 mm after 1600 steps (one either way for the round-off of the sum).
    EXPECT_NEAR(static_cast<double>(r.release_step), 400.0 + 1600.0, 1.0);
    EXPECT_GE(r.height_at_release, p.release_displacement_m);
    EXPECT_LT(r.height_at_release - 0.5 * 2.5e-6, p.release_displacement_m);
    // The string followed it, short of it by the contact's compression F / K (within 5 %).
    EXPECT_NEAR(r.string_at_release, r.height_at_release - r.force_at_release / p.stiffness,
                0.05 * r.height_at_release);
    EXPECT_TRUE(r.gone);
    EXPECT_GT(r.work, 0.0);
    EXPECT_NEAR(static_cast<double>(r.played_steps), 1600.0, 3.0);  // touching from its first step to its release
    EXPECT_GT(r.contact_steps, 100);                                  // and the frets after it let go
    EXPECT_LT(r.worst, 1e-10);
}

TEST(Pluck, APluckDownLetsGoAtItsForceAndTheBalanceWithLossesIsExact) {
    // Pushed toward the frets with a lossy plectrum until 1.5 N, with the string's damping.
    Case c = testing::small_bass(400000.0, 0.25, 0.0);
    PluckSpec p = plucker(0.7, 1.0, 1.0);
    p.loss = 5.0;
    p.gap_m = 1e-4;
    p.release_force_n = 1.5;
    p.stiffness = 2e5;
    p.exponent = 1.5;
    c.plucks.push_back(p);
    const PluckRun r = play(c, 100000);
    ASSERT_GE(r.release_step, 0);
    EXPECT_GE(r.force_at_release, p.release_force_n);
    EXPECT_LT(r.force_before_release, p.release_force_n);
    EXPECT_TRUE(r.losses_never_fall);
    EXPECT_GT(r.contact_loss, 0.0);
    EXPECT_TRUE(r.gone);
    EXPECT_GT(r.work, 0.0);
    EXPECT_LT(r.worst, 1e-10);
}

TEST(Pluck, ASlowPullHoldsTheStringAtTheTautStringsStaticForce) {
    // Pulled up slowly to 1 mm with every mode damped: at the release the plucker's force
    // is the static F = T u L / (x0 (L - x0)) for the string's height u under the pad
    // (bending and the 8 mm pad change it by far less than the tolerance).
    Case c = testing::small_bass(100000.0, 0.2, 0.0);
    for (double& sigma : c.modes.sigma_per_s) sigma = std::max(sigma, 40.0);
    PluckSpec p = plucker(0.5, -1.0, 0.01);
    p.release_displacement_m = 1e-3;
    c.plucks.push_back(p);
    const PluckRun r = play(c, 15000);
    ASSERT_GE(r.release_step, 0);
    const double L = c.string.length_m, x0 = p.position_m;
    const double expected = c.string.tension_n * r.string_at_release * L / (x0 * (L - x0));
    EXPECT_NEAR(r.force_at_release, expected, 0.03 * expected);
}

TEST(Pluck, ScreenedAndStraightforwardPathsAgree) {
    // A pop released into the frets, the plucker gone after a few steps: before, during and
    // after its contact.
    Case c = testing::small_bass(400000.0, 0.05, 0.0);
    PluckSpec p = plucker(0.637, -1.0, 2.0);
    p.release_displacement_m = 2e-3;
    p.loss = 2.0;
    c.plucks.push_back(p);
    const testing::PathComparison r = testing::compare_paths(c, 20000);
    EXPECT_GT(r.contact_steps, 0);
    EXPECT_LT(r.relative_l2, 1e-9);
}

// A plucker on the grid points of its pad beside a flat barrier (pressing the string onto it),
// screening on: when the plucker leaves, its pad's points join that step's obstacle solve,
// with that step's predicted heights (they once kept their last heights as the plucker's: the
// balance jumped by 5e-4 of the energy at the release).
TEST(Pluck, APluckerLeavingABarrierHandsItsPointsOverWithinTheBalance) {
    const std::string text = R"(name = "pluck-barrier"
[string]
L = 1.0
T = 10000.0
mu = 1.0
modes = 200
ideal = true
[obstacle]
type = "flat"
height = -0.3e-3
[excitation]
type = "sine"
mode = 1
amplitude = 0.0
[contact]
K = 1e9
alpha = 1.5
[run]
fs = 200000.0
duration = 0.05
lossless = true
[observe]
x = [0.7]
[[gesture]]
type = "pluck"
position = 0.2013
direction = "down"
speed = 0.5
stiffness = 1e6
release_displacement = 1e-3
)";
    const Case c = parse_case(text, "pluck-barrier.toml", DataSource::builtin());
    const PluckRun r = play(c, 2000);
    EXPECT_TRUE(r.gone);
    EXPECT_GT(r.contact_steps, 0);
    EXPECT_LT(r.worst, 1e-12);
}

// The fretted pop of the built-in cases, small: a finger presses the string onto fret 5,
// then a pop pulls it up 2 mm at 0.637 m and lets go; with damping and the finger's loss.
Case small_fretted_pop(double duration) {
    Case c = testing::small_bass(400000.0, duration, 0.0);
    c.add_fret_finger(5, "fret");
    PluckSpec p = plucker(0.637, -1.0, 0.5);
    p.width_m = 0.01;
    p.start_s = 0.01;
    p.release_displacement_m = 2e-3;
    c.plucks.push_back(p);
    return c;
}

TEST(Pluck, AFrettedPopKeepsTheBalanceWithTheFingerPressing) {
    const PluckRun r = play(small_fretted_pop(0.25), 100000);
    EXPECT_GE(r.release_step, 0);
    EXPECT_TRUE(r.gone);
    EXPECT_TRUE(r.losses_never_fall);
    EXPECT_LT(r.worst, 1e-10);
}

TEST(Pluck, AFrettedPopIsTheSameOnTheScreenedAndStraightforwardPaths) {
    // Through the finger's landing, the pull, the release (step 5626) and the plucker's
    // departure. Not much further: once the popped string slaps the frets with the finger
    // down, the motion is chaotic, and two straightforward runs 1e-18 m apart in mode 1
    // differ by 1e-8 at step 8000 and 1e-3 at step 20000: round-off, not the paths.
    const testing::PathComparison r = testing::compare_paths(small_fretted_pop(0.05), 6500);
    EXPECT_GT(r.contact_steps, 0);
    EXPECT_LT(r.relative_l2, 1e-9);
}

// An ideal string (L = mu = 1, T = 1e4: c = 100 m/s) at rest, plucked up at x0 = 0.2013 (off
// every grid point of 200, 400 and 800 modes) by an 8 mm pad moving at 0.5 m/s, stiffness 1e6,
// let go at 1 mm, at 200 kHz. on_grid: adds a flat barrier 5 cm below the string (never
// touched), on the grid.
const std::string kFarBarrier = "type = \"flat\"\nheight = -0.05";

Case ideal_pluck(std::size_t modes, bool on_grid = false) {
    const std::string obstacle = on_grid ? kFarBarrier : "type = \"none\"";
    Case c = testing::ideal_string(modes, 1e4, obstacle, 2e5);
    PluckSpec p = plucker(0.2013, -1.0, 0.5);
    p.release_displacement_m = 1e-3;
    p.stiffness = 1e6;
    c.plucks.push_back(p);
    return c;
}

// u(0.7) over 20 ms (the pull, the release at 2 ms, the string's free motion after it) at 200 and
// 400 modes against 800: at its exact position the plucker's response converges with the mode
// count (on a grid pad, whose set of points jumps with the grid, it stalled at about 2e-3).
TEST(Pluck, AnExactPluckConvergesWithTheModeCount) {
    const auto run = [](std::size_t modes) { return testing::observed(ideal_pluck(modes), 0.7, 4000); };
    const std::vector<double> u800 = run(800);
    const double coarse = testing::relative_l2(run(200), u800), fine = testing::relative_l2(run(400), u800);
    std::printf("relative L2 of u(0.7) against 800 modes: exact 200 modes %.3g, 400 modes %.3g\n", coarse, fine);
    EXPECT_LT(fine, 0.25 * coarse);
    EXPECT_LT(coarse, 2e-4);
}

// Beside a flat barrier 5 cm below (never touched) the plucker still acts at its exact position
// and width: its run is the plucker's alone, at every mode count (the barrier's grid points are
// solved with the pad every step, apart).
TEST(Pluck, APluckBesideAFarBarrierIsThePluckerAlone) {
    for (const std::size_t modes : {200u, 400u, 800u}) {
        const std::vector<double> alone = testing::observed(ideal_pluck(modes), 0.7, 4000);
        const std::vector<double> beside = testing::observed(ideal_pluck(modes, true), 0.7, 4000);
        const double l2 = testing::relative_l2(beside, alone);
        std::printf("%zu modes: u(0.7) beside the far barrier against the plucker alone: relative L2 %.3g\n", modes, l2);
        EXPECT_LT(l2, 1e-12);
    }
}

// The string plucked 1 mm as a triangle at 0.25 and let go at t = 0; the plucker appears 0.3 mm
// under it at t = dt and rises at 0.5 m/s. By d'Alembert (c = 100 m/s) the pad's mean height
// stays at 0.8052 mm until the kink has crossed the pad (0.527 ms), then falls at 0.2667 m/s: the
// plucker meets it at t* = 0.56396 ms. At its exact position the first contact is the same step
// at 200, 400 and 800 modes, the one that t* falls in, with or without a flat barrier on the grid
// 5 cm below (on a grid pad, centred on the nearest grid point, it moved with the mode count).
TEST(Pluck, AnExactPluckFirstTouchesAtTheSameStepWhateverTheModeCount) {
    const auto first = [](std::size_t modes, bool grid) {
        const std::string obstacle = grid ? kFarBarrier : "type = \"none\"";
        Case c = testing::ideal_string(modes, 1e4, obstacle, 2e5, "type = \"triangle\"\nposition = 0.25\namplitude = 1e-3");
        PluckSpec p = plucker(0.2013, -1.0, 0.5);
        p.gap_m = 3e-4;
        p.release_displacement_m = 2e-3;
        p.stiffness = 1e6;
        c.plucks.push_back(p);
        return play(c, 200).first_contact_step;
    };
    const double dt = 1.0 / 2e5, x0 = 0.2013, c = 100.0, kink = (0.25 - x0) / c;
    const double fall = 0.5 * c * (1e-3 / 0.25 + 1e-3 / 0.75);
    const double t_star = (3e-4 + 0.5 * dt + fall * kink) / (0.5 + fall);
    const long expected = static_cast<long>(std::ceil(t_star / dt));
    const long e200 = first(200, false), e400 = first(400, false), e800 = first(800, false);
    const long b200 = first(200, true), b400 = first(400, true), b800 = first(800, true);
    std::printf("first contact step at 200/400/800 modes: alone %ld %ld %ld; beside the barrier %ld %ld %ld; d'Alembert t* = %.5f ms (step %ld)\n",
                e200, e400, e800, b200, b400, b800, 1e3 * t_star, expected);
    for (long e : {e200, e400, e800, b200, b400, b800}) EXPECT_EQ(e, expected);
}

// The exact plucker's work, contact energy and Hunt-Crossley loss in the discrete balance:
// lossless, and with its loss and the string's damping, H - work + dissipated is constant to
// round-off through the pull, the release and the withdrawal.
TEST(Pluck, AnExactPluckKeepsTheBalanceToRoundOff) {
    for (const bool lossy : {false, true}) {
        Case c = ideal_pluck(200);
        if (lossy) {
            c.plucks.front().loss = 5.0;
            c.plucks.front().exponent = 1.5;
            c.plucks.front().stiffness = 1e8;
            for (double& sigma : c.modes.sigma_per_s) sigma = 3.0;
        }
        const PluckRun r = play(c, 20000);
        std::printf("%s: balance %.2e, work %.3g J, loss %.3g J\n", lossy ? "lossy" : "lossless", r.worst, r.work,
                    r.contact_loss);
        EXPECT_TRUE(r.gone);
        EXPECT_GT(r.work, 0.0);
        EXPECT_LT(r.worst, 1e-12);
        if (lossy) {
            EXPECT_GT(r.contact_loss, 0.0);
            EXPECT_TRUE(r.losses_never_fall);
        }
    }
}

// Pushed down onto two exact point obstacles off the grid (0.3 mm below the string, 4.5 mm
// apart, 3 and 7 cm from the pad): the plucker and the points in contact at the same step move
// one another through the modes and are solved as one system. Lossless, the balance is
// round-off.
// The ideal string pushed down 1 mm at 0.2013 m onto `obstacle` (K = 1e9), lossless.
Case pressed_down_onto(const std::string& obstacle) {
    Case c = testing::ideal_string(200, 1e4, obstacle, 2e5);
    c.contact.stiffness = 1e9;
    PluckSpec p = plucker(0.2013, 1.0, 0.5);
    p.release_displacement_m = 1e-3;
    p.stiffness = 1e6;
    c.plucks.push_back(p);
    return c;
}

TEST(Pluck, AnExactPluckPressingOntoExactPointsKeepsTheBalance) {
    const PluckRun r = play(pressed_down_onto("type = \"points\"\nx = [0.23, 0.2345]\nheight = -0.3e-3"), 10000);
    std::printf("plucker onto exact points: balance %.2e, work %.3g J, %ld steps on the points, %ld played\n", r.worst,
                r.work, r.contact_steps, r.played_steps);
    EXPECT_GT(r.contact_steps, 100);
    EXPECT_GT(r.played_steps, 100);
    EXPECT_TRUE(r.gone);
    EXPECT_LT(r.worst, 1e-12);
}

// Pushed down onto a flat barrier on the grid 0.3 mm below the string (every grid point an
// obstacle point): the pad at its exact position and the barrier's points in contact at the
// same step move one another through the modes and are solved as one system (the pad's
// unknown, the grid's equations inside it). Lossless, the balance is round-off; screened, the
// run is the straightforward one.
Case pressed_onto_a_barrier() { return pressed_down_onto("type = \"flat\"\nheight = -0.3e-3"); }

TEST(Pluck, AnExactPluckPressingOntoABarrierOnTheGridKeepsTheBalance) {
    const Case c = pressed_onto_a_barrier();
    const PluckRun r = play(c, 10000);
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    const Stepper s(plan, c.initial_displacement, c.initial_velocity);
    std::printf("plucker onto a flat barrier: balance %.2e, work %.3g J, %ld steps on the barrier, %ld played\n", r.worst,
                r.work, r.contact_steps, r.played_steps);
    EXPECT_TRUE(s.plucks().front().exact());
    EXPECT_GT(r.contact_steps, 100);
    EXPECT_GT(r.played_steps, 100);
    EXPECT_TRUE(r.gone);
    EXPECT_LT(r.worst, 1e-12);
}

TEST(Pluck, AnExactPluckOntoABarrierIsTheSameOnTheScreenedPath) {
    const testing::PathComparison p = testing::compare_paths(pressed_onto_a_barrier(), 10000);
    std::printf("screened vs straightforward, plucker onto a flat barrier: relative L2 %.3g, %ld joint steps, points solved per step %.2f vs %.2f\n",
                p.relative_l2, p.fast.joint_steps, p.fast.points_solved / 10000.0, p.plain.points_solved / 10000.0);
    EXPECT_GT(p.fast.joint_steps, 100);
    EXPECT_LT(p.fast.points_solved, p.plain.points_solved);
    EXPECT_LT(p.relative_l2, 1e-9);
}

// Two pluckers pressing the string onto two exact points off the grid: pads and points move one
// another through the modes and are solved as one system (each pad one more unknown). Lossless,
// the balance is round-off; screened, the run is the straightforward one.
Case two_pressing_onto_points() {
    Case c = testing::ideal_string(200, 1e4, "type = \"points\"\nx = [0.23, 0.2345]\nheight = -0.3e-3", 2e5);
    c.contact.stiffness = 1e9;
    for (const double x : {0.2013, 0.2513}) {
        PluckSpec p = plucker(x, 1.0, 0.5);
        p.release_displacement_m = 1e-3;
        p.stiffness = 1e6;
        c.plucks.push_back(p);
    }
    return c;
}

TEST(Pluck, TwoPluckersPressingOntoPointsKeepTheBalance) {
    const Case c = two_pressing_onto_points();
    const PluckRun r = play(c, 10000);
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    const Stepper s(plan, c.initial_displacement, c.initial_velocity);
    std::printf("two pluckers onto points: balance %.2e, %ld steps on the points, %ld played\n", r.worst, r.contact_steps,
                r.played_steps);
    EXPECT_TRUE(s.plucks()[0].exact());
    EXPECT_TRUE(s.plucks()[1].exact());
    EXPECT_EQ(plan.point_contact().size(), 2u);  // the points stay exact beside them
    EXPECT_GT(r.contact_steps, 100);
    EXPECT_GT(r.played_steps, 100);
    EXPECT_LT(r.worst, 1e-12);
}

// Two pluckers pressing onto a flat barrier on the grid: screened (barrier points away from the
// string asleep) against every point solved every step.
TEST(Pluck, TwoPluckersOntoABarrierAreTheSameOnTheScreenedPath) {
    Case c = pressed_onto_a_barrier();
    PluckSpec second = c.plucks.front();
    second.position_m = 0.2513;
    c.plucks.push_back(second);
    const testing::PathComparison p = testing::compare_paths(c, 10000);
    std::printf("screened vs straightforward, two pluckers onto a flat barrier: relative L2 %.3g, %ld joint steps, points solved per step %.2f vs %.2f\n",
                p.relative_l2, p.fast.joint_steps, p.fast.points_solved / 10000.0, p.plain.points_solved / 10000.0);
    EXPECT_GT(p.fast.joint_steps, 100);
    EXPECT_LT(p.fast.points_solved, p.plain.points_solved);
    EXPECT_LT(p.relative_l2, 1e-9);
}

// Two pluckers pulling the string up at the same time, 5 cm apart (lossless, then with their
// Hunt-Crossley loss and the string's damping): their pads move one another within every step
// and are solved together. H - work + dissipated is constant to round-off.
TEST(Pluck, TwoPluckersPullingTogetherKeepTheBalance) {
    for (const bool lossy : {false, true}) {
        Case c = ideal_pluck(200);
        PluckSpec second = c.plucks.front();
        second.position_m = 0.2513;
        second.release_displacement_m = 1.5e-3;
        c.plucks.push_back(second);
        if (lossy) {
            for (PluckSpec& p : c.plucks) p.loss = 5.0;
            for (double& sigma : c.modes.sigma_per_s) sigma = 3.0;
        }
        const Plan plan(c, 1.0 / c.run.sample_rate_hz);
        Stepper s(plan, c.initial_displacement, c.initial_velocity);
        double first = 0.0, scale = 0.0, worst = 0.0;
        long both = 0;
        for (long n = 1; n <= 20000; ++n) {
            s.step();
            const double value = s.energy() - s.work() + s.dissipated();
            if (n == 1) first = value;
            scale = std::max({scale, std::abs(s.energy()), std::abs(s.work())});
            worst = std::max(worst, std::abs(value - first));
            const auto pushing = [&](std::size_t j) {  // (contact_force() keeps its last value once gone)
                return s.plucks()[j].stage() != Pluck::Stage::gone && s.plucks()[j].contact_force() != 0.0;
            };
            if (pushing(0) && pushing(1)) ++both;
        }
        std::printf("two pluckers pulling together (%s): %ld steps both pushing, balance %.2e\n", lossy ? "lossy" : "lossless",
                    both, worst / scale);
        EXPECT_TRUE(s.plucks()[0].exact() && s.plucks()[1].exact());
        EXPECT_EQ(s.plucks()[0].stage(), Pluck::Stage::gone);
        EXPECT_EQ(s.plucks()[1].stage(), Pluck::Stage::gone);
        EXPECT_GT(both, 100);
        EXPECT_LT(worst / scale, 1e-12);
    }
}

// A second plucker that appears 5 cm from the string and never reaches it (it would take 0.1 s)
// leaves the first as it is alone, at every mode count: both act at their exact positions.
// (On their grid pads, beside another plucker, the run moved with the grid by about 1e-3.)
TEST(Pluck, AFarSecondPluckerLeavesTheFirstAsItIsAlone) {
    for (const std::size_t modes : {200u, 400u, 800u}) {
        const Case alone = ideal_pluck(modes);
        Case beside = alone;
        PluckSpec far = alone.plucks.front();
        far.position_m = 0.6;
        far.gap_m = 0.05;
        beside.plucks.push_back(far);
        const double l2 = testing::relative_l2(testing::observed(beside, 0.7, 4000), testing::observed(alone, 0.7, 4000));
        std::printf("%zu modes: u(0.7) beside a far second plucker against the first alone: relative L2 %.3g\n", modes, l2);
        EXPECT_LT(l2, 1e-12);
    }
}

// Nine pluckers onto the two points (more than the eight the joint solve once took at their
// exact positions, beyond which every plucker went onto its grid pad and the points onto the
// grid): every plucker and both points stay exact, and the balance stays round-off.
TEST(Pluck, NinePluckersOntoPointsStayExact) {
    Case c = two_pressing_onto_points();
    while (c.plucks.size() < 9) {
        PluckSpec p = c.plucks.back();
        p.position_m += 0.05;
        c.plucks.push_back(p);
    }
    const PluckRun r = play(c, 10000);
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    const Stepper s(plan, c.initial_displacement, c.initial_velocity);
    std::printf("%zu pluckers onto points: balance %.2e, %ld steps on the points\n", c.plucks.size(), r.worst, r.contact_steps);
    for (const Pluck& p : s.plucks()) EXPECT_TRUE(p.exact());
    EXPECT_EQ(plan.point_contact().size(), 2u);  // the points stay exact beside them
    EXPECT_GT(r.contact_steps, 100);
    EXPECT_LT(r.worst, 1e-12);
}

// Screening and free flight once the exact plucker has gone, against every mode stepped at every
// step.
TEST(Pluck, AnExactPluckIsTheSameOnTheFastAndStraightforwardPaths) {
    Case c = ideal_pluck(200);
    c.run.duration_s = 0.05;
    c.run.output_rate_hz = 50000.0;
    const RecordedRun fast = testing::record_run(c, true), plain = testing::record_run(c, false);
    ASSERT_EQ(fast.observation.size(), plain.observation.size());
    const double l2 = testing::relative_l2(fast.observation, plain.observation);
    std::printf("fast vs straightforward path, exact plucker: relative L2 %.3g (free flight %.0f %%)\n", l2,
                100.0 * fast.summary.free_flight_fraction);
    EXPECT_GT(fast.summary.free_flight_fraction, 0.5);
    EXPECT_LT(l2, 1e-12);
}

// `count` pops 12 mm apart from 0.04 m on.
std::string many_pops(int count) {
    std::string text;
    for (int k = 0; k < count; ++k)
        text += "\n[[gesture]]\ntype = \"pop\"\nwidth = 0.004\nrelease_force = 2\nposition = " +
                std::to_string(0.04 + 0.012 * k) + "\n";
    return text;
}

// Every plucker is an unknown of the joint solve, planned for all of them: their number is
// bounded (each keeps two vectors of the mode count), and a case beyond is refused naming it.
TEST(Pluck, PluckersBeyondTheLimitAreRefusedNamingIt) {
    testing::expect_refused("many-pluckers", testing::small_bass_text(),
                            {{many_pops(2), ""}, {many_pops(65), "at most 64 are allowed"}});
}

TEST(Pluck, BadPluckInputIsRefusedNamingTheKey) {
    const std::string pop = "\n[[gesture]]\ntype = \"pop\"\nposition = 0.6\n";
    const std::string pluck = "\n[[gesture]]\ntype = \"pluck\"\nposition = 0.6\n";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {pop + "release_displacement = 0.002\n", ""},  // good
        {pluck + "direction = \"down\"\nrelease_force = 2\nduration = 0.005\n", "gesture[0].duration"},
        {pluck + "release_force = 2\n", "gesture[0].direction"},
        {pop + "direction = \"down\"\nrelease_force = 2\n", "gesture[0].direction"},
        {pop + "speed = 0.5\n", "release_displacement"},
        {pop + "release_force = 2\nspeed = -1\n", "gesture[0].speed"},
        {pop + "release_force = 2\nspeed = 1000\n", "gesture[0].speed"},
        {pop + "release_force = -2\n", "gesture[0].release_force"},
        {pop + "release_displacement = 0.2\n", "gesture[0].release_displacement"},
        {pop + "release_force = 2\ntime = 0.02\n", "gesture[0].time"},
        {pop + "release_force = 2\ngap = -0.001\n", "gesture[0].gap"},
        {pop + "release_force = 2\nwidth = 0\n", "gesture[0].width"},
        {pop + "release_force = 2\nstiffness = -1\n", "gesture[0].stiffness"},
        {pop + "release_force = 2\nexponent = 5\n", "gesture[0].exponent"},
        {pop + "release_force = 2\nloss = -1\n", "gesture[0].loss"},
        {pop + "release_force = 2\nwithdraw_speed = 0\n", "gesture[0].withdraw_speed"},
        {pop + "release_displacement = 0.002\nduration = 0.01\nspeed = 1\n", "gesture[0].duration"},
        {pop + "release_displacement = 0.002\nduration = 0\n", "gesture[0].duration"},
        {pop + "release_force = 2\ncolour = 1\n", "colour"},
        {"\n[[gesture]]\ntype = \"pop\"\nposition = 0.858\nwidth = 0.02\nrelease_force = 2\n", "overlaps an end"},
        {pop + "release_force = 2\n\n[[finger]]\nposition = 0.6\n", "gesture[0].position"},
    };
    testing::expect_refused("bad-pluck", testing::small_bass_text(), cases);
}

}  // namespace
}  // namespace fretbuzz
