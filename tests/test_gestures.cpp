// A force gesture (ForceProfile): a prescribed F(t) at a point or over a pad, at its exact
// position whatever the mode count. Its work enters the discrete balance exactly (H - work +
// dissipated constant to round-off, lossless and lossy, over 1e5 steps, with the string driven
// into the frets or onto exact point obstacles), a string held by a constant force settles at
// the static deflection of a taut string at the force's own x, the response converges with the
// mode count (and not to the grid-snapped force's), the screened path equals the
// straightforward one, and bad gesture input is refused naming the key.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "SmallBass.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

using testing::ideal_string;
using testing::observed;

Case small_bass_at_rest(double fs, double duration) { return testing::small_bass(fs, duration, 0.0); }

ForceSpec push(double x, double width, double direction, std::vector<std::array<double, 2>> profile) {
    ForceSpec f;
    f.position_m = x;
    f.width_m = width;
    f.direction = direction;
    f.force_profile = std::move(profile);
    return f;
}

struct Balance {
    double worst = 0.0, work = 0.0, h0 = 0.0;
    long contact_steps = 0;
};

Balance balance(const Case& c, long steps, bool screen = true) {
    c.validate();
    PlanOptions options;
    options.screen_contacts = screen;
    const Plan plan(c, 1.0 / c.run.sample_rate_hz, options);
    Stepper s(plan, c.initial_displacement, c.initial_velocity);
    Balance b;
    std::vector<double> ledger;
    double scale = 0.0;
    for (long n = 1; n <= steps; ++n) {
        s.step();
        ledger.push_back(s.energy() - s.work() + s.dissipated());
        scale = std::max({scale, std::abs(s.energy()), std::abs(s.work())});
    }
    for (double v : ledger) b.worst = std::max(b.worst, std::abs(v - ledger.front()) / scale);
    b.work = s.work();
    b.contact_steps = s.statistics().contact_steps;
    return b;
}

TEST(ForceGesture, WorkEntersTheLosslessBalanceExactly) {
    // Pushed down onto the frets over 5 ms with 3 N at 0.637 m, then let go: a slow, strong
    // press and release that drives the string into the frets.
    Case c = small_bass_at_rest(400000.0, 0.25);
    c.make_lossless();
    c.forces.push_back(push(0.637, 0.01, 1.0, {{0.0, 0.0}, {0.005, 3.0}, {0.0051, 0.0}}));
    const Balance b = balance(c, 100000);
    EXPECT_GT(b.work, 0.0);
    EXPECT_GT(b.contact_steps, 100);  // the frets are hit
    EXPECT_LT(b.worst, 1e-10);
}

TEST(ForceGesture, BalanceWithDampingIsExactForAPointForceUp) {
    Case c = small_bass_at_rest(400000.0, 0.25);
    c.forces.push_back(push(0.7, 0.0, -1.0, {{0.0, 0.0}, {0.002, 2.0}, {0.004, 0.0}}));
    const Balance b = balance(c, 100000);
    EXPECT_GT(b.work, 0.0);
    EXPECT_LT(b.worst, 1e-10);
}

// The static deflection of a taut string under a point force F at x0, u(x0) = F x0 (L - x0) / (T L),
// at x0 = 0.2013, off every grid point: the modal series truncated after N modes falls short of it
// by at most 2 F / (pi^2 N T) (its tail, sum_{j > N} 2 / (j pi)^2); the force at the nearest grid
// point of 200 modes (0.1990) gives 1.05 % less (the same series with the force there).
TEST(ForceGesture, APointForceSettlesAtTheStaticDeflectionAtItsExactPosition) {
    const double x0 = 0.2013, force = 0.5, tension = 1e4;
    const double expected = force * x0 * (1.0 - x0) / tension;
    for (std::size_t modes : {200u, 800u}) {
        // (fs high enough that the scheme's own static response, (w dt)^2 / (2 - 2 cos w dt) of
        // the exact one per mode, adds less than 1e-4 of u)
        Case c = ideal_string(modes, tension, "type = \"none\"", 1e6);
        for (double& sigma : c.modes.sigma_per_s) sigma = 400.0;  // settles within 0.1 s
        c.forces.push_back(push(x0, 0.0, -1.0, {{0.0, force}}));
        const double u = observed(c, x0, 100000).back();
        const double truncation = 2.0 * force / (std::numbers::pi * std::numbers::pi * static_cast<double>(modes) * tension);
        std::printf("%zu modes: u(x0) = %.6e, static %.6e (relative %.2e, truncation bound %.2e)\n", modes, u, expected,
                    (u - expected) / expected, truncation / expected);
        EXPECT_NEAR(u, expected, truncation) << modes << " modes";
    }
}

