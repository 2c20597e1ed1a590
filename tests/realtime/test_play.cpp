// `fretbuzz play`: a note list and the same notes as a MIDI file render the same audio through
// the engine; bad input is refused with exit status 2 and no output file.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../TestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/realtime/Performance.hpp"

namespace fretbuzz {
namespace {

// A type-0 standard MIDI file, 480 ticks per quarter at the default 120 bpm (1 tick = 1/960 s):
// each note (key, on tick, off tick, velocity).
void write_midi(const std::filesystem::path& path, const std::vector<std::array<int, 4>>& notes) {
    struct Event {
        int tick;
        unsigned char status, key, velocity;
    };
    std::vector<Event> events;
    for (const auto& n : notes) {
        events.push_back({n[1], 0x90, static_cast<unsigned char>(n[0]), static_cast<unsigned char>(n[3])});
        events.push_back({n[2], 0x80, static_cast<unsigned char>(n[0]), 0});
    }
    std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.tick < b.tick; });
    std::vector<unsigned char> track;
    int last = 0;
    for (const Event& e : events) {
        int delta = e.tick - last;
        last = e.tick;
        unsigned char vlq[4];
        int count = 0;
        vlq[count++] = static_cast<unsigned char>(delta & 0x7F);
        while ((delta >>= 7) > 0) vlq[count++] = static_cast<unsigned char>(0x80 | (delta & 0x7F));
        while (count > 0) track.push_back(vlq[--count]);
        track.insert(track.end(), {e.status, e.key, e.velocity});
    }
    track.insert(track.end(), {0x00, 0xFF, 0x2F, 0x00});
    std::ofstream out(path, std::ios::binary);
    const unsigned char header[] = {'M', 'T', 'h', 'd', 0, 0, 0, 6, 0, 0, 0, 1, 0x01, 0xE0, 'M', 'T', 'r', 'k'};
    out.write(reinterpret_cast<const char*>(header), sizeof header);
    const auto size = static_cast<unsigned>(track.size());
    const unsigned char length[] = {static_cast<unsigned char>(size >> 24), static_cast<unsigned char>(size >> 16),
                                    static_cast<unsigned char>(size >> 8), static_cast<unsigned char>(size)};
    out.write(reinterpret_cast<const char*>(length), 4);
    out.write(reinterpret_cast<const char*>(track.data()), static_cast<std::streamsize>(track.size()));
}

TEST(Play, MidiAndNoteListRenderTheSameAudio) {
    const testing::ScratchDir scratch("play-midi");
    const std::filesystem::path& dir = scratch.path();
    const Case c = load_case("bass-pluck");
    const int open = open_string_note(c);
    write_midi(dir / "riff.mid", {{open + 3, 0, 480, 127}, {open, 480, 960, 64}});
    Performance midi = load_midi(dir / "riff.mid", open);
    ASSERT_EQ(midi.notes.size(), 2u);
    EXPECT_EQ(midi.notes[0].fret, 3);
    EXPECT_NEAR(midi.notes[1].time_s, 0.5, 1e-9);
    EXPECT_NEAR(midi.notes[1].duration_s, 0.5, 1e-9);
    const Performance list = parse_note_list(R"(
[play]
tail = 1.0
[[note]]
time = 0.0
fret = 3
duration = 0.5
velocity = 1.0
[[note]]
time = 0.5
fret = 0
duration = 0.5
velocity = 0.50393700787401574
)",
                                             "list");
    EngineOptions o;
    const auto a = render_performance(c, midi, o);
    const auto b = render_performance(c, list, o);
    ASSERT_EQ(a.audio.size(), b.audio.size());
    double diff = 0.0, norm = 0.0;
    for (std::size_t i = 0; i < a.audio.size(); ++i) {
        diff += (a.audio[i] - b.audio[i]) * (a.audio[i] - b.audio[i]);
        norm += b.audio[i] * b.audio[i];
    }
    EXPECT_GT(norm, 0.0);
    EXPECT_LT(std::sqrt(diff / norm), 1e-6);
    // One string: the finger went down on fret 3, moved off for the open note, the guard never fired.
    EXPECT_EQ(a.voice.frets, 20);
    EXPECT_EQ(a.voice.resets, 0);

    const testing::CommandResult r = testing::run_cli("play bass-pluck --midi " + (dir / "riff.mid").string() + " --out " +
                                    (dir / "riff.wav").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // 1 s of notes and the default 1 s tail, 24-bit mono, after a 44-byte header.
    EXPECT_EQ(std::filesystem::file_size(dir / "riff.wav"), 44u + 3u * 2 * 48000);
}

TEST(Play, RefusesBadInputWithoutWritingAnything) {
    const testing::ScratchDir scratch("play-bad");
    const std::filesystem::path& dir = scratch.path();
    std::ofstream(dir / "bad.toml") << "[[note]]\ntime = 0\nfret = 30\n";
    testing::CommandResult r = testing::run_cli("play sitar --notes " + (dir / "bad.toml").string() + " --out " + (dir / "x.wav").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("note[0].fret"), std::string::npos) << r.output;
    std::ofstream(dir / "typo.toml") << "[[note]]\ntime = 0\nvelocty = 1\n";
    r = testing::run_cli("play sitar --notes " + (dir / "typo.toml").string() + " --out " + (dir / "x.wav").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("velocty"), std::string::npos) << r.output;
    // The sitar case has a bridge and no frets: only its open string can be played.
    std::ofstream(dir / "fretted.toml") << "[[note]]\ntime = 0.5\nfret = 2\n";
    r = testing::run_cli("play sitar --notes " + (dir / "fretted.toml").string() + " --out " + (dir / "x.wav").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("fret = 2"), std::string::npos) << r.output;
    r = testing::run_cli("play sitar --out " + (dir / "x.wav").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "x.wav"));
    EXPECT_THROW(parse_note_list("[[note]]\nvelocity = 2\n", "inline"), InputError);
}

}  // namespace
}  // namespace fretbuzz
