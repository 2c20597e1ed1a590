// `fretbuzz play`: a note list and the same notes as a MIDI file render the same audio through
// the engine; bad input (a malformed MIDI file, a performance too long, a file that is not a
// regular one, an --out that cannot be written) is refused with exit status 2, naming what is
// wrong, before any work and without touching --out; the take is written whole or not at all.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "../TestSupport.hpp"
#include "MidiBytes.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/MidiFile.hpp"
#include "fretbuzz/input/Score.hpp"
#include "fretbuzz/realtime/Performance.hpp"

namespace fretbuzz {
namespace {

namespace fs = std::filesystem;
using testing::Bytes;
using testing::CommandResult;

// The program under test: FRETBUZZ_TEST_CLI, if set, runs these checks against another build.
std::string program() {
    const char* other = std::getenv("FRETBUZZ_TEST_CLI");
    return other != nullptr ? other : FRETBUZZ_CLI;
}

// `timeout`: a program that blocks (on a FIFO) is stopped (exit status 124), not waited for.
CommandResult play(const std::string& arguments) { return testing::run_shell("timeout 60 " + program() + " play " + arguments); }

std::string read_all(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Refused as bad input: exit status 2, the fault named.
void expect_refused(const CommandResult& r, const std::string& fault) {
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(contains(r.output, fault)) << "'" << fault << "' is not named in: " << r.output;
}

// Files in `dir` other than those named.
std::vector<std::string> others(const fs::path& dir, const std::vector<std::string>& known) {
    std::vector<std::string> found;
    for (const auto& e : fs::directory_iterator(dir)) {
        const std::string name = e.path().filename().string();
        if (std::find(known.begin(), known.end(), name) == known.end()) found.push_back(name);
    }
    return found;
}

TEST(Play, MidiAndNoteListRenderTheSameAudio) {
    const testing::ScratchDir scratch("play-midi");
    const fs::path& dir = scratch.path();
    const Case c = load_case("bass-pluck");
    const auto open = static_cast<std::uint32_t>(open_string_note(c));
    // 480 ticks per quarter at the default 120 bpm: 1 tick = 1/960 s.
    testing::write_bytes(dir / "riff.mid", testing::midi_file({testing::midi_notes({{open + 3, 0, 480, 127}, {open, 480, 960, 64}})}, 0));
    Score midi = load_midi(dir / "riff.mid", static_cast<int>(open));
    ASSERT_EQ(midi.notes.size(), 2u);
    EXPECT_EQ(midi.notes[0].fret, 3);
    EXPECT_NEAR(midi.notes[1].time_s, 0.5, 1e-9);
    EXPECT_NEAR(midi.notes[1].duration_s, 0.5, 1e-9);
    const Score list = parse_note_list(R"(
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

    const CommandResult r = play("bass-pluck --midi " + (dir / "riff.mid").string() + " --out " + (dir / "riff.wav").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // 1 s of notes and the default 1 s tail, 24-bit mono, after a 44-byte header.
    EXPECT_EQ(fs::file_size(dir / "riff.wav"), 44u + 3u * 2 * 48000);
    EXPECT_EQ(others(dir, {"riff.mid", "riff.wav"}), std::vector<std::string>{});
}

TEST(Play, RefusesBadInputWithoutWritingAnything) {
    const testing::ScratchDir scratch("play-bad");
    const fs::path& dir = scratch.path();
    std::ofstream(dir / "bad.toml") << "[[note]]\ntime = 0\nfret = 30\n";
    CommandResult r = play("sitar --notes " + (dir / "bad.toml").string() + " --out " + (dir / "x.wav").string());
    expect_refused(r, "note[0].fret");
    std::ofstream(dir / "typo.toml") << "[[note]]\ntime = 0\nvelocty = 1\n";
    r = play("sitar --notes " + (dir / "typo.toml").string() + " --out " + (dir / "x.wav").string());
    expect_refused(r, "velocty");
    // The sitar case has a bridge and no frets: only its open string can be played.
    std::ofstream(dir / "fretted.toml") << "[[note]]\ntime = 0.5\nfret = 2\n";
    r = play("sitar --notes " + (dir / "fretted.toml").string() + " --out " + (dir / "x.wav").string());
    expect_refused(r, "fret = 2");
    r = play("sitar --out " + (dir / "x.wav").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_FALSE(fs::exists(dir / "x.wav"));
    EXPECT_EQ(others(dir, {"bad.toml", "typo.toml", "fretted.toml"}), std::vector<std::string>{});
    EXPECT_THROW(parse_note_list("[[note]]\nvelocity = 2\n", "inline"), InputError);
}

// A malformed MIDI file is refused with exit status 2, naming the file and what is wrong
// (libsmf, handed such a file, fails an assertion: SIGABRT, exit status 134).
TEST(Play, MalformedMidiIsRefusedNamingTheFault) {
    const testing::ScratchDir scratch("play-bad-midi");
    const fs::path& dir = scratch.path();
    const Bytes note = {0x00, 0x90, 40, 100, 0x60, 0x80, 40, 0};
    Bytes with_end = note;
    with_end.insert(with_end.end(), testing::kEndOfTrack.begin(), testing::kEndOfTrack.end());
    struct Broken {
        const char* name;
        Bytes bytes;
        const char* fault;
    };
    // Running status right after a sysex: data bytes where a status byte is due.
    Bytes sysex_running = {0x00, 0xF0, 0x03, 0x7E, 0x09, 0xF7, 0x00, 40, 100};
    sysex_running.insert(sysex_running.end(), with_end.begin(), with_end.end());
    Bytes huge = testing::midi_file({with_end});
    huge[18] = 0x7F;  // the MTrk length's bytes: 0x7FFFFFFF
    huge[19] = huge[20] = huge[21] = 0xFF;
    Bytes truncated = testing::midi_file({with_end});
    truncated.resize(truncated.size() - 6);
    const std::vector<Broken> broken = {
        {"huge-track.mid", huge, "claims 2147483647 bytes"},
        {"sysex-running.mid", testing::midi_file({sysex_running}), "where a status byte is due"},
        {"no-end.mid", testing::midi_file({note}), "no End of Track"},
        {"truncated.mid", truncated, "claims"},
        {"long-delta.mid", testing::midi_file({{0xFF, 0xFF, 0xFF, 0xFF, 0x7F, 0x90, 40, 100, 0x00, 0xFF, 0x2F, 0x00}}),
         "longer than 4 bytes"},
        {"short-meta.mid", testing::midi_file({{0x00, 0xFF, 0x51, 0x05, 0x07, 0xA1, 0x20}}), "runs past the track's end"},
        {"bad-tempo.mid", testing::midi_file({{0x00, 0xFF, 0x51, 0x02, 0x07, 0xA1, 0x00, 0xFF, 0x2F, 0x00}}),
         "tempo change with 2 data bytes"},
        {"format2.mid", testing::midi_file({with_end}, 2), "format 2"},
        {"smpte.mid", testing::midi_file({with_end}, 1, 0xE728), "SMPTE"},
        {"missing-track.mid", testing::midi_file({with_end, with_end}), "declares 3 tracks"},
        {"not-midi.mid", Bytes{'R', 'I', 'F', 'F', 0, 0, 0, 4, 'W', 'A', 'V', 'E', 0, 0}, "MThd"},
    };
    for (Broken b : broken) {
        SCOPED_TRACE(b.name);
        if (std::string(b.name) == "missing-track.mid") b.bytes[11] = 3;  // 3 tracks declared, 2 present
        testing::write_bytes(dir / b.name, b.bytes);
        const CommandResult r = play("bass-pluck --midi " + (dir / b.name).string() + " --out " + (dir / "x.wav").string());
        expect_refused(r, b.fault);
        EXPECT_TRUE(contains(r.output, (dir / b.name).string())) << r.output;
        EXPECT_THROW(parse_midi(std::string(b.bytes.begin(), b.bytes.end()), b.name, 40), InputError);
    }
    EXPECT_FALSE(fs::exists(dir / "x.wav"));
}

// Well-formed files that libsmf alone misreads: a meta event longer than 127 bytes (libsmf
// reads its length as one byte), a sysex of 200 bytes (a two-byte length), running status,
// several tracks and a tempo change; the times come out of the tempo map.
TEST(Play, ReadsWellFormedMidiWithLongMetaEventsAndTempoChanges) {
    constexpr unsigned char open = 40;
    Bytes conductor = {0x00, 0xFF, 0x03, 0x81, 0x10};  // a track name of 144 bytes
    conductor.insert(conductor.end(), 144, 'a');
    // Tempo: 1 s per quarter note from tick 480 (0.5 s at the default 120 bpm) on.
    conductor.insert(conductor.end(), {0x83, 0x60, 0xFF, 0x51, 0x03, 0x0F, 0x42, 0x40});
    conductor.insert(conductor.end(), testing::kEndOfTrack.begin(), testing::kEndOfTrack.end());
    Bytes notes = {0x00, 0xF0, 0x81, 0x48};  // a sysex of 200 bytes
    notes.insert(notes.end(), 199, 0x11);
    notes.push_back(0xF7);
    // Fret 2 at tick 0, then (running status) fret 5 at tick 480 ending at 960 (1.5 s).
    notes.insert(notes.end(), {0x00, 0x90, open + 2, 90, 0x83, 0x60, open + 2, 0, 0x00, open + 5, 127, 0x83, 0x60, open + 5, 0});
    notes.insert(notes.end(), testing::kEndOfTrack.begin(), testing::kEndOfTrack.end());
    const Bytes file = testing::midi_file({conductor, notes});
    const Score s = parse_midi(std::string(file.begin(), file.end()), "long-meta.mid", open);
    ASSERT_EQ(s.notes.size(), 2u);
    EXPECT_EQ(s.notes[0].fret, 2);
    EXPECT_NEAR(s.notes[0].time_s, 0.0, 1e-12);
    EXPECT_NEAR(s.notes[0].duration_s, 0.5, 1e-12);
    EXPECT_NEAR(s.notes[0].velocity, 90.0 / 127.0, 1e-12);
    EXPECT_EQ(s.notes[1].fret, 5);
    EXPECT_NEAR(s.notes[1].time_s, 0.5, 1e-12);
    EXPECT_NEAR(s.notes[1].duration_s, 1.0, 1e-12);
    // Tracks are merged in time order, whichever comes first in the file: a tempo change in the
    // last track times the notes of the first, and a track that starts later (here by 55 ticks
    // of 1/960 s) ends the same notes of one that starts at once.
    const Bytes early = testing::midi_notes({{40, 0, 960, 100}, {42, 960, 1920, 100}});
    const Bytes tempo = {0x83, 0x60, 0xFF, 0x51, 0x03, 0x0F, 0x42, 0x40, 0x00, 0xFF, 0x2F, 0x00};
    Bytes late = testing::midi_notes({{40, 0, 960, 100}});
    late[0] = 55;
    const Bytes merged = testing::midi_file({early, tempo, late});
    const Score m = parse_midi(std::string(merged.begin(), merged.end()), "merged.mid", open);
    ASSERT_EQ(m.notes.size(), 3u);
    EXPECT_NEAR(m.notes[0].time_s, 0.0, 1e-12);
    EXPECT_NEAR(m.notes[0].duration_s, 55.0 / 960.0, 1e-12);  // ended by the later track's note-on
    EXPECT_NEAR(m.notes[1].time_s, 55.0 / 960.0, 1e-12);
    EXPECT_NEAR(m.notes[1].time_s + m.notes[1].duration_s, 1.5, 1e-12);  // tick 960: 0.5 s + 1 s
    EXPECT_NEAR(m.notes[2].time_s, 1.5, 1e-12);
    EXPECT_NEAR(m.notes[2].duration_s, 2.0, 1e-12);
    // The program plays it whole: 1.5 s of notes and the 1 s tail, nothing dropped or logged.
    const testing::ScratchDir scratch("play-long-meta");
    testing::write_bytes(scratch.path() / "long-meta.mid", file);
    const CommandResult r = play("bass-pluck --open-note 40 --bits 16 --midi " + (scratch.path() / "long-meta.mid").string() +
                                 " --out " + (scratch.path() / "x.wav").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_FALSE(contains(r.output, "CRITICAL")) << r.output;
    EXPECT_EQ(fs::file_size(scratch.path() / "x.wav"), 44u + 2u * 120000);
}

// A performance lasts at most an hour (tail included), checked before anything is rendered
// or allocated; the rendered length is bounded in samples too (an hour at 48 kHz).
TEST(Play, PerformanceLengthIsLimitedUpFront) {
    const testing::ScratchDir scratch("play-long");
    const fs::path& dir = scratch.path();
    const auto open = static_cast<std::uint32_t>(open_string_note(load_case("bass-pluck")));
    // 480 ticks per quarter, 1 s per quarter: tick t is at t / 480 s.
    const auto at_seconds = [&](double seconds, const char* name) {
        Bytes track = {0x00, 0xFF, 0x51, 0x03, 0x0F, 0x42, 0x40};
        const auto on = static_cast<std::uint32_t>(seconds * 480.0);
        const Bytes notes = testing::midi_notes({{open, on, on + 240, 100}});
        track.insert(track.end(), notes.begin(), notes.end());
        testing::write_bytes(dir / name, testing::midi_file({track}));
        return (dir / name).string();
    };
    for (const double seconds : {4000.0, 30000.0}) {
        const auto start = std::chrono::steady_clock::now();
        const CommandResult r = play("bass-pluck --midi " + at_seconds(seconds, "late.mid") + " --out " + (dir / "x.wav").string());
        const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        expect_refused(r, "at most 3600 s");
        EXPECT_LT(took, 20.0);
    }
    // Within the hour at 48 kHz, but 2 x 3000 s of samples at 96 kHz: refused before rendering.
    const CommandResult r = play("bass-pluck --midi " + at_seconds(3000.0, "at3000.mid") + " --rate 96000 --out " +
                                 (dir / "x.wav").string());
    expect_refused(r, "172800000");
    // A note list's notes each start within the hour; their ends and the tail count too.
    std::ofstream(dir / "late.toml") << "[play]\ntail = 600\n[[note]]\ntime = 3500\nduration = 50\n";
    const CommandResult list = play("bass-pluck --notes " + (dir / "late.toml").string() + " --out " + (dir / "x.wav").string());
    expect_refused(list, "note[0]");
    EXPECT_FALSE(fs::exists(dir / "x.wav"));
}

// --notes and --midi read regular files only, their size checked before they are read: a
// FIFO would block for ever, /dev/zero never ends.
TEST(Play, ReadsOnlyRegularFilesOfBoundedSize) {
    const testing::ScratchDir scratch("play-files");
    const fs::path& dir = scratch.path();
    ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
    const std::string out = " --out " + (dir / "x.wav").string();
    for (const std::string option : {"--notes ", "--midi "}) {
        for (const std::string& source : {std::string("/dev/zero"), (dir / "fifo").string()}) {
            const CommandResult r = play("bass-pluck " + option + source + out);
            expect_refused(r, "not a regular file");
        }
    }
    std::ofstream(dir / "big.toml") << std::string(5u << 20, '#');
    CommandResult r = play("bass-pluck --notes " + (dir / "big.toml").string() + out);
    expect_refused(r, "larger than 4 MiB");
    std::ofstream(dir / "big.mid") << std::string(2u << 20, '\0');
    r = play("bass-pluck --midi " + (dir / "big.mid").string() + out);
    expect_refused(r, "larger than 1 MiB");
    EXPECT_FALSE(fs::exists(dir / "x.wav"));
}

// --out is checked before any work (a folder, a missing folder, a FIFO, an extension that
// names no format the writer writes: exit status 2); the extension names the format; the take
// is written beside --out and renamed into place once whole, so an earlier take survives a
// failed write (a full disk, here the file-size limit) untouched, with nothing left beside it.
TEST(Play, WritesItsOutputWholeOrNotAtAll) {
    const testing::ScratchDir scratch("play-out");
    const fs::path& dir = scratch.path();
    std::ofstream(dir / "one.toml") << "[play]\ntail = 0.2\n[[note]]\ntime = 0\nduration = 0.3\n";
    const std::string notes = "bass-pluck --notes " + (dir / "one.toml").string();
    // 30 s of audio, a minute's work: a refusal before the work comes in a fraction of that.
    std::ofstream(dir / "slow.toml") << "[play]\ntail = 0\n[[note]]\ntime = 0\nduration = 30\n";
    fs::create_directory(dir / "folder.wav");
    ASSERT_EQ(::mkfifo((dir / "pipe.wav").c_str(), 0600), 0);
    struct Refused {
        std::string out;
        const char* fault;
    };
    for (const Refused& bad : std::vector<Refused>{{(dir / "folder.wav").string(), "is a folder"},
                                                   {(dir / "missing" / "x.wav").string(), "does not exist"},
                                                   {(dir / "pipe.wav").string(), "not a regular file"},
                                                   {(dir / "x.mp3").string(), ".wav"},
                                                   {(dir / "x").string(), ".ogg"}}) {
        const auto start = std::chrono::steady_clock::now();
        const CommandResult r = play("bass-pluck --notes " + (dir / "slow.toml").string() + " --out " + bad.out);
        expect_refused(r, bad.fault);
        EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0) << bad.out;
    }
    EXPECT_EQ(others(dir, {"one.toml", "slow.toml", "folder.wav", "pipe.wav"}), std::vector<std::string>{});

    // The extension names the format, in any case.
    ASSERT_EQ(play(notes + " --out " + (dir / "take.OGG").string()).exit_code, 0);
    EXPECT_EQ(read_all(dir / "take.OGG").substr(0, 4), "OggS");
    ASSERT_EQ(play(notes + " --out " + (dir / "take.Flac").string()).exit_code, 0);
    EXPECT_EQ(read_all(dir / "take.Flac").substr(0, 4), "fLaC");
    ASSERT_EQ(play(notes + " --out " + (dir / "take.wav").string()).exit_code, 0);
    const std::string earlier = read_all(dir / "take.wav");
    EXPECT_EQ(earlier.substr(0, 4), "RIFF");
    ASSERT_EQ(::chmod((dir / "take.wav").c_str(), 0640), 0);

    // A longer take that cannot be written whole: the file-size limit (ulimit -f, in 512-byte
    // blocks) stops it at 64 kB, as a full disk would.
    std::ofstream(dir / "long.toml") << "[play]\ntail = 1\n[[note]]\ntime = 0\nduration = 1\n";
    const CommandResult r = testing::run_shell("trap '' XFSZ; ulimit -f 128; exec " + program() + " play bass-pluck --notes " +
                                  (dir / "long.toml").string() + " --out " + (dir / "take.wav").string());
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_EQ(read_all(dir / "take.wav"), earlier) << "the earlier take was changed";
    struct stat info {};
    ASSERT_EQ(::stat((dir / "take.wav").c_str(), &info), 0);
    EXPECT_EQ(info.st_mode & 0777, 0640u);
    EXPECT_EQ(others(dir, {"one.toml", "slow.toml", "long.toml", "folder.wav", "pipe.wav", "take.OGG", "take.Flac",
                           "take.wav"}),
              std::vector<std::string>{});
}

// A take is written wherever the system can write it: deep in the file tree (libsndfile alone
// refuses a path over about a kilobyte, after the work); a path whose temporary file beside it
// would be too long for the system, whatever the process id, is refused before the work.
TEST(Play, WritesATakeAnywhereTheSystemCan) {
    const testing::ScratchDir scratch("play-deep");
    std::string deep = scratch.str();
    while (deep.size() < 3000) deep += "/" + std::string(200, 'd');
    fs::create_directories(deep);
    std::ofstream(scratch.path() / "one.toml") << "[play]\ntail = 0.2\n[[note]]\ntime = 0\nduration = 0.3\n";
    const std::string notes = "bass-pluck --notes " + (scratch.path() / "one.toml").string();
    const fs::path take = deep + "/take.flac";
    const CommandResult r = play(notes + " --out " + take.string());
    ASSERT_EQ(r.exit_code, 0) << r.output.substr(r.output.size() - std::min<std::size_t>(r.output.size(), 300));
    EXPECT_EQ(read_all(take).substr(0, 4), "fLaC");
    EXPECT_EQ(others(deep, {"take.flac"}), std::vector<std::string>{});

    while (deep.size() < 4000) deep += "/" + std::string(std::min<std::size_t>(200, 4000 - deep.size()), 'd');
    fs::create_directories(deep);
    // 4080 bytes: under PATH_MAX, and so could be ".ttt.tmp-PID-N.flac" beside it with a
    // short process id, but not with every one.
    const std::string too_long = deep + "/" + std::string(4080 - deep.size() - 1 - 5, 't') + ".flac";
    ASSERT_EQ(too_long.size(), 4080u);
    const auto start = std::chrono::steady_clock::now();
    expect_refused(play(notes + " --out " + too_long), "--out");
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
    EXPECT_EQ(others(deep, {}), std::vector<std::string>{});
}

}  // namespace
}  // namespace fretbuzz