// The same along both polarisations: a force leaning 60 degrees from z toward y, down, at the
// same off-grid x0 (200 modes): cos(60) of it deflects z down, sin(60) of it deflects y, each
// to the taut string's static deflection within the series' truncation bound (at the nearest
// grid point, 1.05 % short: outside it).
TEST(ForceGesture, ALeaningForceSettlesAtTheStaticDeflectionAlongBothPolarisations) {
    const double x0 = 0.2013, force = 0.5, tension = 1e4, angle = 60.0;
    const std::size_t modes = 200;
    Case c = ideal_string(modes, tension, "type = \"none\"", 1e6);
    for (double& sigma : c.modes.sigma_per_s) sigma = 400.0;
    c.polarisation.count = 2;
    c.polarisation.table = c.modes;  // (y: the same modes and damping)
    ForceSpec leaning = push(x0, 0.0, 1.0, {{0.0, force}});
    leaning.angle_deg = angle;
    c.forces.push_back(leaning);
    c.validate();
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    Stepper s(plan, c.initial_displacement, c.initial_velocity);
    s.add_second_polarisation(c.initial_displacement, c.initial_velocity);
    for (long n = 0; n < 100000; ++n) s.step();
    const std::vector<double> at = plan.basis().mode_shapes_at(x0);
    const double static_deflection = force * x0 * (1.0 - x0) / tension;
    const double truncation = 2.0 * force / (std::numbers::pi * std::numbers::pi * static_cast<double>(modes) * tension);
    const double z = s.displacement(at), y = s.second_polarisation()->displacement(at);
    const double cz = std::cos(angle * std::numbers::pi / 180.0), cy = std::sin(angle * std::numbers::pi / 180.0);
    std::printf("leaning 60 degrees: z %.4e (static %.4e), y %.4e (static %.4e)\n", z, -cz * static_deflection, y,
                cy * static_deflection);
    EXPECT_NEAR(z, -cz * static_deflection, cz * truncation);
    EXPECT_NEAR(y, cy * static_deflection, cy * truncation);
}

// A short push (1 ms up to 0.5 N and back) at x = 0.2013 on the ideal string (c = 100 m/s), with
// no obstacle: u(0.7, t) over 20 ms at 200 and 400 modes against 800 (x is off every one of their
// grid points). The differences shrink as the modes double; the same push at the nearest grid
// point of 200 modes (what a grid-snapped force does) differs from the converged run by far more.
TEST(ForceGesture, ResponseConvergesWithTheModeCountAtTheExactPosition) {
    const double x0 = 0.2013;
    const auto run = [&](std::size_t modes, double x) {
        Case c = ideal_string(modes, 1e4, "type = \"none\"", 2e5);
        c.forces.push_back(push(x, 0.0, 1.0, {{0.0, 0.0}, {0.0005, 0.5}, {0.001, 0.0}}));
        return observed(c, 0.7, 4000);
    };
    const std::vector<double> u200 = run(200, x0), u400 = run(400, x0), u800 = run(800, x0);
    const double snapped_x = std::round(x0 * 201.0) / 201.0;
    const std::vector<double> snapped = run(200, snapped_x);
    const double coarse = testing::relative_l2(u200, u800), fine = testing::relative_l2(u400, u800);
    const double grid = testing::relative_l2(snapped, u800);
    std::printf("relative L2 of u(0.7) against 800 modes: 200 modes %.3g, 400 modes %.3g; snapped to x = %.4f: %.3g\n",
                coarse, fine, snapped_x, grid);
    EXPECT_LT(coarse, 3e-4);
    EXPECT_LT(fine, 0.6 * coarse);
    EXPECT_GT(grid, 5.0 * coarse);
}

// Exact point obstacles (three, 2 mm apart, off the grid, coupled) and a gesture off the grid
// pressing the string onto them, then letting go: lossless, H - work is constant to round-off.
TEST(ForceGesture, LosslessBalanceWithExactPointsIsRoundOff) {
    for (double width : {0.0, 0.013}) {
        Case c = ideal_string(110, 1.0, "type = \"points\"\nx = [0.2, 0.202, 0.204]\nheight = -1e-3", 1e5);
        c.forces.push_back(push(0.2513, width, 1.0, {{0.0, 0.0}, {0.2, 0.02}, {0.3, 0.0}}));
        const Balance b = balance(c, 60000);
        std::printf("width %g: balance %.2e, work %.3g J, %ld steps in contact\n", width, b.worst, b.work, b.contact_steps);
        EXPECT_GT(b.contact_steps, 100);
        EXPECT_LT(b.worst, 1e-12);
    }
}

