// Fretted notes in the real-time engine: the library's Finger pressed behind a fret at run
// time gives the stopped string's pitch, lifting it gives the open string back, and the
// engine's energy ledger (the finger's work and loss included) holds to round-off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "Pitch.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/StoppedString.hpp"
#include "fretbuzz/scheme/HeldString.hpp"
#include "fretbuzz/realtime/Engine.hpp"

namespace fretbuzz {
namespace {

using testing::cents;
using testing::partial_near;

constexpr double kRate = 48000.0;

// Renders `seconds` of audio in blocks of 256, appending to out.
void render(Engine& e, double seconds, std::vector<float>& out) {
    const auto total = static_cast<std::size_t>(seconds * kRate);
    std::vector<float> block(256);
    for (std::size_t done = 0; done < total; done += block.size()) {
        e.process(block);
        out.insert(out.end(), block.begin(), block.end());
    }
}

// A gentle pluck of the sounding part (from the fret to the bridge), 80 % of the way along.
void pluck(Engine& e, int fret) {
    const double stop = e.fret_position_m(fret);
    e.strike({stop + 0.8 * (e.length_m() - stop), 0.2, 0.01, false});
}

// |H + dissipated - work - injected| relative to the largest energy that went through.
double ledger_error(const Engine& e) {
    const double scale = std::max({std::abs(e.injected()), std::abs(e.work()), e.energy(), 1e-300});
    return std::abs(e.energy() + e.dissipated() - e.work() - e.injected()) / scale;
}

class FrettedNote : public ::testing::TestWithParam<int> {};

TEST_P(FrettedNote, SoundsAtTheHeldStringsPitch) {
    // The stiff bass string stopped by the finger on fret k sounds at the held string's first
    // partial (scheme/HeldString.hpp: the string held at x_k, partly clamped there), not at the
    // pinned piece's f_open L / (L - x_k), which lies 2-3.5 cents lower at these frets.
    // bass-neck: bass-pluck's string and neck with modelled modes.
    const int k = GetParam();
    Engine engine(load_case("bass-neck"), {});
    ASSERT_GE(engine.fret_count(), 12);
    ASSERT_TRUE(engine.finger_down(k));
    EXPECT_EQ(engine.fret(), k);
    std::vector<float> out;
    render(engine, 0.02, out);  // the finger presses the string onto the fret (5 ms ramp)
    pluck(engine, k);
    render(engine, 1.0, out);
    const HeldString held(engine.voice_case().modes, engine.length_m(), engine.fret_position_m(k));
    const double expected =
        held.sounding_partials(1, stopping_finger(engine.voice_case(), engine.fret_position_m(k)), engine.voice_case().string.linear_density)
            .frequency_hz[0];
    const double pinned = held.pinned_partials(1).frequency_hz[0];
    const double f = partial_near(out, out.size() - 38400, out.size(), kRate, expected);
    EXPECT_LT(std::abs(cents(f, expected)), 0.5) << f << " Hz, expected " << expected << " Hz";
    std::printf("fret %d: %+.2f cents from the held string, %+.2f from the pinned piece\n", k, cents(f, expected),
                cents(f, pinned));
    EXPECT_EQ(engine.health().resets, 0);
    EXPECT_TRUE(engine.finger_on_string());
}

INSTANTIATE_TEST_SUITE_P(Bass, FrettedNote, ::testing::Values(1, 5, 12));

TEST(RealtimeFinger, TheFretsStayWhereTheCasePutsThem) {
    // The voice drops modes (a coarser grid), but its crowns stay exact points beside the
    // finger: each fret acts, and the finger stops the string, at the case's x_n.
    const Case c = load_case("bass-pluck");
    Engine engine(c, {});
    ASSERT_LT(engine.voice_case().mode_count(), c.mode_count());
    ASSERT_EQ(static_cast<std::size_t>(engine.fret_count()), c.fret_positions_m.size());
    EXPECT_EQ(engine.voice_case().point_obstacles.size(), c.point_obstacles.size());
    for (int k = 1; k <= engine.fret_count(); ++k)
        EXPECT_EQ(engine.fret_position_m(k), c.fret_positions_m[static_cast<std::size_t>(k - 1)]) << "fret " << k;
}

TEST(RealtimeFinger, LiftingTheFingerReturnsToTheOpenPitch) {
    Engine engine(load_case("bass-pluck"), {});
    std::vector<float> out;
    engine.finger_down(5);
    render(engine, 0.02, out);
    pluck(engine, 5);
    render(engine, 0.3, out);
    engine.finger_up();
    EXPECT_EQ(engine.fret(), 0);
    render(engine, 0.1, out);  // the force falls, the string throws the finger off
    EXPECT_FALSE(engine.finger_on_string());
    const std::size_t from = out.size();
    render(engine, 0.8, out);
    const double f_open = engine.voice_case().modes.frequency_hz.front();
    const double f = partial_near(out, from, out.size(), kRate, f_open);
    EXPECT_LT(std::abs(cents(f, f_open)), 5.0) << f << " Hz, open " << f_open << " Hz";
    EXPECT_EQ(engine.health().resets, 0);
}

TEST(RealtimeFinger, LedgerHoldsToRoundOffOverAFrettedNote) {
    // H + dissipated - W = injected: the pressing force's work W in, the finger's contact loss
    // out, through landing, a new note on another fret, a pluck, a lift and a mute.
    Engine engine(load_case("bass-pluck"), {});
    std::vector<float> out;
    const auto check = [&](double seconds) {
        for (double t = 0.0; t < seconds; t += 256.0 / kRate) {
            render(engine, 256.0 / kRate, out);
            ASSERT_LT(ledger_error(engine), 1e-9);
        }
    };
    engine.finger_down(3);
    check(0.02);
    pluck(engine, 3);
    check(0.2);
    EXPECT_GT(engine.work(), 0.0);
    EXPECT_GT(engine.finger_loss(), 0.0);
    engine.finger_down(7);  // a new note: the finger moves
    pluck(engine, 7);
    check(0.2);
    engine.set_obstacle_offset(0.2e-3);  // more buzz while pressed
    check(0.1);
    engine.finger_up();
    check(0.1);
    EXPECT_FALSE(engine.finger_on_string());
    engine.mute(true);
    check(0.1);
    EXPECT_EQ(engine.health().resets, 0);
    EXPECT_EQ(engine.health().solver_failures, 0);
}

TEST(RealtimeFinger, CaseWithoutFretsHasNoFinger) {
    Engine engine(load_case("sitar"), {});  // a bridge, no fret
    EXPECT_EQ(engine.fret_count(), 0);
    EXPECT_FALSE(engine.finger_down(3));
    EXPECT_EQ(engine.fret(), 0);
    EXPECT_GT(engine.health().clamped, 0);
}
}  // namespace
}  // namespace fretbuzz
