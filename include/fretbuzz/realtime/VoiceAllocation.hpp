#pragma once
// How the real-time instruments share their voices among the notes played, as a host plays
// them (the LV2 plugins, fretbuzz play): which voice gives way when a note would sound beyond
// the polyphony, and which string of a fretted instrument plays a note. Nothing here
// allocates: it runs inside an audio callback.
#include <cstddef>
#include <optional>
#include <span>

namespace fretbuzz {

// Where a voice stands in the order of note-ons and note-offs (counted together).
struct VoiceTurn {
    bool sounding = false;  // held, ringing out or fading
    bool fading = false;    // already giving way: it no longer counts
    long started = -1;      // the count at its note-on while held; -1: not held
    long released = -1;     // the count at its note-off while it rings out
};

// The voice to fade out so that voice `wanted` can sound with at most `polyphony` sounding:
// the one released longest ago, or else the one held longest; none while there is room.
template <typename Voices, typename TurnOf>
std::optional<std::size_t> voice_giving_way(const Voices& voices, std::size_t wanted, std::size_t polyphony,
                                            TurnOf turn_of) {
    const auto older = [](const VoiceTurn& a, const VoiceTurn& b) {
        if ((a.started < 0) != (b.started < 0)) return a.started < 0;  // released before held
        return a.started < 0 ? a.released < b.released : a.started < b.started;
    };
    std::size_t sounding = 0, k = 0;
    std::optional<std::size_t> oldest;
    VoiceTurn oldest_turn;
    for (const auto& voice : voices) {
        const VoiceTurn turn = turn_of(voice);
        if (turn.sounding && !turn.fading && k != wanted) {
            ++sounding;
            if (!oldest || older(turn, oldest_turn)) {
                oldest = k;
                oldest_turn = turn;
            }
        }
        ++k;
    }
    return sounding >= polyphony ? oldest : std::nullopt;
}

// The string that plays MIDI note `note` on an instrument whose strings' open notes and fret
// counts are given: the highest open note at most `note` whose frets reach it; -1 if none.
int string_for_note(std::span<const int> open_notes, std::span<const int> fret_counts, int note);

}  // namespace fretbuzz
