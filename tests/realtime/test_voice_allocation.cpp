// How the real-time instruments share their voices (realtime/VoiceAllocation.hpp): the voice
// that gives way beyond the polyphony, and the string a note is played on.
#include <gtest/gtest.h>

#include <array>
#include <optional>
#include <vector>

#include "fretbuzz/realtime/VoiceAllocation.hpp"

namespace fretbuzz {
namespace {

std::optional<std::size_t> giving_way(const std::vector<VoiceTurn>& voices, std::size_t wanted, std::size_t polyphony) {
    return voice_giving_way(voices, wanted, polyphony, [](const VoiceTurn& t) { return t; });
}

TEST(VoiceAllocation, TheVoiceReleasedLongestAgoGivesWayElseTheOneHeldLongest) {
    // Held at counts 3 and 5, released at 4 and 2 (ringing out), one silent.
    std::vector<VoiceTurn> voices = {{true, false, 3, -1}, {true, false, -1, 4}, {true, false, 5, -1},
                                     {true, false, -1, 2}, {false, false, -1, -1}};
    EXPECT_EQ(giving_way(voices, 4, 4), std::optional<std::size_t>(3));  // released at 2, before 4
    EXPECT_EQ(giving_way(voices, 4, 5), std::nullopt);                   // room for a fifth
    voices[3].fading = true;                                             // already giving way
    EXPECT_EQ(giving_way(voices, 4, 3), std::optional<std::size_t>(1));
    voices[1].sounding = false;  // rung out: only held voices left, the one held longest goes
    EXPECT_EQ(giving_way(voices, 4, 2), std::optional<std::size_t>(0));
    // The voice asked for does not count itself, nor give way to itself.
    EXPECT_EQ(giving_way(voices, 0, 2), std::nullopt);
    EXPECT_EQ(giving_way(voices, 0, 1), std::optional<std::size_t>(2));
}

TEST(VoiceAllocation, ANoteIsPlayedOnTheHighestStringThatReachesIt) {
    // A guitar in standard tuning, 21 frets on each string but the first with 5.
    const std::array<int, 6> open = {40, 45, 50, 55, 59, 64};
    const std::array<int, 6> frets = {5, 21, 21, 21, 21, 21};
    EXPECT_EQ(string_for_note(open, frets, 40), 0);   // the open low E
    EXPECT_EQ(string_for_note(open, frets, 45), 1);   // A2: the open A, though the low E's fret 5 plays it too
    EXPECT_EQ(string_for_note(open, frets, 44), 0);   // G#2: only the low E reaches it (fret 4)
    EXPECT_EQ(string_for_note(open, frets, 64), 5);   // the open high E
    EXPECT_EQ(string_for_note(open, frets, 85), 5);   // high E fret 21
    EXPECT_EQ(string_for_note(open, frets, 86), -1);  // beyond every string's frets
    EXPECT_EQ(string_for_note(open, frets, 39), -1);  // below the lowest open string
    const std::array<int, 2> sitar = {50, 62};
    const std::array<int, 2> none = {0, 0};           // unfretted: open notes only
    EXPECT_EQ(string_for_note(sitar, none, 62), 1);
    EXPECT_EQ(string_for_note(sitar, none, 51), -1);
}

}  // namespace
}  // namespace fretbuzz
