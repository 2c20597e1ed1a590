// Point obstacles at their exact positions (PointContact): the first contact where d'Alembert
// puts it whatever the mode count, results that converge with the mode count, the energy
// balance with several coupled points in contact at once, the grid's own path for points on
// grid points against PointContact's, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "TestSupport.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

using testing::CommandResult;
using testing::run_cli;
using testing::ScratchDir;

// An ideal lossless string, L = T = mu = 1 (c = 1), plucked 1 cm at 0.25 as a triangle,
// over point obstacles given as TOML lines.
std::string ideal_string(std::size_t modes, const std::string& obstacle, double fs = 1e5, double stiffness = 1e9) {
    return R"(name = "ideal-point"
[string]
L = 1.0
T = 1.0
mu = 1.0
modes = )" + std::to_string(modes) + R"(
ideal = true
[obstacle]
type = "points"
)" + obstacle + R"(
[excitation]
type = "triangle"
position = 0.25
amplitude = 0.01
[contact]
K = )" + std::to_string(stiffness) + R"(
alpha = 1.5
[run]
fs = )" + std::to_string(fs) + R"(
duration = 0.6
lossless = true
[observe]
x = [0.7]
)";
}

struct PointRun {
    double first_contact_s = -1.0;
    std::vector<double> observed, energy;
    std::size_t most_points_pushing = 0;
    bool coupled = false;
};

PointRun run_points(const Case& c, double duration_s, PlanOptions options = {}) {
    const Plan plan(c, 1.0 / c.run.sample_rate_hz, options);
    const std::vector<double> probe = plan.basis().mode_shapes_at(0.7);
    Stepper stepper(plan, c.initial_displacement, c.initial_velocity);
    PointRun r;
    r.coupled = plan.point_contact().coupled();
    const long steps = std::lround(duration_s * c.run.sample_rate_hz);
    for (long n = 0; n < steps; ++n) {
        stepper.step();
        if (stepper.touched_obstacle() && r.first_contact_s < 0.0) r.first_contact_s = stepper.time();
        r.most_points_pushing = std::max(r.most_points_pushing, stepper.forces().size());
        r.observed.push_back(stepper.displacement(probe));
        if (n > 0) r.energy.push_back(stepper.energy());
    }
    return r;
}

// Relative L2 difference of two runs' signals at x = 0.7.
double relative_l2(const PointRun& a, const PointRun& b) {
    double num = 0.0, den = 0.0;
    for (std::size_t k = 0; k < a.observed.size() && k < b.observed.size(); ++k) {
        num += (a.observed[k] - b.observed[k]) * (a.observed[k] - b.observed[k]);
        den += b.observed[k] * b.observed[k];
    }
    return std::sqrt(num / den);
}

// d'Alembert: u(0.2, t) = 0.005 [(0.8 - t) / 0.75 - 4 (t - 0.2)] for 0.2 <= t <= 0.45 meets
// g = -1 mm at t* = 0.3875 (the 110-mode series at 0.38748). A point at its nearest grid
// point would be dx / 2 off at worst: 0.38662 s at 110 modes, 0.38725 s at 400.
TEST(PointContact, FirstContactWhereDAlembertPutsIt) {
    for (std::size_t modes : {110u, 400u}) {
        const Case c = parse_case(ideal_string(modes, "x = 0.2\nheight = -1e-3"), "ideal-point.toml", DataSource::builtin());
        const PointRun r = run_points(c, 0.45);
        EXPECT_NEAR(r.first_contact_s, 0.3875, 5e-5) << modes << " modes";
        std::printf("%zu modes: first contact at %.5f s\n", modes, r.first_contact_s);
    }
    // The mirror image through a whole run: plucked down onto a point 1 mm above the string
    // (side = "above"), the first contact as the run's summary gives it.
    std::string text = ideal_string(110, "side = \"above\"\nx = 0.2\nheight = 1e-3");
    text.replace(text.find("amplitude = 0.01"), 16, "amplitude = -0.01");
    Case mirrored = parse_case(text, "ideal-point.toml", DataSource::builtin());
    mirrored.run.duration_s = 0.45;
    const RunSummary summary = simulate(mirrored, {});
    EXPECT_NEAR(summary.first_contact_s, 0.3875, 5e-5);
}