TEST(ForceGesture, AConstantForceSettlesAtTheTautStringsStaticDeflection) {
    // Ideal-ish check: u(x0) = F x0 (L - x0) / (T L) under a point force F at x0 (the
    // bending stiffness, B = 3.5e-5, changes it by far less than the tolerance). Up, away
    // from the frets; heavy damping of every mode lets it settle.
    Case c = small_bass_at_rest(100000.0, 1.0);
    for (double& sigma : c.modes.sigma_per_s) sigma = std::max(sigma, 40.0);
    const double x0 = 0.5, force = 0.5;
    c.forces.push_back(push(x0, 0.0, -1.0, {{0.0, force}}));
    c.validate();
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    Stepper s(plan, c.initial_displacement, c.initial_velocity);
    for (long n = 0; n < 100000; ++n) s.step();
    const double dx = c.grid_step();
    const double at = std::round(x0 / dx) * dx;  // the grid point the force acts on
    const double L = c.string.length_m;
    const double expected = force * at * (L - at) / (c.string.tension_n * L);
    EXPECT_NEAR(s.displacement(plan.basis().mode_shapes_at(at)), expected, 0.01 * expected);
}

TEST(ForceGesture, ScreenedAndStraightforwardPathsAgree) {
    Case c = small_bass_at_rest(400000.0, 0.05);
    c.forces.push_back(push(0.637, 0.01, 1.0, {{0.0, 0.0}, {0.005, 3.0}, {0.0051, 0.0}}));
    const testing::PathComparison p = testing::compare_paths(c, 20000);
    EXPECT_GT(p.contact_steps, 0);
    EXPECT_LT(p.relative_l2, 1e-9);
}

// Once a gesture's force has ended the string flies freely between contacts again (the
// whole run's fast path: screening and free flight), and agrees with every point solved
// and every mode stepped at every step.
TEST(ForceGesture, FreeFlightAfterTheGestureEqualsTheStraightforwardPath) {
    Case c = small_bass_at_rest(400000.0, 0.05);
    c.run.output_rate_hz = 50000.0;
    c.forces.push_back(push(0.6371, 0.0, -1.0, {{0.0, 0.0}, {0.002, 1.0}, {0.0021, 0.0}}));
    const RecordedRun fast = testing::record_run(c, true), plain = testing::record_run(c, false);
    ASSERT_EQ(fast.observation.size(), plain.observation.size());
    EXPECT_GT(fast.summary.free_flight_fraction, 0.5);
    const double l2 = testing::relative_l2(fast.observation, plain.observation);
    std::printf("fast vs straightforward path after a gesture: relative L2 %.3g (free flight %.0f %%)\n", l2,
                100.0 * fast.summary.free_flight_fraction);
    EXPECT_LT(l2, 1e-9);
}

// `count` point force gestures 1 cm apart from 0.04 m on.
std::string many_gestures(int count) {
    std::string text;
    for (int k = 0; k < count; ++k)
        text += "\n[[gesture]]\ntype = \"force\"\nposition = " + std::to_string(0.04 + 0.01 * k) + "\nforce = 1\n";
    return text;
}

TEST(ForceGesture, BadGestureInputIsRefusedNamingTheKey) {
    const std::string g = "\n[[gesture]]\ntype = \"force\"\nposition = 0.6\n";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {g + "force = 2\n", ""},  // good
        {"\n[[gesture]]\ntype = \"bow\"\nposition = 0.6\nforce = 1\n", "gesture[0].type"},
        {"\n[[gesture]]\ntype = \"force\"\nposition = 0.0\nforce = 1\n", "gesture[0].position"},
        {"\n[[gesture]]\ntype = \"force\"\nposition = 1.0\nforce = 1\n", "gesture[0].position"},
        {g + "force = 1\nwidth = -0.01\n", "gesture[0].width"},
        {"\n[[gesture]]\ntype = \"force\"\nposition = 0.855\nwidth = 0.03\nforce = 1\n", "overlaps an end"},
        {g + "force = -1\n", "gesture[0].force[0][1]"},
        {g + "force = [[0, 1], [0.02, 2]]\n", ""},  // a point past the run's end: only the part within acts
        {g + "force = []\n", "gesture[0].force = []"},
        {g + "force = 1\ndirection = \"sideways\"\n", "gesture[0].direction"},
        {g + "force = 1\nspeed = 2\n", "gesture[0].speed"},
        {g + "force = 1\n\n[[finger]]\nposition = 0.6\n", "gesture[0].position"},
        {many_gestures(64), ""},
        {many_gestures(65), "at most 64 are allowed"},
    };
    testing::expect_refused("bad-gesture", testing::small_bass_text(), cases);
}

}  // namespace
}  // namespace fretbuzz
