// Two polarisations (z against the obstacle, y parallel to it) coupled by friction at the
// contacts: the one-polarisation result is recovered at angle 0, y without friction is the
// free string's exact motion, the energy balance (both polarisations, contact, damping,
// friction) holds to round-off, friction never adds energy, and the orbit follows the known
// physics of two polarisations (a straight line for equal tables, a beat of period 1/df).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <vector>

#include "SmallBass.hpp"
#include "TestSupport.hpp"
#include "TwoPolarisations.hpp"
#include "fretbuzz/run/ResultRecorder.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/scheme/SecondPolarisation.hpp"

namespace fretbuzz {
namespace {

using testing::small_bass;

// The small bass plucked 6 mm (it slaps on the frets) at `angle` degrees, two polarisations.
Case two_polarisation_bass(double fs, double angle, double friction) {
    Case c = small_bass(fs, 0.25, 6e-3);
    c.run.output_rate_hz.reset();
    c.polarisation.count = 2;
    c.polarisation.angle_deg = angle;
    c.polarisation.friction = friction;
    c.validate();
    return c;
}

void remove_obstacle(Case& c) {
    std::fill(c.obstacle_height_m.begin(), c.obstacle_height_m.end(), -std::numeric_limits<double>::infinity());
    c.point_obstacles.clear();  // (the frets' crowns)
}

using testing::TwoPolarisations;

TEST(Polarisations, AngleZeroGivesTheOnePolarisationRunExactly) {
    Case one = two_polarisation_bass(400000.0, 0.0, 0.3);
    TwoPolarisations two(one);
    one.polarisation = {};
    const Plan plan(one, 1.0 / one.run.sample_rate_hz);
    Stepper single(plan, one.initial_displacement, one.initial_velocity);
    for (long n = 0; n < 20000; ++n) {
        single.step();
        two.stepper.step();
        const auto a = single.modal_displacement(), b = two.stepper.modal_displacement();
        ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin())) << "step " << n;
    }
    EXPECT_GT(single.statistics().contact_steps, 100);
    const auto y = two.y().modal_displacement();
    EXPECT_TRUE(std::all_of(y.begin(), y.end(), [](double q) { return q == 0.0; }));
    EXPECT_EQ(two.y().friction_dissipated(), 0.0);
    EXPECT_EQ(single.energy(), two.stepper.energy());
    EXPECT_EQ(single.dissipated(), two.stepper.dissipated());
}

TEST(Polarisations, WithoutFrictionYIsTheFreeStringsExactMotion) {
    Case c = two_polarisation_bass(400000.0, 30.0, 0.0);
    c.polarisation.frequency_scale = 1.01;  // a y table of its own
    c.polarisation.damping_scale = 2.0;
    TwoPolarisations two(c);
    const long steps = 20000;
    for (long n = 0; n < steps; ++n) two.stepper.step();
    ASSERT_GT(two.stepper.statistics().contact_steps, 100);  // z slaps on the frets meanwhile
    // Closed form of each damped mode from q0 = sin(30 deg) q_j(0) at rest.
    const ModeTable y = c.y_modes();
    const double t = static_cast<double>(steps) / c.run.sample_rate_hz;
    double num = 0.0, den = 0.0;
    for (std::size_t j = 0; j < c.mode_count(); ++j) {
        const double q0 = 0.5 * c.initial_displacement[j];
        const double w = 2.0 * std::numbers::pi * y.frequency_hz[j], s = y.sigma_per_s[j];
        const double wd = std::sqrt(w * w - s * s);
        const double exact = std::exp(-s * t) * q0 * (std::cos(wd * t) + s / wd * std::sin(wd * t));
        const double got = two.y().modal_displacement()[j];
        num += (got - exact) * (got - exact);
        den += exact * exact;
    }
    EXPECT_LT(std::sqrt(num / den), 1e-9);
    EXPECT_EQ(two.y().friction_dissipated(), 0.0);
}

struct BalanceTrace {
    double worst_balance = 0.0;       // max |H + D - H0| / H0 over the steps
    double smallest_friction_step = 0.0;  // min over steps of the friction dissipated in it
    double friction = 0.0;
    long contact_steps = 0;
};

BalanceTrace balance(const Case& c, long steps) {
    TwoPolarisations two(c);
    Stepper& s = two.stepper;
    s.step();
    const double h0 = s.energy();
    BalanceTrace t;
    double friction_before = 0.0;
    t.smallest_friction_step = std::numeric_limits<double>::infinity();
    for (long n = 1; n < steps; ++n) {
        s.step();
        t.worst_balance = std::max(t.worst_balance, std::abs(s.energy() + s.dissipated() - h0) / h0);
        const double friction = two.y().friction_dissipated();
        t.smallest_friction_step = std::min(t.smallest_friction_step, friction - friction_before);
        friction_before = friction;
    }
    t.friction = friction_before;
    t.contact_steps = s.statistics().contact_steps;
    return t;
}

