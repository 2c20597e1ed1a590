// The listener that judges whether a note's contacts are heard (analysis/Listener): its
// psychoacoustic curves at known points, its indifference to phase (a note whose partials
// ring with other phases adds nothing it can hear, though its waveform differs from the clean
// note as much as the note itself), energy read as energy (a click 10 dB stronger reads
// 10 dB higher), masking (a click under a strong partial is heard less than the same click
// where the note is quiet) and the threshold in quiet (a quieter playback hears less); through
// a rig (analysis/ListeningRig), a click is heard less by what the rig's response predicts
// from the click's spectrum and the note's.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "fretbuzz/analysis/Listener.hpp"

namespace fretbuzz {
namespace {

constexpr double kRate = 48000.0;
constexpr double kF0 = 98.0;  // G2

// A plucked string's pickup signal: partials j f0, amplitudes 1/j^2, each decaying at
// 1 + j/4 per second; with `scramble`, each partial's phase turned by a random angle.
std::vector<double> note(std::size_t samples, int partials = 60, bool scramble = false) {
    std::vector<double> u(samples, 0.0);
    std::mt19937_64 random(11);
    std::uniform_real_distribution<double> angle(0.0, 2.0 * std::numbers::pi);
    for (int j = 1; j <= partials; ++j) {
        const double f = j * kF0, a = 1.0 / (j * j), sigma = 1.0 + 0.25 * j, turn = scramble ? angle(random) : 0.0;
        for (std::size_t n = 0; n < samples; ++n) {
            const double t = static_cast<double>(n) / kRate;
            u[n] += a * std::exp(-sigma * t) * std::sin(2.0 * std::numbers::pi * f * t + turn);
        }
    }
    return u;
}

// A short broadband click (10 ms of white noise, Hann-shaped) of the given rms at `at_s`,
// band-limited to [low, high] Hz by summing sines of random phases.
std::vector<double> click(std::size_t samples, double at_s, double rms, double low = 2000.0, double high = 12000.0) {
    std::vector<double> c(samples, 0.0);
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> phase(0.0, 2.0 * std::numbers::pi);
    const std::size_t start = static_cast<std::size_t>(at_s * kRate), length = static_cast<std::size_t>(0.01 * kRate);
    for (double f = low; f <= high; f += 50.0) {
        const double p = phase(random);
        for (std::size_t n = 0; n < length && start + n < samples; ++n)
            c[start + n] += std::sin(2.0 * std::numbers::pi * f * static_cast<double>(n) / kRate + p);
    }
    double energy = 0.0;
    for (std::size_t n = 0; n < length; ++n) {
        const double w = 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * static_cast<double>(n) / static_cast<double>(length)));
        c[start + n] *= w;
        energy += c[start + n] * c[start + n];
    }
    const double scale = rms / std::sqrt(energy / static_cast<double>(length));
    for (double& v : c) v *= scale;
    return c;
}

std::vector<double> plus(std::vector<double> a, const std::vector<double>& b) {
    for (std::size_t n = 0; n < a.size(); ++n) a[n] += b[n];
    return a;
}

TEST(Listener, ItsCurvesAreThePublishedOnes) {
    EXPECT_NEAR(bark(1000.0), 8.51, 0.01);          // Zwicker & Terhardt 1980
    EXPECT_NEAR(bark(100.0), 0.99, 0.01);
    EXPECT_NEAR(threshold_in_quiet_db(1000.0), 3.37, 0.01);  // Terhardt 1979
    EXPECT_LT(threshold_in_quiet_db(3300.0), -4.0);   // the ear's most sensitive region
    EXPECT_GT(threshold_in_quiet_db(15000.0), 40.0);
    EXPECT_NEAR(masking_spread_db(0.0), 0.0, 0.01);  // Schroeder, Atal & Hall 1979
    // Masking spreads upward in frequency more than downward.
    EXPECT_GT(masking_spread_db(2.0), masking_spread_db(-2.0) + 10.0);
}

