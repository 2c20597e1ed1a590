#pragma once
// A performance played offline through the real-time engine: notes (time, fret, velocity,
// duration) from a small TOML note list or a standard MIDI file, rendered block by block
// exactly as a host would (`fretbuzz play`). One string, one Engine: a note on fret k puts the
// engine's finger down behind fret k (moving it from the previous note's fret) and plucks the
// part from the fret to the bridge; a note-off mutes the string and lifts the finger; fret 0
// plays the open string. A case without frets plays fret 0 only.
//
// Note list:
//   [play]                 # all optional
//   tail = 1.0             # s rendered after the last note ends
//   strength = 1.5         # pluck velocity (m/s) at velocity 1
//   width = 0.01           # pluck width (m)
//   pickup = 0.9           # fraction of the string's length from the case's x = 0 end (default: the case's point)
//   [[note]]
//   time = 0.0             # s
//   fret = 0               # 0 (open) to 24, and at most the case's number of frets
//   duration = 1.0         # s, then the string is muted
//   velocity = 0.8         # (0, 1]
//   position = 0.8         # pluck point, fraction of the sounding length (fret to bridge) from the fret
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/realtime/Engine.hpp"

namespace fretbuzz {

struct PlayedNote {
    double time_s = 0.0;
    double duration_s = 1.0;
    int fret = 0;
    double velocity = 0.8;
    double position = 0.8;
};

struct Performance {
    std::vector<PlayedNote> notes;
    double tail_s = 1.0;
    double strength_m_per_s = 1.5;
    double width_m = 0.01;
    double pickup = -1.0;  // < 0: the case's observation point
    std::vector<std::string> warnings;  // e.g. MIDI notes out of the string's range, skipped
};

inline constexpr int kMaxFret = 24;

// InputError naming the key (and note) at fault.
Performance parse_note_list(std::string_view toml_text, const std::string& source_name);
Performance load_note_list(const std::filesystem::path& path);
// Note-on/off pairs of every track and channel; fret = MIDI note - open_note; notes outside
// frets 0 to max_fret are skipped (with a warning). InputError if the file cannot be read as MIDI.
Performance load_midi(const std::filesystem::path& path, int open_note, int max_fret = kMaxFret);
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

// Renders through one Engine (the string), in blocks of at most `block` samples. InputError
// for a note beyond the case's frets.
RenderedPerformance render_performance(const Case& open, const Performance& p, const EngineOptions& options,
                                       std::size_t block = 256);

}  // namespace fretbuzz
