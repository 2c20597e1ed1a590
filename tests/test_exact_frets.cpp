// A fretboard's crowns of zero width at their exact positions x_n = S (1 - 2^(-n/12)), the board
// between them on the grid: the first contact with a fret whatever the mode count, the energy
// balance to round-off with frets and board in contact in the same steps (solved together), the
// screened path against the straightforward one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "SmallBass.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

// bass-pluck (its neck from the fretboard generator) on `modes` modes, lossless, released from
// `amplitude` at 0.637 m.
Case fretted_bass(std::size_t modes, double amplitude, double fs, const std::string& fret_height = "1.2e-3",
                  bool lossless = true) {
    std::string text = builtin_case_text("bass-pluck");
    text.replace(text.find("height = 1.2e-3"), 15, "height = " + fret_height);
    text.replace(text.find("modes = 862"), 11, "modes = " + std::to_string(modes));
    text.replace(text.find("amplitude = 0.5e-3"), 18, "amplitude = " + std::to_string(amplitude));
    Case c = parse_case(text, "fretted-bass.toml", DataSource::builtin());
    if (lossless) c.make_lossless();
    c.run.sample_rate_hz = fs;
    return c;
}

// The same case with each crown on its nearest grid point (the obstacle as it was sampled).
Case crowns_on_grid(Case c) {
    c.obstacle_height_m = c.obstacle_on_grid();
    c.point_obstacles.clear();
    return c;
}

struct FretRun {
    double first_contact_s = -1.0;
    double worst_balance = 0.0;  // |H - H_0| / H_0
    long contact_steps = 0, joint_steps = 0;
};

FretRun run(const Case& c, long steps, PlanOptions options = {}) {
    const Plan plan(c, 1.0 / c.run.sample_rate_hz, options);
    Stepper s(plan, c.initial_displacement, c.initial_velocity);
    FretRun r;
    double h0 = 0.0;
    for (long n = 0; n < steps; ++n) {
        s.step();
        if (s.touched_obstacle() && r.first_contact_s < 0.0) r.first_contact_s = s.time();
        if (n == 1) h0 = s.energy();
        if (n > 1) r.worst_balance = std::max(r.worst_balance, std::abs(s.energy() - h0) / h0);
    }
    r.contact_steps = s.statistics().contact_steps;
    r.joint_steps = s.statistics().joint_steps;
    return r;
}

double fret_x(int n) { return 0.863 * (1.0 - std::exp2(-n / 12.0)); }

TEST(ExactFrets, CrownsOfZeroWidthAreExactPointsOneGridStepWide) {
    for (std::size_t modes : {110u, 400u}) {
        const Case c = fretted_bass(modes, 0.5e-3, 1e6);
        ASSERT_EQ(c.point_obstacles.size(), 20u);
        ASSERT_EQ(c.fret_positions_m.size(), 20u);
        for (int n = 1; n <= 20; ++n) {
            const PointObstacle& p = c.point_obstacles[static_cast<std::size_t>(n - 1)];
            EXPECT_NEAR(p.x_m, fret_x(n), 1e-15) << "fret " << n;
            EXPECT_EQ(c.fret_positions_m[static_cast<std::size_t>(n - 1)], p.x_m);
            EXPECT_DOUBLE_EQ(p.weight_m, c.grid_step());
        }
        // The grid point nearest a crown keeps the board's height (1.2 mm below the fret line).
        const std::size_t near12 = static_cast<std::size_t>(std::lround(fret_x(12) / c.grid_step())) - 1;
        EXPECT_LT(c.obstacle_height_m[near12], c.point_obstacles[11].height_m - 1e-3);
        // The plan solves them beside the board, screening on.
        const Plan plan(c, 1.0 / c.run.sample_rate_hz);
        EXPECT_EQ(plan.point_contact().size(), 20u);
        EXPECT_TRUE(plan.point_contact().grid_coupled());
        EXPECT_TRUE(choose_screening(c, {}, true).screen) << choose_screening(c, {}, true).reason;
    }
}