TEST(Listener, ANoteWhosePartialsDriftOutOfPhaseAddsNothingHeard) {
    const std::size_t samples = static_cast<std::size_t>(0.3 * kRate);
    const std::vector<double> clean = note(samples);
    // The same partials, each with a phase of its own (what a touch leaves behind on a
    // linear string: its modes ring on at their frequencies, their phases moved).
    const std::vector<double> drifted = note(samples, 60, true);
    double difference = 0.0, energy = 0.0;
    for (std::size_t n = 0; n < samples; ++n) {
        difference += (drifted[n] - clean[n]) * (drifted[n] - clean[n]);
        energy += clean[n] * clean[n];
    }
    EXPECT_GT(difference / energy, 0.5);  // the waveforms differ as much as the note itself
    const Listener listener(kRate, samples, kF0);
    // What is left is the interference of neighbouring partials within one band, read in frames
    // that hold them 5 bins apart: below -6 dB however the phases fall.
    EXPECT_LT(listener.added_level(drifted, clean).level_db, -6.0);
    EXPECT_EQ(listener.added_level(clean, clean).level_db, -std::numeric_limits<double>::infinity());
}

// Above the note's partials (up to 5.9 kHz) the click's energy adds to the note's; under them
// it would interfere with them, a term linear in the click.
TEST(Listener, AClickTenDecibelsStrongerReadsTenDecibelsHigher) {
    const std::size_t samples = static_cast<std::size_t>(0.3 * kRate);
    const std::vector<double> clean = note(samples);
    const Listener listener(kRate, samples, kF0);
    const Listener::Clean heard = listener.hear_clean(clean);
    double last = -std::numeric_limits<double>::infinity();
    for (double rms : {1e-5, 1e-4, 1e-3, 1e-2}) {
        const double level = listener.added_level(plus(clean, click(samples, 0.1, rms, 7000.0, 12000.0)), heard).level_db;
        if (std::isfinite(last)) {
            EXPECT_NEAR(level - last, 20.0, 1.0) << rms;  // x10 in amplitude: +20 dB
        }
        last = level;
    }
    // Scaling the clean note and its click together changes nothing above the threshold in quiet.
    const double level = listener.added_level(plus(clean, click(samples, 0.1, 1e-3, 7000.0, 12000.0)), heard).level_db;
    std::vector<double> louder = plus(clean, click(samples, 0.1, 1e-3, 7000.0, 12000.0));
    for (double& v : louder) v *= 3.0;
    EXPECT_NEAR(listener.added_level(louder, heard, 9.0).level_db, level, 1e-9);
}

TEST(Listener, AClickUnderAStrongPartialIsMaskedMoreThanWhereTheNoteIsQuiet) {
    const std::size_t samples = static_cast<std::size_t>(0.3 * kRate);
    const std::vector<double> clean = note(samples, 12);  // nothing above 1.2 kHz
    const Listener listener(kRate, samples, kF0);
    const double under = listener.added_level(plus(clean, click(samples, 0.1, 1e-3, 200.0, 400.0)), clean).level_db;
    const double above = listener.added_level(plus(clean, click(samples, 0.1, 1e-3, 3000.0, 3200.0)), clean).level_db;
    EXPECT_GT(above, under + 20.0) << under << " " << above;
}

TEST(Listener, AQuieterPlaybackHearsLessOfAClickWhereOnlyTheThresholdInQuietMasksIt) {
    const std::size_t samples = static_cast<std::size_t>(0.3 * kRate);
    const std::vector<double> clean = note(samples, 12);
    const std::vector<double> played = plus(clean, click(samples, 0.1, 1e-4, 14000.0, 16000.0));
    ListeningSettings loud, quiet;
    loud.level_db_spl = 95.0;
    quiet.level_db_spl = 65.0;
    const double a = Listener(kRate, samples, kF0, loud).added_level(played, clean).level_db;
    const double b = Listener(kRate, samples, kF0, quiet).added_level(played, clean).level_db;
    EXPECT_NEAR(a - b, 30.0, 1.0);
}

