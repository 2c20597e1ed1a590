// The real-time engine: the same scheme as the offline run, energy bookkeeping of every event,
// and an audio path that never allocates nor produces a non-finite sample.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <span>
#include <vector>

#include "../TestSupport.hpp"
#include "AllocationCounter.hpp"
#include "Pitch.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/StoppedString.hpp"
#include "fretbuzz/scheme/HeldString.hpp"
#include "fretbuzz/realtime/Decimator.hpp"
#include "fretbuzz/realtime/Engine.hpp"
#include "fretbuzz/run/ResultRecorder.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/numerics/SineTransform.hpp"

namespace fretbuzz {
namespace {

using testing::relative_l2;

// The offline run of `c` at rate fs, one row per step, at the case's first observation point.
std::vector<double> offline_signal(Case c, double fs, long steps) {
    c.run.sample_rate_hz = fs;
    c.run.duration_s = static_cast<double>(steps) / fs;
    c.run.output_rate_hz.reset();  // native: one row per step from t = 0
    ResultRecorder recorder;
    RunObserver* observers[] = {&recorder};
    simulate(c, observers);
    std::vector<double> u;
    const RecordedRun& run = recorder.run();
    for (std::size_t n = 0; n < run.time.size(); ++n) u.push_back(run.observation[n * run.point_count()]);
    return u;
}

TEST(RealtimeEngine, EqualsTheOfflineRunBeforeDecimation) {
    // The tanpura buzzes on its point obstacle about once a period: contact from the start.
    for (const char* name : {"tanpura", "bass-pop"}) {
        SCOPED_TRACE(name);
        const Case c = load_case(name);
        EngineOptions o;
        o.start_from_case = true;
        o.free_flight = false;
        o.oversampling = 8;  // 384 kHz
        Engine engine(c, o);
        ASSERT_EQ(engine.mode_count(), std::string(name) == "tanpura" ? c.mode_count() : engine.mode_count());
        const long steps = 20000;
        std::vector<double> live(static_cast<std::size_t>(steps));
        engine.render_internal(live);
        // The engine took the first step at set-up: its samples are steps 2, 3, ...
        Case same = engine.voice_case();
        if (engine.fret_count() > 0) same.fingers.pop_back();  // the engine's finger, lifted
        const std::vector<double> offline = offline_signal(same, engine.internal_rate_hz(), steps + 1);
        const std::vector<double> reference(offline.begin() + 2, offline.begin() + 2 + steps);
        EXPECT_LT(relative_l2(live, reference), 1e-9);
    }
}

TEST(RealtimeEngine, FrettedNoteEqualsTheOfflineRunWithTheSameFinger) {
    // finger_down(5) right after set-up (step 1) lands the finger as the offline run starts
    // the same finger (at rest on the string at step 1) with its force ramped from then on.
    const Case c = load_case("bass-pop");
    EngineOptions o;
    o.start_from_case = true;
    o.free_flight = false;
    o.oversampling = 8;  // 384 kHz
    Engine engine(c, o);
    ASSERT_TRUE(engine.finger_down(5));
    const long steps = 20000;
    std::vector<double> live(static_cast<std::size_t>(steps));
    engine.render_internal(live);
    Case offline_case = engine.voice_case();
    offline_case.fingers.pop_back();  // the engine's own (lifted) finger ...
    FingerSpec finger = offline_case.fret_finger(5, "fret");  // ... as `fret = 5` puts it
    const double dt = 1.0 / engine.internal_rate_hz();
    const double ramp = finger.force_profile.back()[0];
    finger.force_profile = {{dt, 0.0}, {dt + ramp, finger.force_profile.back()[1]}};
    finger.default_force = false;
    offline_case.fingers.push_back(finger);
    const std::vector<double> offline = offline_signal(offline_case, engine.internal_rate_hz(), steps + 1);
    const std::vector<double> reference(offline.begin() + 2, offline.begin() + 2 + steps);
    EXPECT_LT(relative_l2(live, reference), 1e-9);
    EXPECT_GT(engine.work(), 0.0);  // the finger pressed
}

TEST(RealtimeEngine, ChoosesTheRateThatKeepsEveryModeBelowNyquist) {
    const Case c = load_case("tanpura");  // top mode near 160 kHz
    Engine engine(c, {});
    const double top = c.modes.frequency_hz.back();
    EXPECT_EQ(engine.mode_count(), c.mode_count());
    EXPECT_LT(top, 0.45 * engine.internal_rate_hz());
    EXPECT_GE(top, 0.45 * (engine.oversampling() - 1) * 48000.0);  // the smallest such factor
    EngineOptions low;
    low.max_oversampling = 2;  // 96 kHz: only the modes below 43.2 kHz are kept
    Engine limited(c, low);
    EXPECT_EQ(limited.oversampling(), 2);
    EXPECT_LT(limited.mode_count(), c.mode_count());
    EXPECT_LT(limited.voice_case().modes.frequency_hz.back(), 0.45 * 96000.0);
}

TEST(RealtimeEngine, KeepsItsPointObstacleWhereTheCasePutsItWithFewerModes) {
    // The tanpura's bridge point, 4 mm from the end: a voice with fewer modes (a coarser grid)
    // keeps it there with the width it had, and its energy balance holds through the contacts.
    const Case c = load_case("tanpura");
    EngineOptions low;
    low.max_oversampling = 2;
    Engine limited(c, low);
    ASSERT_LT(limited.mode_count(), c.mode_count());
    const Case& voice = limited.voice_case();
    ASSERT_EQ(voice.point_obstacles.size(), 1u);
    EXPECT_EQ(voice.point_obstacles[0].x_m, c.point_obstacles[0].x_m);
    EXPECT_EQ(voice.point_obstacles[0].weight_m, c.point_obstacles[0].weight_m);
    EXPECT_EQ(c.point_obstacles[0].x_m, 0.004);
    limited.strike({0.3, 1.0, 0.02, false});
    std::vector<float> block(256);
    for (int b = 0; b < 100; ++b) {
        limited.process(block);
        EXPECT_NEAR((limited.energy() + limited.dissipated()) / limited.injected(), 1.0, 1e-9);
    }
}

TEST(RealtimeEngine, PluckInjectsTheKineticEnergyOfItsVelocity) {
    // A raised-cosine velocity V (1 + cos(pi r)) / 2 of width w on a string at rest carries
    // (mu/2) V^2 (3 w / 8): the engine's discrete energy after the strike is that, to the
    // discretisation of the bump and the damping of half a step.
    const Case c = load_case("guitar-point");
    Engine engine(c, {});
    ASSERT_EQ(engine.energy(), 0.0);
    Strike s;
    s.position_m = 0.2;
    s.width_m = 0.02;
    s.strength = 0.8;
    engine.strike(s);
    const double expected = 0.5 * c.string.linear_density * s.strength * s.strength * 3.0 * s.width_m / 8.0;
    EXPECT_NEAR(engine.energy() / expected, 1.0, 1e-3);
    EXPECT_NEAR(engine.injected(), engine.energy() + engine.dissipated(), 1e-12 * expected);
}

TEST(RealtimeEngine, EnergyOnlyDecreasesBetweenEventsThroughContact) {
    const Case c = load_case("tanpura");
    Engine engine(c, {});
    engine.strike({0.3, 1.0, 0.02, false});
    std::vector<float> block(256);
    double previous = engine.energy();
    for (int b = 0; b < 200; ++b) {
        engine.process(block);
        const double h = engine.energy();
        EXPECT_LE(h, previous * (1.0 + 1e-12));
        previous = h;
        // H + dissipated stays what was put in, to round-off.
        EXPECT_NEAR((engine.energy() + engine.dissipated()) / engine.injected(), 1.0, 1e-9);
    }
    EXPECT_EQ(engine.health().resets, 0);
    // Parameter changes while sounding are counted as input too, and the balance holds on.
    engine.set_contact_law(1e13, 2.0);
    engine.set_damping_scale(3.0);
    engine.set_obstacle_offset(0.2e-3);
    for (int b = 0; b < 50; ++b) engine.process(block);
    EXPECT_NEAR((engine.energy() + engine.dissipated()) / engine.injected(), 1.0, 1e-9);
    EXPECT_EQ(engine.health().resets, 0);
}

// Raising the obstacle toward a string at rest puts no energy in: it rises at most to the
// string's rest line, so nothing penetrates (raised into the string, frets and bridges
// pushed it away with the penetration's energy: a note then peaked hundreds of times louder).
TEST(RealtimeEngine, RaisingTheObstacleIntoARestingStringPutsInNoEnergy) {
    const Case bass = load_case("bass-pluck");
    const Case fifth = stopped_string(bass, fret_position(bass.string.length_m, 5), bass.mode_count());
    const std::vector<Case> cases = {bass, fifth, load_case("sitar"), load_case("tanpura"), load_case("guitar-point")};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        EngineOptions options;
        options.max_oversampling = 4;
        double peaks[2] = {0.0, 0.0};
        for (int raised = 0; raised < 2; ++raised) {
            Engine engine(c, options);
            engine.set_obstacle_offset(raised * 1e-3);  // the most the engine allows
            EXPECT_EQ(engine.injected(), 0.0);
            EXPECT_EQ(engine.energy(), 0.0);
            engine.strike({0.8 * engine.length_m(), 1.0, 0.01, false});
            std::vector<float> block(24000);
            engine.process(block);
            for (float y : block) peaks[raised] = std::max(peaks[raised], std::abs(static_cast<double>(y)));
            EXPECT_EQ(engine.health().resets, 0);
        }
        EXPECT_GT(peaks[0], 0.0);
        EXPECT_LT(peaks[1], 2.0 * peaks[0]);
    }
}

TEST(RealtimeEngine, MuteDampsTheString) {
    Engine engine(load_case("guitar-point"), {});
    engine.strike({0.2, 0.5, 0.02, false});
    std::vector<float> block(480);
    engine.process(block);
    const double before = engine.energy();
    engine.mute(true);
    for (int b = 0; b < 10; ++b) engine.process(block);  // 0.1 s
    EXPECT_LT(engine.energy(), 1e-6 * before);
}

TEST(RealtimeEngine, FreeFlightGivesTheSameAudio) {
    // Flying over host samples steps only the audible modes; after decimation the audio is
    // that of stepping every mode (what flight leaves out lies above the filter's band).
    const Case c = load_case("tanpura");
    EngineOptions fly, step;
    step.free_flight = false;
    Engine a(c, fly), b(c, step);
    for (Engine* e : {&a, &b}) e->strike({0.3, 1.0, 0.02, false});
    std::vector<float> x(24000), y(24000);
    a.process(x);
    b.process(y);
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        num += (x[i] - y[i]) * (x[i] - y[i]);
        den += static_cast<double>(y[i]) * y[i];
    }
    EXPECT_LT(std::sqrt(num / den), 1e-4);
}