// Beside an obstacle on the grid, the point still acts at its exact x: with a flat barrier
// 4 mm below (reached after the point), d'Alembert's first contact at 110 and 400 modes; with
// the barrier 1.5 mm below, point and barrier in contact in the same steps, solved together,
// keep the lossless balance at round-off.
TEST(PointContact, BesideAnObstacleOnTheGridThePointKeepsItsExactPosition) {
    for (const double barrier : {-4e-3, -1.5e-3})
        for (std::size_t modes : {110u, 400u}) {
            std::string text = ideal_string(modes, "x = 0.2\nheight = -1e-3");
            text.replace(text.find("[obstacle]"), 10,
                         "[[obstacle]]\ntype = \"flat\"\nheight = " + std::to_string(barrier) + "\n[[obstacle]]");
            const Case c = parse_case(text, "ideal-point-flat.toml", DataSource::builtin());
            ASSERT_EQ(c.point_obstacles.size(), 1u);
            const Plan plan(c, 1.0 / c.run.sample_rate_hz);
            Stepper s(plan, c.initial_displacement, c.initial_velocity);
            double first = -1.0, h0 = 0.0, worst = 0.0;
            for (long n = 0; n < 60000; ++n) {
                s.step();
                if (s.touched_obstacle() && first < 0.0) first = s.time();
                if (n == 1) h0 = s.energy();
                if (n > 1) worst = std::max(worst, std::abs(s.energy() - h0) / h0);
            }
            std::printf("%zu modes, a flat barrier %.1f mm below: first contact at %.5f s, %ld joint steps, balance %.2g\n",
                        modes, -1e3 * barrier, first, s.statistics().joint_steps, worst);
            if (barrier < -2e-3)
                EXPECT_NEAR(first, 0.3875, 5e-5) << modes << " modes";
            else
                EXPECT_GT(s.statistics().joint_steps, 100);
            EXPECT_LT(worst, 1e-12);
        }
}

// The point acts at x = 0.2 whatever the grid: runs at 200, 400 and 800 modes (the point
// 0.2 grid steps off the nearest grid point of each, one contact width for all) meet it at
// d'Alembert's time, and their signals differ by what the truncated series differ by,
// shrinking as the modes double.
TEST(PointContact, ResultsIndependentOfTheModeCount) {
    std::vector<PointRun> runs;
    for (std::size_t modes : {200u, 400u, 800u}) {
        const Case c = parse_case(ideal_string(modes, "x = 0.2\nheight = -1e-3\nwidth = 5e-3", 4e5), "ideal-point.toml", DataSource::builtin());
        runs.push_back(run_points(c, 0.6));
    }
    const double coarse = relative_l2(runs[0], runs[2]), fine = relative_l2(runs[1], runs[2]);
    std::printf("relative L2 of u(0.7) against 800 modes: 200 modes %.3g, 400 modes %.3g\n", coarse, fine);
    EXPECT_LT(coarse, 5e-4);
    EXPECT_LT(fine, 0.6 * coarse);
    for (const PointRun& r : runs) EXPECT_NEAR(r.first_contact_s, 0.3875, 5e-5);
}

// Three points 2 mm apart, off the grid, under a soft penalty: they couple through the modes
// and push at the same steps; the coupled discrete-gradient solve keeps H constant to round-off.
TEST(PointContact, EnergyConservedWithSeveralCoupledPointsInContact) {
    // alpha = 1.5 (closed form), 1 (linear), 2.5 (the general law through pow)
    for (const double alpha : {1.5, 1.0, 2.5}) {
        std::string text = ideal_string(110, "x = [0.2, 0.202, 0.204]\nheight = -1e-3", 1e5, 1e5);
        text.replace(text.find("alpha = 1.5"), 11, "alpha = " + std::to_string(alpha));
        const Case c = parse_case(text, "ideal-point.toml", DataSource::builtin());
        const PointRun r = run_points(c, 0.6);
        EXPECT_TRUE(r.coupled);
        EXPECT_GE(r.most_points_pushing, 2u) << "alpha " << alpha;
        double worst = 0.0;
        for (double h : r.energy) worst = std::max(worst, std::abs(h - r.energy.front()) / r.energy.front());
        std::printf("alpha %.1f: %zu points pushing at once at most; energy drift %.2g\n", alpha, r.most_points_pushing,
                    worst);
        EXPECT_LT(worst, 1e-12) << "alpha " << alpha;
    }
}

