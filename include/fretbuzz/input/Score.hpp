#pragma once
// What a string is asked to play: notes (time, fret, duration, velocity, pluck point) and how
// the performance is rendered (tail, pluck strength and width, pickup), read from a TOML note
// list here or from a standard MIDI file (MidiFile.hpp). Both readers check every value, and
// the performance's length (the last note's end and the tail) against kMaxScoreSeconds before
// anything is rendered.
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
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace fretbuzz {

struct ScoreNote {
    double time_s = 0.0;
    double duration_s = 1.0;
    int fret = 0;
    double velocity = 0.8;
    double position = 0.8;
};

struct Score {
    std::vector<ScoreNote> notes;
    double tail_s = 1.0;
    double strength_m_per_s = 1.5;
    double width_m = 0.01;
    double pickup = -1.0;               // < 0: the case's observation point
    std::vector<std::string> warnings;  // e.g. MIDI notes out of the string's range, skipped

    // When the last note ends (s); the rendered length is end_s() + tail_s.
    double end_s() const;
};

inline constexpr int kMaxFret = 24;
// A performance (its last note's end and the tail) lasts at most an hour.
inline constexpr double kMaxScoreSeconds = 3600.0;

// InputError naming the key (and note) at fault.
Score parse_note_list(std::string_view toml_text, const std::string& source_name);
// Reads a regular file of at most kMaxCaseFileBytes (TextFile.hpp), then parses it.
Score load_note_list(const std::filesystem::path& path);
// InputError (starting with `source`) unless every note starts and ends within
// kMaxScoreSeconds, tail included.
void check_score_length(const Score& score, const std::string& source);

}  // namespace fretbuzz
