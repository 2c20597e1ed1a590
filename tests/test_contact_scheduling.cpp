// Skipping points that provably cannot touch, and jumping over stretches where nothing can,
// must not change the results: the fast path and the straightforward path (every point
// solved at every step) agree to round-off, on the paper's case and on random cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

#include "TestSupport.hpp"
#include "fretbuzz/geometry/InitialShape.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/numerics/ModalBasis.hpp"
#include "fretbuzz/scheme/FreeFlight.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

class Recorder : public RunObserver {
public:
    void observation(double, std::span<const double> u) override { signal.insert(signal.end(), u.begin(), u.end()); }
    void energy(double, double h, double, double d) override { balance.push_back(h + d); }
    std::vector<double> signal, balance;
};

struct Outcome {
    std::vector<double> signal, balance;
    RunSummary summary;
};

Outcome simulate_with(const Case& c, bool screen) {
    Recorder recorder;
    RunObserver* observers[] = {&recorder};
    RunOptions options;
    options.plan.screen_contacts = screen;
    Outcome o;
    o.summary = simulate(c, observers, options);
    o.signal = std::move(recorder.signal);
    o.balance = std::move(recorder.balance);
    return o;
}

using testing::relative_l2;

void expect_same_results(const Case& c) {
    const Outcome fast = simulate_with(c, true);
    const Outcome plain = simulate_with(c, false);
    ASSERT_EQ(fast.signal.size(), plain.signal.size());
    EXPECT_GT(plain.summary.contact_steps, 0) << c.name << ": the case must exercise contact";
    EXPECT_EQ(fast.summary.contact_steps, plain.summary.contact_steps) << c.name;
    EXPECT_LT(relative_l2(fast.signal, plain.signal), 1e-9) << c.name;
    for (std::size_t k = 0; k < fast.balance.size(); ++k)
        ASSERT_NEAR(fast.balance[k], plain.balance[k], 1e-10 * plain.balance.front()) << c.name << " row " << k;
    // And the fast path really skipped work.
    EXPECT_LT(fast.summary.mean_points_solved, 0.5 * plain.summary.mean_points_solved) << c.name;
}

TEST(ContactScheduling, BassPopUnchangedByScreeningAndFreeFlight) {
    Case c = load_case("bass-pop");
    c.run.sample_rate_hz = 400000.0;
    c.run.duration_s = 0.03;
    c.run.output_rate_hz = 20000.0;
    expect_same_results(c);
}

// A finger pressing the string onto a fret pushes at every step: the speed bound then grows
// by the pad's push weights at every step and is recomputed once it passes 1.25x of the last
// full one (a looser bound wakes the other frets' points earlier). The results must not change.
TEST(ContactScheduling, FrettedPopUnchangedByScreening) {
    Case c = load_case("bass-fret5-pop");
    c.run.sample_rate_hz = 400000.0;
    c.run.duration_s = 0.04;  // pressed, pulled from 0.02 s, released at 0.03 s
    c.run.output_rate_hz = 20000.0;
    const Outcome fast = simulate_with(c, true);
    const Outcome plain = simulate_with(c, false);
    ASSERT_EQ(fast.signal.size(), plain.signal.size());
    EXPECT_GT(plain.summary.contact_steps, 0);
    EXPECT_EQ(fast.summary.contact_steps, plain.summary.contact_steps);
    EXPECT_LT(relative_l2(fast.signal, plain.signal), 1e-9);
    for (std::size_t k = 0; k < fast.balance.size(); ++k)
        ASSERT_NEAR(fast.balance[k], plain.balance[k], 1e-10 * std::abs(plain.balance.back())) << "row " << k;
}

