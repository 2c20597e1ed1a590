// A phase-only change of a real note is not heard (the bench listens to the run's band-limited
// audio, not to its samples taken without an anti-alias filter). Listening examples either side of the bench's threshold (docs/setup.md, "What is heard"):
// the Jazz Bass's G string at fret 17, plucked by the medium finger pluck grown in size until
// its contacts are heard 3 dB below the masked threshold, and 3 dB above it. The test finds
// the two sizes by bisection on the level, checks that the level was found to 0.5 dB and that
// the louder one touches harder, and writes both notes (1.5 s, the pickup's velocity, as the
// map's WAVs are) to build/tests/listening/ for docs/audio.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <filesystem>
#include <iostream>
#include <limits>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "fretbuzz/input/InstrumentFile.hpp"
#include "fretbuzz/run/Simulation.hpp"
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

// What the bench hears is the run's own band-limited audio (the run is at 1 MHz, its partials
// reach 500 kHz): a phase-only change of a real note (each partial turned by a random angle,
// its amplitude and decay kept: what a touch leaves behind on a linear string) is not heard,
// for E5, D0 and G12 of the Jazz Bass, medium pluck, ten draws each. Sampled from the run
// without an anti-alias filter (the observation rows at 47.6 kHz), the partials above 24 kHz
// fold into the band and beat with those below, and the same change reads far higher
// (printed beside it).
TEST(SetupListening, APhaseOnlyChangeOfARealNoteIsNotHeard) {
    const Instrument bass = load_instrument("jazz-bass");
    const Attack medium = parse_attacks("medium", bass.attack).front();
    const ListeningSettings settings = listening_settings(bass.bench);
    std::mt19937_64 random(55);
    std::uniform_real_distribution<double> angle(0.0, 2.0 * std::numbers::pi);
    for (const auto& [string, fret] : std::vector<std::pair<std::size_t, std::size_t>>{{0, 5}, {2, 0}, {3, 12}}) {
        const NoteMaker maker(bass, string);
        Case clean = maker.stand_in(fret, medium, ensemble(bass.attack, string, fret, 1).front());
        clean.obstacle_height_m.assign(clean.mode_count(), -std::numeric_limits<double>::infinity());
        clean.point_obstacles.clear();  // the frets, at their exact positions
        const std::vector<double> heard = pickup_audio(clean, settings.rate_hz);
        const Listener listener(settings.rate_hz, heard.size(), maker.fundamental_hz(fret), settings);
        const Listener::Clean reference = listener.hear_clean(heard);
        // The rows the run observes, for the unfiltered comparison.
        const auto rows = [](const Case& c) {
            NoteContacts observed({}, {}, false);
            std::vector<RunObserver*> observers{&observed};
            simulate(c, observers);
            return std::pair{observed.signal(), observed.output_rate_hz()};
        };
        const auto [clean_rows, row_rate] = rows(clean);
        const Listener unfiltered(row_rate, clean_rows.size(), maker.fundamental_hz(fret), settings);
        double worst = -std::numeric_limits<double>::infinity(), worst_unfiltered = worst;
        for (int draw = 0; draw < 10; ++draw) {
            Case turned = clean;
            for (std::size_t j = 0; j < clean.mode_count(); ++j) {
                const double omega = 2.0 * std::numbers::pi * clean.modes.frequency_hz[j];
                const double sigma = clean.modes.sigma_per_s[j];
                const double w = std::sqrt(omega * omega - sigma * sigma);
                const double q0 = clean.initial_displacement[j], v0 = clean.initial_velocity[j];
                // u_j(t) = Re(c_j e^{(-sigma + i w) t}), c_j = q0 - i (sigma q0 + v0) / w: turned by a random angle.
                const std::complex<double> c = std::complex<double>(q0, -(sigma * q0 + v0) / w) *
                                               std::polar(1.0, angle(random));
                turned.initial_displacement[j] = c.real();
                turned.initial_velocity[j] = -w * c.imag() - sigma * c.real();
            }
            const double level = listener.added_level(pickup_audio(turned, settings.rate_hz), reference).level_db;
            EXPECT_LT(level, 0.0) << "string " << string << " fret " << fret << " draw " << draw;
            worst = std::max(worst, level);
            worst_unfiltered = std::max(worst_unfiltered, unfiltered.added_level(rows(turned).first, clean_rows).level_db);
        }
        std::cout << bass.strings[string].name << fret << ": a phase-only change reads at most " << worst
                  << " dB over 10 draws (sampled without a filter at " << row_rate << " Hz: " << worst_unfiltered
                  << " dB)\n";
    }
}

}  // namespace
}  // namespace fretbuzz
