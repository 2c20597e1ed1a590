// Friction along y at point obstacles held at their exact positions (two polarisations): the
// friction solve meets its equations with several coupled points, the energy balance holds to
// round-off with one and with several points rubbing, the tanpura's bridge acts at 4 mm whatever
// the mode count, z is the one-polarisation run when y stays at rest, and the screened path
// agrees with the straightforward one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "SmallBass.hpp"
#include "TestSupport.hpp"
#include "TwoPolarisations.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/PointFriction.hpp"
#include "fretbuzz/scheme/SecondPolarisation.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

// The built-in tanpura with two polarisations and friction, `modes` modes.
Case tanpura(std::size_t modes) { return with_mode_count(read_case_text("tanpura-friction"), modes); }

// Its bridge as three points 1 mm apart (a curved bridge), off the grid: they couple.
Case tanpura_three_points(std::size_t modes) {
    Case c = tanpura(modes);
    const PointObstacle bridge = c.point_obstacles.front();
    c.point_obstacles.clear();
    for (double x : {0.003, 0.004, 0.005}) c.point_obstacles.push_back({x, bridge.height_m, bridge.weight_m});
    c.validate();
    return c;
}

using testing::TwoPolarisations;

TEST(ExactFriction, CoupledPointsMeetTheirEquations) {
    // Three points 1 mm apart on 110 modes (rows far from orthogonal), each rubbing: the
    // velocities v = v0 + (k / 2 dt) G f with f = -mu_f |F| phi(v) at every point.
    const ModalBasis basis(1.0, 110);
    std::vector<PointObstacle> obstacles;
    for (double x : {0.3, 0.301, 0.3025}) obstacles.push_back({x, 0.0, 2e-3});
    const PointContact points(basis, obstacles);
    ASSERT_TRUE(points.coupled());
    PointFriction friction(points);
    const Friction law(0.3, 1e-3);
    const double dt = 1.0 / 44100.0, k = dt * dt / 1e-3;
    const std::vector<double> v0{0.02, -0.015, 0.004}, normal{4e4, 2e4, 3e4};
    std::vector<double> force(3);
    const double work = friction.solve(law, v0, normal, k, dt, force);
    EXPECT_LT(work, 0.0);
    EXPECT_GT(friction.iterations(), 1);
    // In velocity (the equation's own unit: a point sticks where phi is steep, and there the
    // force is only as accurate as the velocity times 1 / v_eps), relative to the largest term.
    double worst = 0.0, size = 0.0;
    for (std::size_t p = 0; p < 3; ++p) {
        double v = v0[p], reach = 0.0;
        for (std::size_t q = 0; q < 3; ++q) {
            const double product = kernels::dot(points.row(p).data(), points.row(q).data(), basis.mode_count());
            v += k / (2.0 * dt) * points.weight(q) * product * force[q];
            reach += k / (2.0 * dt) * points.weight(q) * std::abs(product * force[q]);
        }
        const double g = -force[p] / (law.coefficient() * normal[p]);  // phi(v) as solved
        const double solved = law.regularisation_velocity() * g / std::sqrt(1.0 - g * g);
        EXPECT_LT(force[p] * v, 0.0);
        worst = std::max(worst, std::abs(solved - v));
        size = std::max(size, std::abs(v0[p]) + reach);
    }
    const double total = size;
    EXPECT_LT(worst / total, 1e-12);
    std::printf("[ numbers  ] three coupled points: relative residual %.3g (velocity), %d Newton iterations\n", worst / total,
                friction.iterations());
}

struct BalanceTrace {
    double worst_balance = 0.0;                // max |H + D - W - H0| / H0 over the steps
    double smallest_friction_step = 0.0;       // min over steps of the friction dissipated in it
    double friction = 0.0;
    long contact_steps = 0;
    int friction_iterations = 0;
    double worst_reported = 0.0;               // the y forces reported against the points' own
};