TEST(RealtimeEngine, AudioPathNeverAllocates) {
    Engine engine(load_case("bass-pop"), {});
    std::vector<float> block(4096);
    const long before = testing::allocations();
    {
        const testing::Counting counting;
        engine.strike({0.7, 1.5, 0.01, false});
        engine.process(std::span<float>(block).first(256));
        engine.strike({0.6, 2e-3, 0.01, true});  // a pop into the frets
        engine.set_contact_law(1e12, 1.3);
        engine.set_pickup(0.8);
        engine.set_obstacle_offset(0.3e-3);
        engine.process(std::span<float>(block).first(1024));
        engine.set_damping_scale(2.0);
        engine.mute(true);
        engine.process(block);
        engine.mute(false);
        engine.process(std::span<float>(block).first(7));
        // Fingering: a note on fret 5, a new note on fret 7 (the finger moves), a lift, fret 1.
        engine.finger_down(5);
        engine.strike({0.7, 1.0, 0.01, false});
        engine.process(std::span<float>(block).first(512));
        engine.finger_down(7);
        engine.process(std::span<float>(block).first(300));
        engine.set_obstacle_offset(0.1e-3);
        engine.finger_up();
        engine.process(block);
        engine.process(block);
        engine.finger_down(1);
        engine.process(std::span<float>(block).first(256));
        engine.finger_down(0);
        engine.process(std::span<float>(block).first(256));
    }
    EXPECT_EQ(testing::allocations() - before, 0);
}