// A random stiff, damped string over a random profile of bumps and points, plucked so
// that it hits some of them.
Case random_case(std::mt19937& rng) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    Case c;
    c.name = "random";
    const std::size_t modes = 40 + static_cast<std::size_t>(160 * unit(rng));
    c.string = {0.5 + 0.5 * unit(rng), 50.0 + 200.0 * unit(rng), 1e-3 + 5e-3 * unit(rng)};
    const double f0 = std::sqrt(c.string.tension_n / c.string.linear_density) / (2.0 * c.string.length_m);
    const double inharmonicity = 1e-5 * unit(rng);
    for (std::size_t j = 1; j <= modes; ++j) {
        const double jj = static_cast<double>(j);
        c.modes.frequency_hz.push_back(f0 * jj * std::sqrt(1.0 + inharmonicity * jj * jj));
        c.modes.sigma_per_s.push_back(unit(rng) < 0.2 ? 0.0 : 0.5 + 1e-3 * jj * jj * unit(rng));
        c.modes.source.push_back(ModeSource::model);
    }
    const Grid grid{c.string.length_m, modes};
    const double amplitude = 1e-3 + 3e-3 * unit(rng);
    const std::vector<double> shape = triangle_shape(grid, (0.2 + 0.6 * unit(rng)) * c.string.length_m, amplitude);
    c.obstacle_height_m.assign(modes, -std::numeric_limits<double>::infinity());
    for (int bump = 0; bump < 6; ++bump) {
        const double centre = unit(rng) * c.string.length_m, width = 0.05 * unit(rng) * c.string.length_m;
        const double top = -amplitude * (0.2 + 0.7 * unit(rng));
        for (std::size_t i = 0; i < modes; ++i) {
            const double x = grid.x(i);
            if (std::abs(x - centre) <= width) c.obstacle_height_m[i] = std::max(c.obstacle_height_m[i], top);
        }
    }
    for (std::size_t i = 0; i < modes; ++i)  // a floor far below, and no penetration at rest
        c.obstacle_height_m[i] = std::min(std::max(c.obstacle_height_m[i], -0.02), shape[i]);
    const ModalBasis basis(c.string.length_m, modes);
    c.initial_displacement.resize(modes);
    basis.to_modes(shape, c.initial_displacement);
    c.initial_velocity.assign(modes, 0.0);
    c.contact = {std::pow(10.0, 6.0 + 8.0 * unit(rng)), 1.0 + 1.5 * unit(rng)};
    c.run.sample_rate_hz = std::round(20.0 * c.modes.frequency_hz.back() * (0.05 + unit(rng)));
    c.run.duration_s = 6.0 / f0;
    c.run.output_rate_hz = c.run.sample_rate_hz / 17.0;
    c.observation_points_m = {0.37 * c.string.length_m, 0.9 * c.string.length_m};
    return c;
}

TEST(ContactScheduling, RandomCasesUnchangedByScreeningAndFreeFlight) {
    std::mt19937 rng(20171);
    for (int trial = 0; trial < 12; ++trial) {
        Case c = random_case(rng);
        c.name = "random case " + std::to_string(trial);
        expect_same_results(c);
    }
}

// The envelope that parks a point: |u(x_i, t)| <= sum_j |phi_j(x_i)| R_j over the whole free
// motion from the state where the amplitudes R_j were taken, damped modes and lossless ones.
TEST(ContactScheduling, FreeMotionStaysWithinItsEnvelope) {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 4; ++trial) {
        Case c = random_case(rng);
        c.obstacle_height_m.assign(c.mode_count(), -std::numeric_limits<double>::infinity());
        const Plan plan(c, 1.0 / c.run.sample_rate_hz);
        Stepper s(plan, c.initial_displacement, c.initial_velocity);
        s.step();
        std::vector<double> amplitude(c.mode_count());
        plan.propagator().free_amplitudes(s.modal_displacement(), s.modal_difference(), amplitude);
        std::vector<double> envelope(c.mode_count(), 0.0);
        for (std::size_t i = 0; i < c.mode_count(); ++i)
            for (std::size_t j = 0; j < c.mode_count(); ++j) envelope[i] += std::abs(plan.basis().row(i)[j]) * amplitude[j];
        double closest = 0.0;  // largest |u_i| / E_i met
        for (int n = 0; n < 20000; ++n) {
            s.step();
            for (std::size_t i = 0; i < c.mode_count(); i += 7)
                closest = std::max(closest, std::abs(s.displacement(plan.basis().row(i))) / envelope[i]);
        }
        EXPECT_LE(closest, 1.0 + 1e-12) << "trial " << trial;
        EXPECT_GT(closest, 0.3) << "trial " << trial << ": the envelope should not be far above the motion";
    }
}