BalanceTrace balance(const Case& c, long steps) {
    TwoPolarisations two(c);
    Stepper& s = two.stepper;
    const PointContact& points = two.plan.point_contact();
    EXPECT_EQ(points.size(), c.point_obstacles.size());  // every point at its exact position
    s.step();
    const double h0 = s.energy();
    BalanceTrace t;
    double friction_before = 0.0;
    t.smallest_friction_step = std::numeric_limits<double>::infinity();
    const double dx = two.plan.basis().grid_step();
    for (long n = 1; n < steps; ++n) {
        s.step();
        t.worst_balance = std::max(t.worst_balance, std::abs(s.energy() + s.dissipated() - s.work() - h0) / h0);
        const double friction = two.y().friction_dissipated();
        t.smallest_friction_step = std::min(t.smallest_friction_step, friction - friction_before);
        // The reported y forces (per grid step) add up to the points' friction over their widths:
        // |f_y| <= mu_f |F_n| at each point, so their total is at most mu_f times the normal total.
        double reported = 0.0, normal = 0.0;
        for (const auto& [i, f] : two.y().forces()) reported += std::abs(f) * dx;
        for (const auto& [i, f] : s.forces()) normal += std::abs(f) * dx;
        if (normal > 0.0) t.worst_reported = std::max(t.worst_reported, reported / (c.polarisation.friction * normal));
        friction_before = friction;
    }
    t.friction = friction_before;
    t.contact_steps = s.statistics().contact_steps;
    t.friction_iterations = two.y().max_iterations();
    return t;
}

void expect_exact_balance(const BalanceTrace& t, const char* what) {
    EXPECT_GT(t.contact_steps, 100);
    EXPECT_GT(t.friction, 0.0);
    EXPECT_GE(t.smallest_friction_step, 0.0);  // friction never adds energy
    EXPECT_LT(t.worst_balance, 1e-12);
    EXPECT_GT(t.worst_reported, 0.0);
    EXPECT_LE(t.worst_reported, 1.0 + 1e-12);
    std::printf("[ numbers  ] %s: balance %.3g, friction %.4g J over %ld contact steps, %d friction iterations\n", what,
                t.worst_balance, t.friction, t.contact_steps, t.friction_iterations);
}

TEST(ExactFriction, LosslessBalanceIsExactWithOnePoint) {
    Case c = tanpura(110);
    c.make_lossless();
    expect_exact_balance(balance(c, 12000), "one exact point");
}

TEST(ExactFriction, LosslessBalanceIsExactWithSeveralCoupledPoints) {
    Case c = tanpura_three_points(110);
    c.make_lossless();
    const BalanceTrace t = balance(c, 12000);
    expect_exact_balance(t, "three exact points");
    EXPECT_GT(t.friction_iterations, 1);  // the coupled solve ran
}

TEST(ExactFriction, BalanceIsExactWithDamping) {
    const BalanceTrace t = balance(tanpura_three_points(110), 12000);
    expect_exact_balance(t, "three exact points, damped");
}

TEST(ExactFriction, CrownsBesideTheBoardKeepTheBalance) {
    // The small bass slapping its frets at 30 degrees: its crowns at their exact positions,
    // solved with the board's grid points rubbing in the same step.
    Case c = testing::small_bass(400000.0, 0.25, 6e-3);
    c.run.output_rate_hz.reset();
    c.polarisation.count = 2;
    c.polarisation.angle_deg = 30.0;
    c.polarisation.friction = 0.3;
    c.make_lossless();
    c.validate();
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    ASSERT_TRUE(plan.point_contact().grid_coupled());
    expect_exact_balance(balance(c, 40000), "crowns beside the board");
}

// When the bridge first pushes and what it has done 3 ms on.
struct Onset {
    long first_contact_step = -1;
    double impulse = 0.0;   // N s: the bridge's normal force over the window
    double friction = 0.0;  // J dissipated by friction over the window
};

Onset onset(const Case& c, long window) {
    TwoPolarisations two(c);
    Stepper& s = two.stepper;
    const double dx = two.plan.basis().grid_step(), dt = two.plan.dt();
    Onset o;
    for (long n = 0; n < window; ++n) {
        s.step();
        double force = 0.0;
        for (const auto& [i, f] : s.forces()) force += f * dx;
        if (force != 0.0 && o.first_contact_step < 0) o.first_contact_step = n;
        o.impulse += force * dt;
    }
    o.friction = two.y().friction_dissipated();
    return o;
}

