#pragma once
// Standard MIDI files (format 0 or 1, ticks per quarter note) as notes for one string: the
// note-on/note-off pairs of every track and channel, fret = MIDI note - the open string's
// note. The file is someone else's input: it is read only if it is a regular file of at most
// kMaxMidiFileBytes, its chunks and event stream are checked byte by byte (chunk lengths,
// delta times, status bytes, running status, meta and sysex lengths, End of Track), and only
// then are its notes and tempo changes handed to libsmf, which turns ticks into seconds.
// Anything wrong is an InputError naming the file, the track and the byte.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include "fretbuzz/input/Score.hpp"

namespace fretbuzz {

// A minute of dense playing is a few kB; a large orchestral file a few hundred.
inline constexpr std::size_t kMaxMidiFileBytes = 1u << 20;

// Notes outside frets 0 to max_fret are skipped (with a warning); a note still sounding at
// the end of the file ends there. InputError if the bytes are not a well-formed standard
// MIDI file, hold no note the string can play, or last longer than kMaxScoreSeconds.
Score parse_midi(std::string_view bytes, const std::string& source_name, int open_note, int max_fret = kMaxFret);
Score load_midi(const std::filesystem::path& path, int open_note, int max_fret = kMaxFret);

}  // namespace fretbuzz
