// The real-time voice of strings on one bridge (BridgeEngine): the offline Assembly's physics,
// its energy ledger through every event, and an audio path that never allocates.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <span>
#include <vector>

#include "../TestSupport.hpp"
#include "AllocationCounter.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/StringsCaseFile.hpp"
#include "fretbuzz/realtime/BridgeEngine.hpp"
#include "fretbuzz/scheme/Assembly.hpp"
#include "fretbuzz/scheme/Plan.hpp"

namespace fretbuzz {
namespace {

constexpr double kRate = 48000.0;

StringsCase load_strings(const char* name) { return parse_strings_case(*read_strings_case_text(name)); }

// |H + dissipated - work - injected| relative to the largest energy that went through.
double ledger_error(const BridgeEngine& e) {
    const double scale = std::max({std::abs(e.injected()), std::abs(e.work()), e.energy(), 1e-300});
    return std::abs(e.energy() + e.dissipated() - e.work() - e.injected()) / scale;
}

// The offline Assembly of the voice's own cases (its strings cut to the internal band), at the
// voice's internal rate, from the cases' initial state: the sum of the strings' pickups, step
// by step from step 2 (the voice took the first step at set-up).
std::vector<double> offline_pickups(const BridgeEngine& e, const StringsCase& sc, long steps) {
    const double dt = 1.0 / e.internal_rate_hz();
    std::vector<Case> cases;
    std::vector<std::unique_ptr<Plan>> plans;
    std::vector<Assembly::OnBridge> on_bridge;
    std::vector<std::vector<double>> rows;
    for (std::size_t s = 0; s < e.string_count(); ++s) {
        Case c = e.string_case(s);
        if (e.fret_count(s) > 0) c.fingers.pop_back();  // the voice's fretting finger, lifted
        cases.push_back(c);
    }
    for (const Case& c : cases) {
        plans.push_back(std::make_unique<Plan>(c, dt));
        on_bridge.push_back({plans.back().get(), c.string, c.initial_displacement, c.initial_velocity});
        rows.push_back(plans.back()->basis().mode_shapes_at(c.observation_points_m.front()));
        plans.back()->orient(rows.back());
    }
    Assembly assembly(on_bridge, sc.bridge);
    assembly.step();
    std::vector<double> u;
    for (long n = 0; n < steps; ++n) {
        assembly.step();
        double sum = 0.0;
        for (std::size_t s = 0; s < cases.size(); ++s) sum += assembly.string(s).modes().at(rows[s].data());
        u.push_back(sum);
    }
    return u;
}

TEST(BridgeEngine, EqualsTheOfflineAssemblyBeforeDecimation) {
    // The sitar's main string buzzes on its jawari from the start; the guitar's pick strums at
    // 10 ms with two fingers down (the cases' own gestures and fingers, kept from the case).
    for (const char* name : {"sitar-taraf", "guitar-chord"}) {
        SCOPED_TRACE(name);
        const StringsCase sc = load_strings(name);
        BridgeEngineOptions o;
        o.engine.start_from_case = true;
        o.engine.oversampling = 8;  // 384 kHz
        BridgeEngine engine(sc, o);
        const long steps = 6000;
        std::vector<double> live(static_cast<std::size_t>(steps));
        engine.render_internal(live);
        const std::vector<double> offline = offline_pickups(engine, sc, steps);
        const double error = testing::relative_l2(live, offline);
        std::printf("%s: relative L2 %.3e over %ld steps\n", name, error, steps);
        EXPECT_LT(error, 1e-9);
        EXPECT_LT(std::abs(engine.energy() + engine.dissipated() - engine.work() - engine.injected()),
                  1e-9 * std::max(engine.injected(), std::abs(engine.work())));
    }
}

TEST(BridgeEngine, BalanceHoldsThroughBlocksWithAFingerDown) {
    // The A string fretted at 2 and struck; its energy passes to the other strings through the
    // bridge; H + dissipated - work equals what the events put in, block after block.
    BridgeEngine guitar(load_strings("guitar-chord"));
    ASSERT_EQ(guitar.string_count(), 6u);
    ASSERT_GE(guitar.fret_count(1), 12);
    ASSERT_TRUE(guitar.finger_down(1, 2));
    std::vector<float> block(256);
    for (int b = 0; b < 4; ++b) guitar.process(block);  // the finger presses (5 ms ramp)
    const double stop = guitar.fret_position_m(1, 2);
    guitar.strike(1, {stop + 0.8 * (guitar.length_m(1) - stop), 0.5, 0.01, false});
    double worst = 0.0;
    for (int b = 0; b < 40; ++b) {
        guitar.process(block);
        worst = std::max(worst, ledger_error(guitar));
    }
    std::printf("worst ledger error %.3e of %.3e J put in\n", worst, guitar.injected());
    EXPECT_LT(worst, 1e-10);
    EXPECT_TRUE(guitar.finger_on_string(1));
    EXPECT_EQ(guitar.fret(1), 2);
    EXPECT_EQ(guitar.health().resets, 0);
    // The others took up energy through the bridge (no other way in).
    for (std::size_t s : {0u, 2u, 5u}) EXPECT_GT(guitar.assembly().string_energy(s), 0.0) << s;
    double peak = 0.0;
    for (float y : block) peak = std::max(peak, static_cast<double>(std::abs(y)));
    EXPECT_GT(peak, 1e-4);
}

TEST(BridgeEngine, AStrikeAndAStopKeepTheBalanceExact) {
    // A strike changes the main string's state between steps; the assembly takes its bridge end
    // anew, so the bridge's next pull sees it and H + dissipated - work stays what the events
    // put in, to round-off, block after block; a stop (every string at rest, the bridge ringing
    // on) too.
    BridgeEngine sitar(load_strings("sitar-taraf"));
    std::vector<float> block(256);
    double worst = 0.0;
    for (int round = 0; round < 2; ++round) {
        sitar.strike(0, {0.63, 0.5, 0.01, false});
        sitar.strike(5, {0.2, 0.05, 0.01, false});
        for (int b = 0; b < 8; ++b) {
            sitar.process(block);
            worst = std::max(worst, ledger_error(sitar));
        }
        sitar.stop();
        sitar.process(block);
        worst = std::max(worst, ledger_error(sitar));
    }
    std::printf("strikes and stops: worst ledger error %.3e of %.3e J put in\n", worst, sitar.injected());
    EXPECT_LT(worst, 1e-11);
    EXPECT_EQ(sitar.health().resets, 0);
}

TEST(BridgeEngine, AMutedStringFallsSilentAndTheBalanceHolds) {
    // The guitar's A string struck, then muted: within 50 ms it holds under a thousandth of its
    // energy, while a string left alone keeps ringing from what the bridge gave it; the damping
    // changes are events like any other, so the ledger stays at round-off through them.
    BridgeEngine guitar(load_strings("guitar-chord"));
    std::vector<float> block(240);  // 5 ms
    guitar.strike(1, {0.55, 0.5, 0.01, false});
    for (int b = 0; b < 4; ++b) guitar.process(block);
    const double before = guitar.assembly().string_energy(1);
    guitar.mute(1, true);
    EXPECT_TRUE(guitar.muted(1));
    double worst = ledger_error(guitar);
    for (int b = 0; b < 10; ++b) {
        guitar.process(block);
        worst = std::max(worst, ledger_error(guitar));
    }
    const double muted = guitar.assembly().string_energy(1);
    guitar.mute(1, false);
    guitar.set_damping_scale(0.5);
    for (int b = 0; b < 4; ++b) {
        guitar.process(block);
        worst = std::max(worst, ledger_error(guitar));
    }
    std::printf("muted A string: %.3e J -> %.3e J in 50 ms; worst ledger error %.3e\n", before, muted, worst);
    EXPECT_LT(muted, 1e-3 * before);
    EXPECT_LT(worst, 1e-10);
    EXPECT_EQ(guitar.health().resets, 0);
}

TEST(BridgeEngine, AudioPathNeverAllocates) {
    BridgeEngine guitar(load_strings("guitar-chord"));
    BridgeEngine sitar(load_strings("sitar-taraf"));
    std::vector<float> block(1024);
    const long before = testing::allocations();
    {
        const testing::Counting counting;
        guitar.finger_down(1, 2);
        guitar.finger_down(2, 2);
        guitar.process(std::span<float>(block).first(256));
        for (std::size_t s = 0; s < 6; ++s) guitar.strike(s, {0.55, 0.8, 0.01, false});
        guitar.process(block);
        guitar.finger_down(1, 5);  // a new note: the finger moves
        guitar.strike(1, {0.5, 2e-3, 0.01, true});
        guitar.process(std::span<float>(block).first(300));
        guitar.finger_up(2);
        guitar.process(block);
        guitar.process(block);
        guitar.finger_down(3, 0);
        guitar.stop();
        guitar.process(std::span<float>(block).first(7));
        sitar.strike(0, {0.63, 0.5, 0.01, false});
        sitar.strike(4, {0.2, 0.1, 0.01, false});
        sitar.process(block);
        sitar.mute(0, true);  // a damping change forms the bridge end's loads again, in place
        sitar.set_damping_scale(2.0);
        sitar.process(block);
        sitar.mute(0, false);
        sitar.finger_down(0, 3);  // no frets: refused
        sitar.stop();
        sitar.process(block);
    }
    EXPECT_EQ(testing::allocations() - before, 0);
    EXPECT_EQ(guitar.health().resets, 0);
    EXPECT_EQ(sitar.health().resets, 0);
}

TEST(BridgeEngine, BadOptionsNameTheOption) {
    const StringsCase sc = load_strings("guitar-chord");
    const auto message = [&](const BridgeEngineOptions& o) {
        try {
            BridgeEngine e(sc, o);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    BridgeEngineOptions played;
    played.played = 6;
    EXPECT_NE(message(played).find("played string"), std::string::npos) << message(played);
    BridgeEngineOptions rate;
    rate.engine.host_rate_hz = 100.0;
    EXPECT_NE(message(rate).find("host rate"), std::string::npos) << message(rate);
    BridgeEngineOptions gain;
    gain.bridge_gain_per_m_s = -1.0;
    EXPECT_NE(message(gain).find("bridge gain"), std::string::npos) << message(gain);
    BridgeEngineOptions m;
    m.engine.oversampling = 65;
    EXPECT_NE(message(m).find("oversampling"), std::string::npos) << message(m);
}

TEST(BridgeEngine, CuttingTheTarafStringsModesChangesTheSoundLittle) {
    // max_free_modes cuts the strings that touch nothing (the taraf: 40 modes, all below the
    // host band). One second of the sitar struck once, against every mode kept: at 20 modes
    // the output moves by 6.3e-4 (relative L2), at 10 by 3.0e-3; the taraf's energy at 1 s by
    // 0.4 % and 1.9 % (docs/performance.md gives the speed it buys).
    const StringsCase sc = load_strings("sitar-taraf");
    std::vector<std::vector<double>> outs;
    std::vector<double> taraf;
    for (const std::size_t cap : {std::size_t{0}, std::size_t{20}, std::size_t{10}}) {
        BridgeEngineOptions o;
        o.max_free_modes = cap;
        BridgeEngine e(sc, o);
        if (cap > 0) {
            EXPECT_EQ(e.mode_count(1), cap);
        }
        e.strike(0, {0.63, 0.5, 0.01, false});
        std::vector<float> block(256);
        outs.emplace_back();
        for (int b = 0; b < 188; ++b) {
            e.process(block);
            outs.back().insert(outs.back().end(), block.begin(), block.end());
        }
        double sum = 0.0;
        for (std::size_t s = 1; s < e.string_count(); ++s) sum += e.assembly().string_energy(s);
        taraf.push_back(sum);
        EXPECT_EQ(e.health().resets, 0);
    }
    const double at20 = testing::relative_l2(outs[1], outs[0]), at10 = testing::relative_l2(outs[2], outs[0]);
    std::printf("relative L2 of the output: %.2e at 20 modes, %.2e at 10; taraf energy %+.2f %%, %+.2f %%\n", at20, at10,
                100.0 * (taraf[1] / taraf[0] - 1.0), 100.0 * (taraf[2] / taraf[0] - 1.0));
    EXPECT_GT(at20, 0.0);
    EXPECT_LT(at20, 1e-3);
    EXPECT_LT(at20, at10);  // fewer modes, farther
    EXPECT_NEAR(taraf[1] / taraf[0], 1.0, 0.01);
}

}  // namespace
}  // namespace fretbuzz