// The same case on the fast path (screening, and flights of a few steps as a run makes them)
// and on the straightforward one (every point solved every step), stepped side by side.
struct SideBySide {
    static PlanOptions unscreened() {
        PlanOptions o;
        o.screen_contacts = false;
        return o;
    }
    explicit SideBySide(const Case& c)
        : fast_plan(c, 1.0 / c.run.sample_rate_hz),
          plain_plan(c, 1.0 / c.run.sample_rate_hz, unscreened()),
          fast(fast_plan, c.initial_displacement, c.initial_velocity),
          plain(plain_plan, c.initial_displacement, c.initial_velocity),
          flight(fast_plan.propagator(), kStride) {}
    // Runs both to `steps`; after each step that is not a flight, seen(stepper).
    template <class Seen>
    void run(long steps, Seen&& seen) {
        fast.step();
        plain.step();
        while (fast.step_index() < steps) {
            if (fast.step_index() % kStride != 0 || fast.free_flight(flight, 16, {}, rows, nullptr) == 0) {
                fast.step();
                seen(fast);
            }
            while (plain.step_index() < fast.step_index()) {
                plain.step();
                seen(plain);
            }
        }
    }
    double difference() const {  // relative L2 of the modal displacements
        const auto vec = [](std::span<const double> q) { return std::vector<double>(q.begin(), q.end()); };
        return relative_l2(vec(fast.modal_displacement()), vec(plain.modal_displacement()));
    }
    static constexpr long kStride = 17;
    const Plan fast_plan, plain_plan;
    Stepper fast, plain;
    const FreeFlight flight;
    std::vector<double> rows;
};

// Rings of ten periods over random obstacles: points parked by the envelope come back at the
// next impulse, and the motion stays the one of every point solved at every step. (Longer,
// the two paths part as any two roundings of a buzzing string do: their difference grows
// smoothly, about tenfold per period in the worst of these cases.)
TEST(ContactScheduling, ParkedPointsComeBackAtTheNextImpulse) {
    std::mt19937 rng(4242);
    long parks = 0, releases = 0;
    for (int trial = 0; trial < 8; ++trial) {
        const Case c = random_case(rng);
        SideBySide s(c);
        s.run(10 * std::lround(c.run.sample_rate_hz * 2.0 * c.string.length_m /
                               std::sqrt(c.string.tension_n / c.string.linear_density)),
              [](const Stepper&) {});
        EXPECT_LT(s.difference(), 1e-9) << "trial " << trial;
        EXPECT_NEAR(s.fast.energy() + s.fast.dissipated(), s.plain.energy() + s.plain.dissipated(), 1e-10 * s.plain.energy())
            << trial;
        EXPECT_EQ(s.fast.statistics().contact_steps, s.plain.statistics().contact_steps) << "trial " << trial;
        parks += s.fast.scheduler().parks();
        releases += s.fast.scheduler().releases();
    }
    std::printf("points parked %ld times, released %ld times\n", parks, releases);
    EXPECT_GT(parks, 0);
    EXPECT_GT(releases, 0);
}

// A point the first free motion cannot reach is parked; the bounce on another point reshapes
// the string (the same energy spread over more modes), which then reaches the parked point after
// all. The parked point must be back in the checks by then: the fast path still touches it at
// the same steps as the straightforward one.
TEST(ContactScheduling, ParkedPointComesBackWhenABounceReshapesTheString) {
    Case c;
    c.name = "bounce";
    const std::size_t modes = 59;  // grid x_i = (i + 1) L / 60: the middle and the quarter are on it
    c.string = {0.65, 100.0, 5e-3};
    const double f0 = std::sqrt(c.string.tension_n / c.string.linear_density) / (2.0 * c.string.length_m);
    for (std::size_t j = 1; j <= modes; ++j) {
        c.modes.frequency_hz.push_back(f0 * static_cast<double>(j));
        c.modes.sigma_per_s.push_back(0.0);
        c.modes.source.push_back(ModeSource::model);
    }
    const double a = 1e-3, norm = std::sqrt(2.0 / c.string.length_m);
    const std::size_t bounce = 40, quarter = 14;
    const auto first_mode = [&](std::size_t i) { return a * std::sin(std::numbers::pi * static_cast<double>(i + 1) / 60.0); };
    c.obstacle_height_m.assign(modes, -std::numeric_limits<double>::infinity());
    c.obstacle_height_m[bounce] = -0.8 * first_mode(bounce);
    // Just out of reach of the first mode alone; the bounce makes the quarter point swing
    // about 0.3 % further (measured: 1.0034 times the first mode's amplitude there).
    c.obstacle_height_m[quarter] = -1.001 * first_mode(quarter);
    c.initial_displacement.assign(modes, 0.0);
    c.initial_displacement[0] = a / norm;
    c.initial_velocity.assign(modes, 0.0);
    c.contact = {1e9, 1.5};
    c.run.sample_rate_hz = 200.0 * c.modes.frequency_hz.back();
    SideBySide s(c);
    long quarter_fast = 0, quarter_plain = 0;  // steps with a force on the quarter point
    s.run(4 * std::lround(c.run.sample_rate_hz / f0), [&](const Stepper& stepper) {
        for (const auto& [i, f] : stepper.forces())
            if (i == quarter) ++(&stepper == &s.fast ? quarter_fast : quarter_plain);
    });
    EXPECT_GT(quarter_plain, 0) << "the reshaped string must reach the quarter point";
    EXPECT_EQ(quarter_fast, quarter_plain);
    EXPECT_GT(s.fast.scheduler().parks(), 0);
    EXPECT_LT(s.difference(), 1e-9);
}