TEST(ExactFrets, CrownedFretsAreWhereTheFretboardPutsThem) {
    // Crowns 2 mm wide act on the grid points within them; the frets (what `fret = k` stands
    // behind) stay at x_n, not at the middle of those points.
    std::string text = builtin_case_text("bass-pluck");
    text.replace(text.find("crown_width = 0.0"), 17, "crown_width = 2e-3");
    const Case c = parse_case(text, "crowned-bass.toml", DataSource::builtin());
    EXPECT_TRUE(c.point_obstacles.empty());
    ASSERT_EQ(c.fret_positions_m.size(), 20u);
    for (int n = 1; n <= 20; ++n) EXPECT_NEAR(c.fret_positions_m[static_cast<std::size_t>(n - 1)], fret_x(n), 1e-15);
    const FingerSpec f = c.fret_finger(5, "fret");
    EXPECT_NEAR(f.position_m, finger_behind_fret(fret_x(5), fret_x(5) - fret_x(4)).position_m, 1e-15);
}

TEST(ExactFrets, FirstFretContactIndependentOfTheModeCount) {
    // Released from 3 mm at 0.637 m, the string first meets a fret (the board lies 1.2 mm lower)
    // at the time its free motion crosses the crown's height at x_n: with the crowns at x_n, 110
    // and 400 modes agree to a step (1 us; measured: 4073 and 4072 us), where crowns on their
    // nearest grid points moved the contact by 33 us (4079 and 4046 us).
    const double fs = 1e6;
    const FretRun exact_110 = run(fretted_bass(110, 3e-3, fs), 6000);
    const FretRun exact_400 = run(fretted_bass(400, 3e-3, fs), 6000);
    const FretRun grid_110 = run(crowns_on_grid(fretted_bass(110, 3e-3, fs)), 6000);
    const FretRun grid_400 = run(crowns_on_grid(fretted_bass(400, 3e-3, fs)), 6000);
    std::printf("first fret contact: %.0f us (110 modes), %.0f us (400); crowns on the grid: %.0f us, %.0f us\n",
                1e6 * exact_110.first_contact_s, 1e6 * exact_400.first_contact_s, 1e6 * grid_110.first_contact_s,
                1e6 * grid_400.first_contact_s);
    ASSERT_GT(exact_110.first_contact_s, 0.0);
    ASSERT_GT(exact_400.first_contact_s, 0.0);
    EXPECT_LE(std::abs(exact_110.first_contact_s - exact_400.first_contact_s), 2.5 / fs);
    // (what the crowns on the grid gave: the check can tell)
    EXPECT_GT(std::abs(grid_110.first_contact_s - grid_400.first_contact_s), 10.0 / fs);
}

TEST(ExactFrets, EnergyBalanceToRoundOffWithFretsAndBoardInContactTogether) {
    // Frets 0.02 mm high: the string lands on crowns and board in the same steps, solved as one
    // system (the grid's equations inside the points' Newton solve).
    const Case c = fretted_bass(110, 6e-3, 1e6, "0.02e-3");
    const FretRun r = run(c, 30000);
    std::printf("crowns and board together: %ld joint steps of %ld in contact, balance %.2g\n", r.joint_steps,
                r.contact_steps, r.worst_balance);
    EXPECT_GT(r.joint_steps, 20);
    EXPECT_GT(r.contact_steps, 200);
    EXPECT_LT(r.worst_balance, 1e-12);  // measured 3e-14
}

TEST(ExactFrets, ScreenedPathEqualsTheStraightforwardOne) {
    // Screening puts crowns apart from the string to sleep as it does grid points; both paths
    // solve the same equations, rounding differently: they agree to round-off amplified by the
    // contacts.
    const Case c = fretted_bass(110, 6e-3, 1e6, "0.1e-3");
    const testing::PathComparison p = testing::compare_paths(c, 30000);
    EXPECT_GT(p.fast.joint_steps, 0);
    EXPECT_GT(p.contact_steps, 200);
    // far fewer points solved per step: the crowns sleep while the string is away
    EXPECT_LT(p.fast.points_solved, 0.5 * p.plain.points_solved);
    std::printf("screened vs straightforward, crowns and board: relative L2 %.3g, points solved per step %.2f vs %.2f\n",
                p.relative_l2, p.fast.points_solved / 30000.0, p.plain.points_solved / 30000.0);
    EXPECT_LT(p.relative_l2, 1e-9);
}

// The string at rest pressed down by a plucker at its exact position (its pad off the grid,
// 0.531 m, between frets 16 and 17) onto frets 0.02 mm high: pad, crowns and board in contact
// in the same steps, solved as one system (the pad's unknown beside the crowns' and the
// board's equations inside them). Lossless, H - work is constant to round-off.
// (played_run below: a run with pluckers or fingers, its ledger and counts.)
struct PlayedRun {
    double worst = 0.0;  // max |H - W + D - (H - W + D)_1| / max(|H|, |W|)
    long joint_steps = 0, contact_steps = 0, played_steps = 0;
    long pressed_joint = 0;  // joint steps with the (first) plucker pushing
    bool exact = false, gone = false;  // the first plucker's
    std::size_t exact_points = 0;
    double finger_force = 0.0;  // on the first finger at the end, N
};