TEST(Polarisations, EnergyBalanceIsExactWithFrictionLossless) {
    Case c = two_polarisation_bass(400000.0, 30.0, 0.3);
    c.make_lossless();
    const BalanceTrace t = balance(c, 100000);
    ASSERT_GT(t.contact_steps, 500);  // (873: the crowns at their exact positions)
    EXPECT_GT(t.friction, 0.0);
    EXPECT_GE(t.smallest_friction_step, 0.0);  // friction dissipates at every step, never gives back
    EXPECT_LT(t.worst_balance, 1e-10);
    std::printf("[ numbers  ] lossless, friction 0.3, 1e5 steps: balance %.3g, friction took %.3g J\n",
                t.worst_balance, t.friction);
}

TEST(Polarisations, EnergyBalanceIsExactWithFrictionAndDamping) {
    Case c = two_polarisation_bass(400000.0, 30.0, 0.3);
    c.polarisation.frequency_scale = 1.003;
    c.polarisation.damping_scale = 1.5;
    const BalanceTrace t = balance(c, 100000);
    ASSERT_GT(t.contact_steps, 1000);
    EXPECT_GT(t.friction, 0.0);
    EXPECT_GE(t.smallest_friction_step, 0.0);
    EXPECT_LT(t.worst_balance, 1e-10);
    std::printf("[ numbers  ] with losses, friction 0.3, 1e5 steps: balance %.3g, friction took %.3g J\n",
                t.worst_balance, t.friction);
}

TEST(Polarisations, StiffFrictionStillConvergesAndDissipates) {
    // A tiny regularisation velocity makes phi nearly a step: the solve must still converge.
    Case c = two_polarisation_bass(400000.0, 45.0, 2.0);
    c.polarisation.friction_velocity = 1e-7;
    const BalanceTrace t = balance(c, 20000);
    std::printf("[ numbers  ] %ld steps with contact\n", t.contact_steps);
    EXPECT_GT(t.friction, 0.0);
    EXPECT_GE(t.smallest_friction_step, 0.0);
    EXPECT_LT(t.worst_balance, 1e-10);
}

TEST(Polarisations, FrictionSolveMeetsItsEquation) {
    const Friction law(0.4, 1e-3);
    for (double v0 : {-3.0, -1e-3, -1e-9, 0.0, 2e-6, 0.5, 7.0})
        for (double normal : {0.0, 1.0, 1e3, 1e7}) {
            const double k = 1e-10, dt = 1e-6;
            const FrictionSolution s = law.solve(v0, normal, k, dt);
            const double big_k = k * 0.4 * normal / (2.0 * dt);
            EXPECT_NEAR(s.velocity + big_k * law.phi(s.velocity), v0, 1e-13 * (std::abs(v0) + big_k) + 1e-18);
            EXPECT_LE(s.force * s.velocity, 0.0);  // opposes the sliding
            EXPECT_LE(std::abs(s.force), 0.4 * normal);  // bounded by mu F_n
        }
}

// Orbit at x over a run of a string with no obstacle plucked in mode 1 only, lossless.
struct Orbit {
    std::vector<double> z, y, vz, vy;
};

Orbit orbit(Case c, double frequency_scale, long steps) {
    remove_obstacle(c);
    c.make_lossless();
    std::fill(c.initial_displacement.begin(), c.initial_displacement.end(), 0.0);
    c.initial_displacement[0] = 1e-3;
    c.polarisation.angle_deg = 45.0;
    c.polarisation.frequency_scale = frequency_scale;
    TwoPolarisations two(c);
    const std::vector<double> probe = two.plan.basis().mode_shapes_at(0.3 * c.string.length_m);
    Orbit o;
    for (long n = 0; n < steps; ++n) {
        two.stepper.step();
        o.z.push_back(two.stepper.displacement(probe));
        o.y.push_back(two.y().displacement(probe));
        o.vz.push_back(two.stepper.velocity(probe));
        o.vy.push_back(two.y().velocity(probe));
    }
    return o;
}

TEST(Polarisations, FortyFiveDegreesWithEqualTablesKeepsAStraightOrbit) {
    Case c = two_polarisation_bass(48000.0, 45.0, 0.0);
    remove_obstacle(c);  // the whole pluck, every mode
    TwoPolarisations two(c);
    const std::vector<double> probe = two.plan.basis().mode_shapes_at(0.854);
    double worst = 0.0, largest = 0.0;
    for (long n = 0; n < 48000; ++n) {
        two.stepper.step();
        const double z = two.stepper.displacement(probe), y = two.y().displacement(probe);
        worst = std::max(worst, std::abs(y - z));
        largest = std::max(largest, std::abs(z));
    }
    EXPECT_LT(worst, 1e-12 * largest);  // y = z: the line at 45 degrees
}