TEST(RealtimeEngine, SineTransformsNeverAllocate) {
    // A fretboard or a flat obstacle with many points due moves the state to the grid and back
    // by sine transforms inside a block: they run in buffers planned ahead, and FFTW's own
    // algorithms allocate nothing for every length the engine transforms (n + 1 without a prime
    // factor above 31; for the others it evaluates rows of S).
    std::size_t lengths = 0;
    for (std::size_t n = 1; n <= 4096; ++n) {
        if (sine_transform_allocates(n)) continue;
        ++lengths;
        const SineTransform transform(n);
        std::vector<double> x(n, 1.0), y(n);
        const long before = testing::allocations();
        {
            const testing::Counting counting;
            for (int k = 0; k < 2; ++k) transform.apply(x, y, 1.0);
        }
        ASSERT_EQ(testing::allocations() - before, 0) << "n = " << n;
        EXPECT_TRUE(std::isfinite(y[n / 2]));
    }
    EXPECT_GT(lengths, 1000u);
    EXPECT_TRUE(sine_transform_allocates(400));  // 401 is prime: FFTW runs Rader's algorithm
    EXPECT_FALSE(sine_transform_allocates(399));
}

TEST(RealtimeEngine, FuzzedEventsStayFiniteAndNeverAllocate) {
    std::mt19937_64 random(16);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (const char* name : {"tanpura", "sitar", "bass-pop"}) {
        SCOPED_TRACE(name);
        Engine engine(load_case(name), {});
        std::vector<float> block(4096);
        const long before = testing::allocations();
        long samples = 0;
        bool finite = true;
        {
            const testing::Counting counting;
            while (samples < 48000 * 3) {
                // Controller values from anywhere, including out of range and not numbers.
                const auto wild = [&](double low, double high) {
                    const double r = unit(random);
                    if (r < 0.05) return nan;
                    if (r < 0.1) return (unit(random) < 0.5 ? -1.0 : 1.0) * inf;
                    if (r < 0.2) return low - (high - low) * unit(random) * 10.0;
                    return low + (high - low) * unit(random) * 1.2;
                };
                switch (static_cast<int>(unit(random) * 9.0)) {
                    case 0: engine.strike({wild(0.0, 1.0), wild(-2.0, 2.0), wild(0.0, 0.05), unit(random) < 0.3}); break;
                    case 1: engine.mute(unit(random) < 0.5); break;
                    case 2: engine.set_damping_scale(wild(0.0, 5.0)); break;
                    case 3: engine.set_contact_law(std::pow(10.0, wild(6.0, 15.0)), wild(1.0, 3.0)); break;
                    case 4: engine.set_pickup(wild(0.0, 1.0)); break;
                    case 5: engine.set_obstacle_offset(wild(-1e-3, 1e-3)); break;
                    case 6: engine.finger_down(static_cast<int>(unit(random) * 30.0) - 3); break;
                    case 7: engine.finger_up(); break;
                    default: break;
                }
                const auto size = static_cast<std::size_t>(1 + unit(random) * 4095.0);
                const std::span<float> out(block.data(), size);
                engine.process(out);
                for (float y : out) finite = finite && std::isfinite(y);
                samples += static_cast<long>(size);
            }
        }
        EXPECT_TRUE(finite);
        EXPECT_EQ(testing::allocations() - before, 0);
        EXPECT_GT(engine.health().clamped, 0);
    }
}