// H - W + D against its value after the first step, relative to the largest |H| or |W| so far.
class Ledger {
public:
    void add(const Stepper& s) {
        const double value = s.energy() - s.work() + s.dissipated();
        if (!started_) first_ = value;
        started_ = true;
        scale_ = std::max({scale_, std::abs(s.energy()), std::abs(s.work())});
        drift_ = std::max(drift_, std::abs(value - first_));
    }
    double worst() const { return drift_ / scale_; }

private:
    bool started_ = false;
    double first_ = 0.0, scale_ = 0.0, drift_ = 0.0;
};

PlayedRun played_run(const Case& c, long steps) {
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    Stepper s(plan, c.initial_displacement, c.initial_velocity);
    PlayedRun r;
    Ledger ledger;
    const bool plucked = !s.plucks().empty();
    for (long n = 1; n <= steps; ++n) {
        const long joint_before = s.statistics().joint_steps;
        s.step();
        if (plucked && s.statistics().joint_steps > joint_before && s.plucks().front().contact_force() != 0.0)
            ++r.pressed_joint;
        ledger.add(s);
    }
    r.worst = ledger.worst();
    r.joint_steps = s.statistics().joint_steps;
    r.contact_steps = s.statistics().contact_steps;
    r.played_steps = s.statistics().played_steps;
    r.exact_points = plan.point_contact().size();
    if (plucked) {
        r.exact = s.plucks().front().exact();
        r.gone = s.plucks().front().stage() == Pluck::Stage::gone;
    }
    if (!s.fingers().empty()) r.finger_force = s.fingers().front().contact_force();
    return r;
}

Case pressed_onto_the_frets(std::size_t modes) {
    Case c = fretted_bass(modes, 0.5e-3, 1e6, "0.02e-3");
    std::fill(c.initial_displacement.begin(), c.initial_displacement.end(), 0.0);
    std::fill(c.initial_velocity.begin(), c.initial_velocity.end(), 0.0);
    PluckSpec p;
    p.position_m = 0.5313;
    p.direction = 1.0;  // toward the fretboard
    p.speed = 1.0;
    p.stiffness = 1e6;
    p.release_displacement_m = 4e-3;  // below the board: it presses until the board's force holds it
    p.release_force_n = 200.0;
    c.plucks.push_back(p);
    return c;
}

TEST(ExactFrets, APluckerPressingOntoCrownsAndBoardKeepsTheBalance) {
    const PlayedRun r = played_run(pressed_onto_the_frets(110), 20000);
    std::printf("plucker onto crowns and board: %ld joint steps (%ld with the plucker pushing), %ld in contact, %ld played, balance %.2g\n",
                r.joint_steps, r.pressed_joint, r.contact_steps, r.played_steps, r.worst);
    EXPECT_TRUE(r.exact);
    EXPECT_TRUE(r.gone);
    EXPECT_GT(r.pressed_joint, 100);
    EXPECT_LT(r.worst, 1e-12);
}

// Nine pluckers beside the fretboard: the one pressing onto crowns and board, and eight that
// never reach the string (5 cm away). Past eight, the joint solve once put every plucker on its
// grid pad and every crown back on its nearest grid point; its room is now planned for them all:
// the crowns stay at their exact positions, and the eight leave the first one's run as it is
// alone, to the joint solve's tolerance (1e-9 of its unknowns; their pads enter its Newton
// system and move its pivots and stopping point, as screening does: see the next test).
TEST(ExactFrets, NinePluckersBesideTheFretsKeepTheCrownsExact) {
    const Case alone = pressed_onto_the_frets(110);
    Case nine = alone;
    for (const double x : {0.05, 0.09, 0.13, 0.17, 0.66, 0.70, 0.74, 0.78}) {
        PluckSpec far = alone.plucks.front();
        far.position_m = x;
        far.gap_m = 0.05;
        nine.plucks.push_back(far);
    }
    constexpr long kSteps = 20000;
    const PlayedRun one = played_run(alone, kSteps), r = played_run(nine, kSteps);
    const double l2 = testing::relative_l2(testing::observed(nine, 0.7, kSteps), testing::observed(alone, 0.7, kSteps));
    std::printf("nine pluckers beside the frets: %zu exact crowns (%zu alone), %ld joint steps, balance %.2g; "
                "u(0.7) against the first plucker alone: relative L2 %.3g\n",
                r.exact_points, one.exact_points, r.joint_steps, r.worst, l2);
    EXPECT_EQ(r.exact_points, alone.point_obstacles.size());  // every crown at its exact position
    EXPECT_EQ(r.exact_points, one.exact_points);
    EXPECT_TRUE(r.exact);
    EXPECT_GT(r.pressed_joint, 100);
    EXPECT_LT(r.worst, 1e-12);
    EXPECT_LT(l2, 1e-9);
}