TEST(ExactFriction, TheBridgeActsAtFourMillimetresWhateverTheModeCount) {
    // 110 modes: grid step 9.0 mm; 400 modes: 2.5 mm. The bridge at 4 mm is on neither grid.
    const Case coarse = tanpura(110), fine = tanpura(400);
    Plan plan(coarse, 1.0 / coarse.run.sample_rate_hz);
    ASSERT_EQ(plan.point_contact().size(), 1u);
    EXPECT_EQ(plan.point_contact().point(0).x_m, 0.004);
    const long window = 1200;  // 3 ms at 400 kHz
    const Onset a = onset(coarse, window), b = onset(fine, window);
    ASSERT_GE(a.first_contact_step, 0);
    ASSERT_GE(b.first_contact_step, 0);
    const double impulse = std::abs(a.impulse - b.impulse) / std::abs(b.impulse);
    const double friction = std::abs(a.friction - b.friction) / b.friction;
    std::printf("[ numbers  ] bridge onset, 110 vs 400 modes: first contact step %ld vs %ld, impulse %.4g vs %.4g N s "
                "(%.2g), friction %.4g vs %.4g J (%.2g)\n",
                a.first_contact_step, b.first_contact_step, a.impulse, b.impulse, impulse, a.friction, b.friction, friction);
    // With the bridge at its nearest grid point (9.0 mm and 5.0 mm) the friction dissipated over
    // these 3 ms differed threefold (relative difference 2.0; the impulse by 0.26). What is left
    // at the exact position is the coarse table's truncation (0.22; the impulse 0.20).
    EXPECT_LE(std::abs(a.first_contact_step - b.first_contact_step), 1);
    EXPECT_LT(friction, 0.4);
    EXPECT_LT(impulse, 0.25);
}

TEST(ExactFriction, ZIsTheOnePolarisationRunWhenYStaysAtRest) {
    // Along z alone (angle 0), y at rest: friction has no sliding to oppose, and z steps exactly
    // as with one polarisation, the bridge at its exact position in both.
    for (double mu_f : {0.0, 0.3}) {
        Case two = tanpura(110);
        two.polarisation.angle_deg = 0.0;
        two.polarisation.friction = mu_f;
        two.validate();
        TwoPolarisations both(two);
        Case one = two;
        one.polarisation = {};
        one.validate();
        const Plan plan(one, 1.0 / one.run.sample_rate_hz);
        Stepper single(plan, one.initial_displacement, one.initial_velocity);
        double worst = 0.0;
        for (long n = 0; n < 8000; ++n) {
            single.step();
            both.stepper.step();
            const auto a = single.modal_displacement(), b = both.stepper.modal_displacement();
            double diff = 0.0, norm = 0.0;
            for (std::size_t j = 0; j < a.size(); ++j) {
                diff += (a[j] - b[j]) * (a[j] - b[j]);
                norm += a[j] * a[j];
            }
            worst = std::max(worst, std::sqrt(diff / norm));
        }
        EXPECT_GT(single.statistics().contact_steps, 100);
        EXPECT_LE(worst, 1e-14) << "mu_f " << mu_f;
        EXPECT_EQ(both.y().friction_dissipated(), 0.0);
        const auto y = both.y().modal_displacement();
        EXPECT_TRUE(std::all_of(y.begin(), y.end(), [](double q) { return q == 0.0; }));
    }
}

TEST(ExactFriction, ScreenedPathAgreesWithTheStraightforwardPath) {
    // Three points 0.5 mm apart, 50 um below the string at 10 cm, beside the bridge: the
    // string strikes them on its way down, and they rub too.
    Case c = tanpura(110);
    for (double x : {0.1, 0.1005, 0.101}) c.point_obstacles.push_back({x, -5e-5, c.point_obstacles.front().weight_m});
    c.run.duration_s = 0.03;
    c.run.output_rate_hz = 50000.0;
    c.validate();
    const RecordedRun fast = testing::record_run(c, true), plain = testing::record_run(c, false);
    ASSERT_EQ(fast.observation_y.size(), plain.observation_y.size());
    ASSERT_GT(plain.friction.back(), 0.0);
    // The strikes, in the contact map at the points' nearest grid point (as every exact point's).
    bool struck = false;
    for (std::size_t i = 0; i < plain.grid_x.size(); ++i)
        struck = struck || (std::abs(plain.grid_x[i] - 0.1) < 0.01 && std::isfinite(plain.first_contact_s[i]));
    EXPECT_TRUE(struck);
    const double z = testing::relative_l2(fast.observation, plain.observation);
    const double y = testing::relative_l2(fast.observation_y, plain.observation_y);
    EXPECT_LT(z, 1e-9);
    EXPECT_LT(y, 1e-9);
    std::printf("[ numbers  ] screened vs straightforward path: relative L2 z %.3g, y %.3g (free flight %.0f %%)\n", z, y,
                100.0 * fast.summary.free_flight_fraction);
}

}  // namespace
}  // namespace fretbuzz
