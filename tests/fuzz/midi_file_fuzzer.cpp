// libFuzzer target: any bytes as a standard MIDI file. The reader may refuse them
// (InputError), never crash, hang, abort inside libsmf or throw anything else; what it
// accepts is a playable score: notes within the hour, on the string's frets.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/MidiFile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    try {
        const fretbuzz::Score score = fretbuzz::parse_midi(bytes, "fuzz.mid", 40, 24);
        if (score.notes.empty()) __builtin_trap();
        for (const fretbuzz::ScoreNote& n : score.notes)
            if (!(n.time_s >= 0.0 && n.duration_s >= 0.0 && n.time_s + n.duration_s <= fretbuzz::kMaxScoreSeconds) ||
                n.fret < 0 || n.fret > 24 || !(n.velocity > 0.0 && n.velocity <= 1.0))
                __builtin_trap();
    } catch (const fretbuzz::InputError&) {
    }
    return 0;
}