TEST(ContactScheduling, ChosenWithoutScreeningWhereTheStringRestsOnAFewPoints) {
    // The sitar's bridge (12 grid points within a micrometre of the rest line) and the
    // tanpura's point: screening is turned off automatically, said so in the summary, and
    // the result is the screened one to round-off.
    for (const char* name : {"sitar", "tanpura"}) {
        Case c = load_case(name);
        c.run.duration_s = 0.02;
        Recorder automatic, forced;
        RunObserver* a[] = {&automatic};
        RunObserver* f[] = {&forced};
        const RunSummary chosen = simulate(c, a);
        RunOptions on;
        on.plan.choose_screening = false;
        const RunSummary screened = simulate(c, f, on);
        EXPECT_FALSE(chosen.screened) << name;
        EXPECT_NE(chosen.screening.find("automatic"), std::string::npos) << chosen.screening;
        EXPECT_TRUE(screened.screened) << name;
        EXPECT_GT(chosen.contact_steps, 100) << name;
        EXPECT_EQ(chosen.contact_steps, screened.contact_steps) << name;
        EXPECT_LT(relative_l2(forced.signal, automatic.signal), 1e-9) << name;
    }
    // Many points (the bass frets): screening stays on.
    Case bass = load_case("bass-pop");
    bass.run.duration_s = 1e-4;
    EXPECT_TRUE(simulate(bass, {}).screened);
}

TEST(ContactScheduling, TransformThresholdFollowsThePlannedCost) {
    // N = 862 (N + 1 prime) plans a much costlier transform than N = 863 (864 = 2^5 3^3):
    // rows of S stay the cheaper way to many more points there.
    Case c = load_case("tanpura");
    auto threshold = [&](std::size_t modes) {
        const ModalBasis basis(c.string.length_m, modes);
        return Plan::default_transform_threshold(modes, basis.transform_flops());
    };
    EXPECT_GT(threshold(862), 3 * threshold(863));
    EXPECT_GT(threshold(1600), 2 * threshold(1599));  // 1601 prime, 1600 = 2^6 5^2
}


// The arrays the kernels sweep at every step start on a cache line (numerics/CacheAligned.hpp):
// with malloc's 16-byte alignment a step's vector loads straddled two lines or not as the
// heap's layout fell, which moved the bass pop's speed between builds.
TEST(ContactScheduling, TheArraysTheKernelsSweepStartOnACacheLine) {
    const Case c = load_case("bass-pop");
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    Stepper s(plan, c.initial_displacement, c.initial_velocity);
    s.step();
    const auto on_a_line = [](std::span<const double> a) { return reinterpret_cast<std::uintptr_t>(a.data()) % 64 == 0; };
    EXPECT_TRUE(on_a_line(s.modal_displacement()));
    EXPECT_TRUE(on_a_line(s.modal_difference()));
    EXPECT_TRUE(on_a_line(plan.propagator().decay()));
    EXPECT_TRUE(on_a_line(plan.propagator().beta()));
    EXPECT_TRUE(on_a_line(plan.propagator().loss()));
    for (std::size_t i : {std::size_t{0}, c.mode_count() / 3, c.mode_count() - 1}) EXPECT_TRUE(on_a_line(plan.basis().row(i))) << i;
}

}  // namespace
}  // namespace fretbuzz
