#pragma once
// A performance played offline through the real-time engine: a Score (notes read by
// input/Score.hpp or input/MidiFile.hpp) rendered block by block exactly as a host would
// (`fretbuzz play`). One string, one Engine: a note on fret k puts the engine's finger down
// behind fret k (moving it from the previous note's fret) and plucks the part from the fret to
// the bridge; a note-off mutes the string and lifts the finger; fret 0 plays the open string.
// A case without frets plays fret 0 only.
#include <cstddef>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/input/Score.hpp"
#include "fretbuzz/realtime/Engine.hpp"

namespace fretbuzz {

// The rendered audio is held whole (the file is peak-normalised): at most this many samples,
// an hour at 48 kHz (1.4 GB as doubles); at a higher rate the hour shrinks in proportion.
inline constexpr long kMaxRenderedSamples = 3600L * 48000L;

// The MIDI note nearest the open string's first mode.
int open_string_note(const Case& c);

struct RenderedPerformance {
    std::vector<double> audio;  // at the host rate
    struct Voice {
        int frets;
        int oversampling;
        std::size_t modes;
        long resets;
        long clamped;
        double latency_samples;  // the decimation filter's group delay (host samples)
        const char* rate_choice;  // why the oversampling is what it is (Engine::rate_choice)
    };
    Voice voice;
    double wall_seconds = 0.0;
};

// The number of host samples the score renders to (its last note's end and the tail);
// InputError if it exceeds kMaxRenderedSamples, checked before anything is allocated.
long rendered_samples(const Score& score, double host_rate_hz);

// Renders through one Engine (the string), in blocks of at most `block` samples. InputError
// for a note beyond the case's frets, or a score longer than rendered_samples allows.
RenderedPerformance render_performance(const Case& open, const Score& score, const EngineOptions& options,
                                       std::size_t block = 256);

}  // namespace fretbuzz
