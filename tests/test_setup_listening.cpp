// Listening examples either side of the bench's threshold (docs/setup.md, "What is heard"):
// the Jazz Bass's G string at fret 17, plucked by the medium finger pluck grown in size until
// its contacts are heard 3 dB below the masked threshold, and 3 dB above it. The test finds
// the two sizes by bisection on the level, checks that the level was found to 0.5 dB and that
// the louder one touches harder, and writes both notes (1.5 s, the pickup's velocity, as the
// map's WAVs are) to build/tests/listening/ for docs/audio.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>

#include "fretbuzz/input/InstrumentFile.hpp"
#include "fretbuzz/setup/NotePlayer.hpp"

namespace fretbuzz {
namespace {

TEST(SetupListening, ExamplesEitherSideOfTheThreshold) {
    Instrument bass = load_instrument("jazz-bass");
    bass.bench.duration_s = 1.5;
    const std::size_t string = 3, fret = 17;
    const NoteMaker maker(bass, string);
    NotePlayer player(maker, fret, false, listening_settings(bass.bench));
    const Attack medium = parse_attacks("medium", bass.attack).front();
    const PluckVariation member = ensemble(bass.attack, string, fret, 1).front();
    const auto level = [&](double size) {
        const PluckOutcome o = player.play(medium, size, 0, member);
        return o.touched ? o.buzz_db : -std::numeric_limits<double>::infinity();
    };
    // The first touch, then the sizes whose levels are -3 and +3 dB.
    double silent = player.touch_free_size(medium, member), loud = 10e-3;
    ASSERT_GT(level(loud), 3.0);
    const auto find = [&](double target, double low, double high) {
        for (int k = 0; k < 60 && high > low * (1.0 + 1e-12); ++k) {
            const double mid = 0.5 * (low + high);
            (level(mid) < target ? low : high) = mid;
        }
        return high;
    };
    const double below = find(-3.0, silent, loud), above = find(3.0, silent, loud);
    EXPECT_NEAR(level(below), -3.0, 0.5);
    EXPECT_NEAR(level(above), 3.0, 0.5);
    EXPECT_GT(above, below);
    const std::filesystem::path dir = std::filesystem::path(FRETBUZZ_BINARY_DIR) / "listening";
    std::filesystem::create_directories(dir);
    for (const auto& [size, name] : {std::pair{below, "buzz-threshold-below.wav"}, {above, "buzz-threshold-above.wav"}}) {
        PluckOptions with_sound;
        with_sound.wav = dir / name;
        with_sound.keep_details = true;
        const PluckOutcome o = player.play(medium, size, 0, member, with_sound);
        EXPECT_TRUE(std::filesystem::is_regular_file(with_sound.wav));
        std::cout << name << ": medium pluck " << size * 1e3 << " mm, level " << o.buzz_db << " dB, peak force "
                  << o.peak_force_n << " N, first contact at " << o.first_contact_s * 1e3 << " ms\n";
    }
}

}  // namespace
}  // namespace fretbuzz