TEST(Polarisations, OrbitCyclesWithThePeriodOfTheFrequencyDifference) {
    const Case c = two_polarisation_bass(20000.0, 45.0, 0.0);
    const double f1 = c.modes.frequency_hz[0];
    const double df = 2.0;
    const double fs = c.run.sample_rate_hz;
    const Orbit o = orbit(c, (f1 + df) / f1, static_cast<long>(1.8 * fs / df));
    // The orbit's signed area rate z vy - y vz goes as sin(2 pi df t): average it over
    // periods of the fundamental and time its zero crossings (two a period).
    const auto window = static_cast<std::size_t>(std::lround(fs / f1));
    std::vector<double> t, mean;
    for (std::size_t start = 0; start + window <= o.z.size(); start += window) {
        double sum = 0.0;
        for (std::size_t n = start; n < start + window; ++n) sum += o.z[n] * o.vy[n] - o.y[n] * o.vz[n];
        mean.push_back(sum / static_cast<double>(window));
        t.push_back((static_cast<double>(start) + 0.5 * static_cast<double>(window)) / fs);
    }
    std::vector<double> crossings;
    for (std::size_t k = 1; k < mean.size(); ++k)
        if ((mean[k - 1] < 0.0) != (mean[k] < 0.0))
            crossings.push_back(t[k - 1] + (t[k] - t[k - 1]) * mean[k - 1] / (mean[k - 1] - mean[k]));
    ASSERT_GE(crossings.size(), 3u);
    const double period = crossings[2] - crossings[0];
    EXPECT_NEAR(period, 1.0 / df, 0.01 / df);
    std::printf("[ numbers  ] orbit period %.5f s for 1/df = %.5f s (error %.3g %%)\n", period, 1.0 / df,
                100.0 * std::abs(period * df - 1.0));
}

using testing::relative_l2;

TEST(Polarisations, FastPathEqualsTheStraightforwardPath) {
    Case c = two_polarisation_bass(400000.0, 30.0, 0.3);
    // 20 ms of slapping: longer, sharp contacts amplify round-off differences in z alone.
    c.run.duration_s = 0.02;
    c.run.output_rate_hz = 50000.0;
    const RecordedRun fast = testing::record_run(c, true), plain = testing::record_run(c, false);
    ASSERT_EQ(fast.observation_y.size(), plain.observation_y.size());
    ASSERT_GT(fast.summary.free_flight_fraction, 0.0);
    EXPECT_GT(fast.summary.friction_j, 0.0);
    const double z = relative_l2(fast.observation, plain.observation);
    const double y = relative_l2(fast.observation_y, plain.observation_y);
    EXPECT_LT(z, 1e-9);
    EXPECT_LT(y, 1e-9);
    std::printf("[ numbers  ] fast vs straightforward path: relative L2 z %.3g, y %.3g (free flight %.0f %%)\n", z, y,
                100.0 * fast.summary.free_flight_fraction);
}

TEST(Polarisations, BadInputIsRefusedWithoutFiles) {
    const testing::ScratchDir dir("pol");
    const std::filesystem::path out = dir.path() / "out";
    const auto refused = [&](const std::string& args, const std::string& key) {
        const testing::CommandResult r = testing::run_cli("run " + args + " --duration 0.001 -q --out " + out.string());
        EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
        EXPECT_NE(r.output.find(key), std::string::npos) << r.output;
        EXPECT_FALSE(std::filesystem::exists(out)) << args;
    };
    refused("bass-pop --polarisations 2 --angle nan", "excitation.angle");
    refused("bass-pop --polarisations 3", "--polarisations");
    refused("bass-pop --angle 30", "polarisations = 2");
    // Case files: a negative friction coefficient, a y table of another mode count.
    std::string text = builtin_case_text("bass-pop-30");
    const auto write = [&](const std::string& name, const std::string& body) {
        std::ofstream(dir.path() / name) << body;
        return (dir.path() / name).string();
    };
    std::string negative = text;
    negative.replace(negative.find("friction = 0.3"), 14, "friction = -0.3");
    refused(write("negative.toml", negative), "contact.friction");
    std::ofstream(dir.path() / "y.csv") << "mode,frequency_hz,sigma_per_s\n1,41.2,0.5\n2,82.4,0.6\n";
    refused(write("table.toml", text + "\n[polarisation_y]\ntable = \"" + (dir.path() / "y.csv").string() + "\"\n"),
            "polarisation_y.table");
    refused(write("modes.toml", text + "\n[polarisation_y]\nmodes = 100\n"), "polarisation_y.modes");
}

}  // namespace
}  // namespace fretbuzz