// The same press screened and straightforward: the same equations, rounded differently.
TEST(ExactFrets, APluckerPressingOntoTheFretsIsTheSameOnTheScreenedPath) {
    const testing::PathComparison p = testing::compare_paths(pressed_onto_the_frets(110), 20000);
    std::printf("screened vs straightforward, plucker onto crowns and board: relative L2 %.3g, points solved per step %.2f vs %.2f\n",
                p.relative_l2, p.fast.points_solved / 20000.0, p.plain.points_solved / 20000.0);
    EXPECT_GT(p.fast.joint_steps, 100);
    EXPECT_LT(p.fast.points_solved, p.plain.points_solved);
    EXPECT_LT(p.relative_l2, 1e-9);
}

// A finger stops the string at fret 5 while it rings from the pluck: its pad (grid points)
// presses the string onto crown 5 (exact), and the string beats on the crowns and board beyond.
// Crowns, pad and board are solved as one system (the finger's step inside the crowns' Newton
// solve): H - work + dissipated is constant to round-off, lossless or not.
Case stopped_at_fret_5(bool lossless, const std::string& fret_height = "1.2e-3") {
    Case c = fretted_bass(110, 1e-3, 1e6, fret_height, lossless);
    c.add_fret_finger(5, "fret");
    if (lossless) c.fingers.back().loss = 0.0;
    return c;
}

TEST(ExactFrets, AFingerPressingOntoExactCrownsKeepsTheBalance) {
    for (const bool lossless : {true, false}) {
        const PlayedRun r = played_run(stopped_at_fret_5(lossless), 30000);
        std::printf("finger onto exact crowns (%s): %ld joint steps of %ld in contact, %.2f N on the finger, balance %.2g\n",
                    lossless ? "lossless" : "with losses", r.joint_steps, r.contact_steps, r.finger_force, r.worst);
        EXPECT_EQ(r.exact_points, 20u);  // the crowns stay exact points beside the finger
        EXPECT_GT(r.joint_steps, 3000);
        EXPECT_GT(r.finger_force, 1.0);
        // Measured 3.0e-12 lossless, as with the crowns on the grid (3.5e-12): a few jumps of
        // up to 9e-13 where the lossless finger bounces off the string, its stiff pad's own
        // round-off. With losses (the finger stays down) 8.9e-14 (on the grid 2.8e-14).
        EXPECT_LT(r.worst, lossless ? 1e-11 : 3e-13);
    }
}

// The same stopped string screened and straightforward (crowns away from the string asleep on
// the screened path): the same equations, rounded differently. Through the finger's landing
// (from 4.5 ms) and the first 5 ms of the string beating on the crowns beyond it they agree to
// 8e-14 (the joint solve's round-off); later, as any two roundings of a string beating on
// frets, they part (first by 1e-12 after 11000 steps, 14000 with the crowns on the grid; the
// difference then grows by 1e4 every 2000 steps on either).
TEST(ExactFrets, AFingerOnExactCrownsIsTheSameOnTheScreenedPath) {
    constexpr long kSteps = 10000;
    const testing::PathComparison p = testing::compare_paths(stopped_at_fret_5(false), kSteps);
    std::printf("screened vs straightforward, finger onto exact crowns: relative L2 %.3g, points solved per step %.2f vs %.2f\n",
                p.relative_l2, p.fast.points_solved / static_cast<double>(kSteps), p.plain.points_solved / static_cast<double>(kSteps));
    EXPECT_GT(p.fast.joint_steps, 1000);
    EXPECT_LT(p.fast.points_solved, 0.1 * p.plain.points_solved);
    EXPECT_LT(p.relative_l2, 1e-11);
}

