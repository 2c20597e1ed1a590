// A force gesture (ForceProfile): a prescribed F(t) at a point or over a pad. Its work enters
// the discrete balance exactly (H - work + dissipated constant to round-off, lossless and
// lossy, over 1e5 steps, with the string driven into the frets), a string held by a constant
// force settles at the static deflection of a taut string, the screened path equals the
// straightforward one, and bad gesture input is refused naming the key.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "SmallBass.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

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
    };
    testing::expect_refused("bad-gesture", testing::small_bass_text(), cases);
}

}  // namespace
}  // namespace fretbuzz