namespace fretbuzz {
namespace {

TEST(Polarisations, AGestureAtAnAngleKeepsTheBalance) {
    // The string at rest, pushed at 60 degrees (half of it along z, toward the frets) and
    // let go: the balance H - W + D = H(1/2) over both polarisations, friction included.
    Case c = testing::small_bass(400000.0, 0.25, 0.0);
    c.polarisation.count = 2;
    c.polarisation.friction = 0.3;
    ForceSpec push;
    push.key = "gesture[0]";
    push.position_m = 0.5;
    push.width_m = 0.01;
    push.angle_deg = 60.0;
    push.force_profile = {{0.0, 0.0}, {0.01, 20.0}, {0.0101, 0.0}};
    c.forces.push_back(push);
    c.validate();
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    Stepper s(plan, c.initial_displacement, c.initial_velocity);
    s.add_second_polarisation(c.initial_displacement, c.initial_velocity);
    double worst = 0.0, largest = 0.0;
    s.step();
    const double h0 = s.energy();
    for (long n = 1; n < 100000; ++n) {
        s.step();
        largest = std::max({largest, std::abs(s.work()), h0});
        worst = std::max(worst, std::abs(s.energy() - s.work() + s.dissipated() - h0));
    }
    const SecondPolarisation& y = *s.second_polarisation();
    EXPECT_GT(y.work(), 0.0);  // the y part did work
    EXPECT_GT(s.statistics().contact_steps, 100);
    EXPECT_GT(y.friction_dissipated(), 0.0);
    EXPECT_LT(worst / largest, 1e-10);
    std::printf("[ numbers  ] gesture at 60 degrees, friction 0.3, 1e5 steps: balance %.3g of %.3g J work\n",
                worst / largest, largest);
}

}  // namespace
}  // namespace fretbuzz

namespace fretbuzz {
namespace {

TEST(Polarisations, FrictionUnderAFingerKeepsTheBalanceAndDragsY) {
    // The small bass stopped at fret 5 by the default finger and plucked at 45 degrees: the
    // string rubs under the finger's pad and on the fret it presses onto. The balance holds
    // with the finger's work and losses, friction never adds energy, and the y motion loses
    // more with friction than without.
    const auto run = [](double friction, double& worst, double& smallest_step) {
        Case c = testing::small_bass(400000.0, 0.25, 1e-3);
        c.polarisation.count = 2;
        c.polarisation.angle_deg = 45.0;
        c.polarisation.friction = friction;
        c.add_fret_finger(5, "fret");
        c.validate();
        TwoPolarisations two(c);
        Stepper& s = two.stepper;
        s.step();
        const double h0 = s.energy();
        double largest = h0, before = 0.0;
        worst = 0.0;
        smallest_step = std::numeric_limits<double>::infinity();
        for (long n = 1; n < 40000; ++n) {
            s.step();
            largest = std::max({largest, std::abs(s.work()), s.energy()});
            worst = std::max(worst, std::abs(s.energy() - s.work() + s.dissipated() - h0));
            const double f = two.y().friction_dissipated();
            smallest_step = std::min(smallest_step, f - before);
            before = f;
        }
        worst /= largest;
        const Finger& finger = s.fingers().front();
        bool pressed = false;  // the pad presses on the string, so it rubs there too
        for (std::size_t p = 0; p < finger.pad().size(); ++p) pressed = pressed || finger.normal_force(p) > 0.0;
        EXPECT_TRUE(pressed);
        return std::pair{two.y().friction_dissipated(), two.y().energy()};
    };
    double worst = 0.0, smallest = 0.0, worst_free = 0.0, smallest_free = 0.0;
    const auto [friction, y_energy] = run(0.5, worst, smallest);
    const auto [no_friction, y_energy_free] = run(0.0, worst_free, smallest_free);
    EXPECT_EQ(no_friction, 0.0);
    EXPECT_GT(friction, 0.0);
    EXPECT_GE(smallest, 0.0);
    EXPECT_LT(worst, 1e-10);
    EXPECT_LT(worst_free, 1e-10);
    EXPECT_LT(y_energy, y_energy_free);  // the pad and the fret hold y back
    std::printf("[ numbers  ] finger at fret 5, 45 degrees, friction 0.5, 4e4 steps: balance %.3g, friction %.3g J, "
                "y energy %.3g J (%.3g J without friction)\n",
                worst, friction, y_energy, y_energy_free);
}

}  // namespace
}  // namespace fretbuzz
