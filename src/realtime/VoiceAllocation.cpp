#include "fretbuzz/realtime/VoiceAllocation.hpp"

namespace fretbuzz {

int string_for_note(std::span<const int> open_notes, std::span<const int> fret_counts, int note) {
    int best = -1;
    for (std::size_t s = 0; s < open_notes.size() && s < fret_counts.size(); ++s) {
        const int fret = note - open_notes[s];
        if (fret < 0 || fret > fret_counts[s]) continue;
        if (best < 0 || open_notes[s] > open_notes[static_cast<std::size_t>(best)]) best = static_cast<int>(s);
    }
    return best;
}

}  // namespace fretbuzz