// The loaded pickup: a lightly loaded one resonates at 1/(2 pi sqrt(L C)) with a peak of
// its quality factor Q, 1/Q = 1/(R_load sqrt(C/L)) + R sqrt(C/L); the figures of cases/rigs/ lie in the ranges their source gives.
TEST(ListeningRig, ThePickupResonatesWhereItsCircuitSays) {
    RigSettings light;
    light.pickup = {3.0, 10.0, 650e-12, 1e7};
    const ListeningRig rig(light);
    const double f0 = 1.0 / (2.0 * std::numbers::pi * std::sqrt(3.0 * 650e-12));
    EXPECT_NEAR(rig.resonance_hz() / f0, 1.0, 1e-3);
    // 1/Q: the parallel load's and the coil's own losses add.
    const double q = 1.0 / (1.0 / (1e7 * std::sqrt(650e-12 / 3.0)) + 10.0 / std::sqrt(3.0 / 650e-12));
    EXPECT_NEAR(rig.resonance_peak_db(), 20.0 * std::log10(q), 0.01);
    EXPECT_NEAR(std::abs(rig.pickup_response(1.0)), 1.0, 1e-6);
    // Far above it the response falls as 1/f^2 (12 dB an octave).
    EXPECT_NEAR(20.0 * std::log10(std::abs(rig.pickup_response(80e3)) / std::abs(rig.pickup_response(160e3))), 12.0, 0.1);
    const ListeningRig usual{RigSettings{}};
    EXPECT_GT(usual.resonance_hz(), 2000.0);  // Lemme: 2 to 5 kHz, 0 to 12 dB, with a cable
    EXPECT_LT(usual.resonance_hz(), 5000.0);
    EXPECT_GT(usual.resonance_peak_db(), 0.0);
    EXPECT_LT(usual.resonance_peak_db(), 12.0);
    RigSettings bad;
    bad.pickup.inductance_h = 0.0;
    EXPECT_THROW(ListeningRig{bad}, std::exception);
}

// A click at 7-7.4 kHz over a low note (partials to 300 Hz: nothing masks the click but the
// threshold in quiet). The rig weighs the click's energy by its power gain across the click's
// components, and the playback level (set by the note's loudest frame) by its gain across the
// note's partials: the level falls by the ratio of the two.
TEST(ListeningRig, AClickIsHeardLessByWhatTheRigsResponsePredicts) {
    const std::size_t samples = static_cast<std::size_t>(0.3 * kRate);
    const std::vector<double> clean = note(samples, 3);
    const std::vector<double> played = plus(clean, click(samples, 0.1, 1e-4, 7000.0, 7400.0));
    ListeningSettings through;
    through.rig = RigSettings{};
    const double full = Listener(kRate, samples, kF0).added_level(played, clean).level_db;
    const double rigged = Listener(kRate, samples, kF0, through).added_level(played, clean).level_db;
    const ListeningRig rig(*through.rig);
    double click_gain = 0.0, click_weight = 0.0;
    for (double f = 7000.0; f <= 7400.0; f += 50.0) {
        click_gain += f * f * rig.power_gain(f);
        click_weight += f * f;
    }
    double note_gain = 0.0, note_weight = 0.0;
    for (int j = 1; j <= 3; ++j) {
        const double f = j * kF0, e = f * f / std::pow(j, 4);  // velocity, amplitude 1/j^2
        note_gain += e * rig.power_gain(f);
        note_weight += e;
    }
    const double predicted = 10.0 * std::log10((click_gain / click_weight) / (note_gain / note_weight));
    EXPECT_LT(predicted, -15.0);  // a 4 kHz cabinet, fourth order: far down at 7 kHz
    EXPECT_NEAR(rigged - full, predicted, 0.5) << full << " -> " << rigged;
}

TEST(Listener, BadSettingsAreRefused) {
    EXPECT_THROW(Listener(100.0, 1000, kF0), std::exception);
    EXPECT_THROW(Listener(kRate, 1000, 0.0), std::exception);
}

}  // namespace
}  // namespace fretbuzz