// A plucker at its exact position (0.5313 m, its pad off the grid) pulling the string up while a
// finger stops it at fret 5: plucker, finger, crowns and board in one solve (the plucker's pad
// and the finger's height as unknowns beside the crowns'). The finger lands while the plucker
// pulls; both act in the same steps.
Case plucked_at_fret_5(std::size_t modes, bool lossless) {
    Case c = fretted_bass(modes, 0.5e-3, 1e6, "1.2e-3", lossless);
    std::fill(c.initial_displacement.begin(), c.initial_displacement.end(), 0.0);
    std::fill(c.initial_velocity.begin(), c.initial_velocity.end(), 0.0);
    PluckSpec p;
    p.position_m = 0.5313;
    p.direction = -1.0;  // away from the fretboard
    p.speed = 1.0;
    p.stiffness = 1e6;
    p.release_displacement_m = 2e-3;
    c.plucks.push_back(p);
    return c;
}

// One plucker, or two (the second at 0.6013 m, also off the grid, let go at 1.5 mm), pulling
// beside the finger at fret 5: the pads, the finger's height, crowns and board in one solve.
// Lossless and with losses, H - work + dissipated is constant to round-off.
void expect_exact_pluckers_beside_the_finger(std::size_t pluckers) {
    for (const bool lossless : {true, false}) {
        Case c = plucked_at_fret_5(110, lossless);
        if (pluckers == 2) {
            PluckSpec second = c.plucks.front();
            second.position_m = 0.6013;
            second.release_displacement_m = 1.5e-3;
            c.plucks.push_back(second);
        }
        c.add_fret_finger(5, "fret");
        if (lossless) c.fingers.back().loss = 0.0;
        const PlayedRun r = played_run(c, 20000);
        std::printf("%zu plucker(s) beside a finger at fret 5 (%s): %ld joint steps (%ld with the first plucker pushing), balance %.2g\n",
                    pluckers, lossless ? "lossless" : "with losses", r.joint_steps, r.pressed_joint, r.worst);
        EXPECT_TRUE(r.exact);
        EXPECT_TRUE(r.gone);
        EXPECT_GT(r.pressed_joint, 100);
        EXPECT_LT(r.worst, lossless ? 1e-11 : 3e-13);
    }
}

TEST(ExactFrets, APluckerBesideAFingerIsExactAndKeepsTheBalance) { expect_exact_pluckers_beside_the_finger(1); }

TEST(ExactFrets, TwoPluckersBesideAFingerAreExactAndKeepTheBalance) { expect_exact_pluckers_beside_the_finger(2); }

// A finger held 20 mm above the string never touches it: beside it the plucker acts as it does
// alone, at any mode count. (With the plucker on its grid pad beside a finger, the pad's points
// moved with the grid: the runs parted by 1e-3.)
TEST(ExactFrets, AFingerThatNeverTouchesLeavesThePluckerAsItIsAlone) {
    constexpr long kSteps = 12000;
    for (std::size_t modes : {200u, 400u, 800u}) {
        const Case alone = plucked_at_fret_5(modes, false);
        Case beside = alone;
        FingerSpec f;
        f.position_m = fret_x(5) - 0.012;
        f.initial_gap_m = 0.02;
        beside.fingers.push_back(f);
        const Plan plan_alone(alone, 1e-6), plan_beside(beside, 1e-6);
        Stepper a(plan_alone, alone.initial_displacement, alone.initial_velocity);
        Stepper b(plan_beside, beside.initial_displacement, beside.initial_velocity);
        const double l2 = testing::step_and_compare(b, a, kSteps);
        std::printf("plucker beside an untouched finger against the plucker alone, %zu modes: relative L2 %.2g\n", modes, l2);
        EXPECT_TRUE(b.plucks().front().exact());
        EXPECT_EQ(b.plucks().front().stage(), Pluck::Stage::gone);
        EXPECT_EQ(b.fingers().front().contact_force(), 0.0);
        EXPECT_LT(l2, 1e-10);
    }
}

// The plucker beside the finger screened and straightforward: the same equations, rounded
// differently.
TEST(ExactFrets, APluckerBesideAFingerIsTheSameOnTheScreenedPath) {
    Case c = plucked_at_fret_5(110, false);
    c.add_fret_finger(5, "fret");
    const testing::PathComparison p = testing::compare_paths(c, 10000);
    std::printf("screened vs straightforward, plucker beside a finger: relative L2 %.3g\n", p.relative_l2);
    EXPECT_GT(p.fast.joint_steps, 1000);
    EXPECT_LT(p.relative_l2, 1e-11);
}

}  // namespace
}  // namespace fretbuzz