TEST(Decimator, PassesTheBandAndStopsWhatWouldAlias) {
    const Decimator d(8, 64, 0.45);
    EXPECT_NEAR(d.gain_at(0.0), 1.0, 1e-12);
    for (double f : {0.1, 0.3, 0.4}) EXPECT_NEAR(d.gain_at(f / 8.0), 1.0, 1e-3) << f;  // of the output rate
    for (double f : {0.5, 0.7, 1.5, 3.9}) EXPECT_LT(d.gain_at(f / 8.0), 1e-4) << f;
}

TEST(Decimator, ReportsTheDelayOfItsImpulseResponse) {
    // Linear phase: the centroid of the whole impulse response (every input phase s of the
    // impulse together) lies group_delay() output samples after the impulse.
    for (int m : {1, 2, 4, 8}) {
        double moment = 0.0, area = 0.0;  // in input samples
        for (int s = 0; s < m; ++s) {
            Decimator d(m, 64, 0.45);
            for (int n = 0; n < 64 + 4; ++n) {
                for (int k = 0; k < m; ++k) d.push(n * m + k == s ? 1.0 : 0.0);
                const double lag = n * m + m - 1 - s;  // output n comes after input n M + M - 1
                moment += lag * d.output();
                area += d.output();
            }
        }
        EXPECT_NEAR(moment / area / m, Decimator(m, 64, 0.45).group_delay(), 1e-9) << "M=" << m;
    }
    EXPECT_NEAR(Decimator(8, 64, 0.45).group_delay(), (512.0 - 1.0) / 16.0, 1e-12);
}