// Points on grid points, one grid step wide: the grid's scalar solve with screening (the fast
// path) and PointContact (the straightforward one, a row per point and the decoupled solve)
// give the same motion to round-off over many contacts.
TEST(PointContact, GridPathEqualsThePointSolve) {
    const double dx = 1.0 / 111.0;
    const std::string points = "x = [" + std::to_string(22 * dx) + ", " + std::to_string(60 * dx) +
                               "]\nheight = [-1e-3, -2e-3]\nwidth = " + std::to_string(dx);
    Case c = parse_case(ideal_string(110, points), "ideal-point.toml", DataSource::builtin());
    // exactly on the grid (the text rounds them)
    c.point_obstacles[0].x_m = 22 * dx;
    c.point_obstacles[1].x_m = 60 * dx;
    c.point_obstacles[0].weight_m = c.point_obstacles[1].weight_m = dx;
    PlanOptions reference;
    reference.grid_points_on_grid = false;
    const Plan fast_plan(c, 1e-5), reference_plan(c, 1e-5, reference);
    EXPECT_TRUE(fast_plan.point_contact().empty());
    EXPECT_EQ(reference_plan.point_contact().size(), 2u);
    EXPECT_FALSE(reference_plan.point_contact().coupled());
    const PointRun fast = run_points(c, 0.6), slow = run_points(c, 0.6, reference);
    ASSERT_GT(fast.first_contact_s, 0.0);
    std::printf("grid path against the point solve: relative L2 %.2g\n", relative_l2(fast, slow));
    EXPECT_LT(relative_l2(fast, slow), 1e-10);
    EXPECT_EQ(fast.first_contact_s, slow.first_contact_s);
}

// The step that pushes with the points' rows and forms their next prediction in the same pass
// (the fast path) against separate passes and an impulse vector (fused_step = false).
TEST(PointContact, FusedStepEqualsSeparatePasses) {
    const Case c = parse_case(ideal_string(110, "x = [0.2, 0.202, 0.204]\nheight = -1e-3", 1e5, 1e5), "ideal-point.toml",
                              DataSource::builtin());
    PlanOptions separate;
    separate.fused_step = false;
    const PointRun fused = run_points(c, 0.6), slow = run_points(c, 0.6, separate);
    std::printf("fused point step against separate passes: relative L2 %.2g\n", relative_l2(fused, slow));
    EXPECT_LT(relative_l2(fused, slow), 1e-12);
    EXPECT_EQ(fused.first_contact_s, slow.first_contact_s);
}

TEST(PointContact, BadInputIsRefusedWithExit2) {
    ScratchDir dir("point-width");
    {  // an initial shape through a point (u = 1 cm at x = 0.25, the point 2 cm up)
        const std::string path = (dir.path() / "through.toml").string();
        std::ofstream(path) << ideal_string(110, "x = 0.25\nheight = 0.02");
        const CommandResult r = run_cli("run " + path + " --out " + (dir.path() / "out").string() + " -q");
        EXPECT_EQ(r.exit_code, 2) << r.output;
        EXPECT_NE(r.output.find("initial shape penetrates"), std::string::npos) << r.output;
        EXPECT_FALSE(std::filesystem::exists(dir.path() / "out"));
    }
    for (const char* width : {"0", "-1e-3", "2.0"}) {
        const std::string path = (dir.path() / "bad.toml").string();
        std::ofstream(path) << ideal_string(110, "x = 0.2\nheight = -1e-3\nwidth = " + std::string(width));
        const CommandResult r = run_cli("run " + path + " --out " + (dir.path() / "out").string() + " -q");
        EXPECT_EQ(r.exit_code, 2) << r.output;
        EXPECT_NE(r.output.find("obstacle.width = "), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("out of range: must be"), std::string::npos) << r.output;
        EXPECT_FALSE(std::filesystem::exists(dir.path() / "out")) << width;
    }
}

}  // namespace
}  // namespace fretbuzz