TEST(StoppedString, AStoppedVoiceSoundsAtTheHeldStringsPitch) {
    // A plugin voice stopped at fret k (an engine on stopped_string()'s Case, which drops the
    // modes it cannot run) sounds at the held string's first partial (scheme/HeldString.hpp),
    // the stiff string partly clamped on the fret: 2-5 cents above the pinned piece's.
    const Case open = load_case("bass-pluck");
    EXPECT_NEAR(fret_position(open.string.length_m, 12), 0.5 * open.string.length_m, 1e-12);
    for (const int fret : {5, 12}) {
        const double stop = fret_position(open.string.length_m, fret);
        const Case stopped = stopped_string(open, stop, open.mode_count());
        const HeldString held(open.modes, open.string.length_m, stop);
        const double f_held = held.sounding_partials(1, stopping_finger(open, stop), open.string.linear_density).frequency_hz[0];
        const double f_pinned = held.pinned_partials(1).frequency_hz[0];
        Engine engine(stopped, {});
        engine.strike({0.8 * stopped.string.length_m, 0.2, 0.01, false});
        std::vector<float> out(2 * 48000);
        for (std::size_t done = 0; done < out.size(); done += 256) engine.process(std::span<float>(out).subspan(done, 256));
        const double f = testing::partial_near(out, 48000, out.size(), 48000.0, f_held);
        EXPECT_NEAR(testing::cents(f, f_held), 0.0, 0.3) << "fret " << fret;
        EXPECT_GT(testing::cents(f, f_pinned), 1.5) << "fret " << fret;
        EXPECT_LT(testing::cents(f, f_pinned), 6.0) << "fret " << fret;
        std::printf("fret %d: %+.2f cents from the held string, %+.2f from the pinned piece\n", fret,
                    testing::cents(f, f_held), testing::cents(f, f_pinned));
    }
    // The string rests on fret 5: the frets beyond stay below it, the fret under the finger is gone.
    const Case stopped = stopped_string(open, fret_position(open.string.length_m, 5), open.mode_count());
    double highest = -1.0;
    for (double g : stopped.obstacle_height_m)
        if (std::isfinite(g)) highest = std::max(highest, g);
    EXPECT_LT(highest, 0.0);
    EXPECT_FALSE(std::isfinite(stopped.obstacle_height_m[0]));
}

TEST(StoppedString, KeepsEveryFretOnACoarserGrid) {
    // With half the modes the grid step doubles. Crowns of zero width are exact points: each
    // fret keeps its exact position and its top, whatever the mode count.
    const Case open = load_case("bass-pluck");
    ASSERT_EQ(open.point_obstacles.size(), 20u);
    for (const std::size_t modes : {open.mode_count() / 2, std::size_t{110}}) {
        const Case coarse = stopped_string(open, 0.0, modes);
        ASSERT_EQ(coarse.fret_positions_m.size(), open.fret_positions_m.size());
        ASSERT_EQ(coarse.point_obstacles.size(), open.point_obstacles.size());
        for (std::size_t k = 0; k < open.fret_positions_m.size(); ++k) {
            EXPECT_EQ(coarse.fret_positions_m[k], open.fret_positions_m[k]) << k;
            EXPECT_EQ(coarse.point_obstacles[k].x_m, open.point_obstacles[k].x_m) << k;
            EXPECT_EQ(coarse.point_obstacles[k].height_m, open.point_obstacles[k].height_m) << k;
        }
    }
}

TEST(StoppedString, SitarIsStoppedAtTheFarEndAndKeepsItsBridge) {
    const Case open = load_case("sitar");  // the bridge lies at x in [0, 25 mm]
    ASSERT_TRUE(stops_at_far_end(open));
    const Case stopped = stopped_string(open, fret_position(open.string.length_m, 7), open.mode_count());
    // The held string's pitch: a little above the pinned piece's (its stiffness), stopped at x = L.
    EXPECT_GT(testing::cents(stopped.modes.frequency_hz[0], open.modes.frequency_hz[0] * std::exp2(7.0 / 12.0)), 0.0);
    EXPECT_LT(testing::cents(stopped.modes.frequency_hz[0], open.modes.frequency_hz[0] * std::exp2(7.0 / 12.0)), 10.0);
    // The same bridge heights at the same distances from x = 0 (grid of the shorter string).
    for (std::size_t i = 0; i < stopped.mode_count() && stopped.grid_point(i) < 0.02; ++i) {
        const auto k = static_cast<std::size_t>(std::lround(stopped.grid_point(i) / open.grid_step())) - 1;
        EXPECT_EQ(stopped.obstacle_height_m[i], open.obstacle_height_m[k]) << i;
    }
    EXPECT_FALSE(std::isfinite(stopped.obstacle_height_m.back()));
}

}  // namespace
}  // namespace fretbuzz
