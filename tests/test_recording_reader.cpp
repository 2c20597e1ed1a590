// The recording reader of `fretbuzz estimate` on someone else's files: metadata chunks never
// reach libsndfile (whatever they hold, the samples read are the same), the chunks it is
// given are checked first, and a recording cut short is read up to where it ends.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/analysis/Recording.hpp"

namespace fretbuzz {
namespace {

std::string u32(std::uint32_t v, bool big_endian = false) {
    std::string out(4, '\0');
    for (std::size_t i = 0; i < 4; ++i) out[big_endian ? 3 - i : i] = static_cast<char>((v >> (8 * i)) & 0xffu);
    return out;
}

std::string u16(std::uint16_t v, bool big_endian = false) {
    std::string out(2, '\0');
    out[big_endian ? 1 : 0] = static_cast<char>(v & 0xffu);
    out[big_endian ? 0 : 1] = static_cast<char>(v >> 8);
    return out;
}

std::string chunk(const std::string& tag, const std::string& body, bool big_endian = false) {
    std::string c = tag + u32(static_cast<std::uint32_t>(body.size()), big_endian) + body;
    if (body.size() % 2 == 1) c.push_back('\0');
    return c;
}

// 16-bit samples of a short decaying ramp, as a WAV's or an AIFF's sound data.
std::vector<std::int16_t> samples() {
    std::vector<std::int16_t> s;
    for (int n = 0; n < 200; ++n) s.push_back(static_cast<std::int16_t>((n % 23 - 11) * (2000 - 9 * n)));
    return s;
}

std::string pcm(bool big_endian) {
    std::string out;
    for (std::int16_t v : samples()) out += u16(static_cast<std::uint16_t>(v), big_endian);
    return out;
}

std::string fmt_chunk(bool big_endian = false) {
    const bool b = big_endian;
    return chunk("fmt ", u16(1, b) + u16(1, b) + u32(8000, b) + u32(16000, b) + u16(2, b) + u16(16, b), b);
}

// A mono 8 kHz WAV (RIFF, or RIFX where big_endian) with `before` and `after` around its data.
std::string wav(const std::string& before = "", const std::string& after = "", bool big_endian = false) {
    const std::string body = "WAVE" + fmt_chunk(big_endian) + before + chunk("data", pcm(big_endian), big_endian) + after;
    return (big_endian ? "RIFX" : "RIFF") + u32(static_cast<std::uint32_t>(body.size()), big_endian) + body;
}

// The same as an AIFF file (COMM with 8000 Hz as an 80-bit float).
std::string aiff(const std::string& before = "") {
    const std::string rate80("\x40\x0b\xfa\x00\x00\x00\x00\x00\x00\x00", 10);
    const std::string comm = chunk("COMM", u16(1, true) + u32(200, true) + u16(16, true) + rate80, true);
    const std::string ssnd = chunk("SSND", u32(0, true) + u32(0, true) + pcm(true), true);
    const std::string body = "AIFF" + comm + before + ssnd;
    return "FORM" + u32(static_cast<std::uint32_t>(body.size()), true) + body;
}

// The same as RF64: its ds64 chunk gives the data's length, and the data chunk's own size
// field holds `data_size` (0xffffffff by the format; a damaged file may hold anything).
// `data_length`, where given, is the ds64 chunk's claim instead; `table` follows its sizes.
std::string rf64(std::uint32_t data_size, const std::string& after = "", std::uint64_t data_length = 0,
                 const std::string& table = "") {
    const std::string audio = pcm(false);
    if (data_length == 0) data_length = audio.size();
    const std::string sizes = u32(0) + u32(0) + u32(static_cast<std::uint32_t>(data_length & 0xffffffffu)) +
                              u32(static_cast<std::uint32_t>(data_length >> 32)) +
                              u32(static_cast<std::uint32_t>(audio.size() / 2)) + u32(0) +
                              u32(static_cast<std::uint32_t>(table.size())) + table;
    return "RF64" + u32(0xffffffffu) + "WAVE" + chunk("ds64", sizes) + fmt_chunk() + "data" + u32(data_size) + audio + after;
}

std::vector<double> expected() {
    std::vector<double> out;
    for (std::int16_t v : samples()) out.push_back(v / 32768.0);
    return out;
}

// A LIST whose INFO entry claims 2^32 - 9 bytes: libsndfile 1.2 jumps back 8 bytes and reads
// the same entry again, for ever (found by the recording fuzzer).
std::string endless_list() { return chunk("LIST", "INFO" + std::string("ABCD") + u32(0xfffffff7u) + "abcdefgh"); }
// A cue chunk shorter than the one cue point it counts: libsndfile would jump back into it.
std::string short_cue() { return chunk("cue ", u32(1)); }

TEST(RecordingReader, MetadataChunksNeverReachTheDecoder) {
    const std::vector<double> want = expected();
    const std::vector<std::pair<std::string, std::string>> files = {
        {"plain", wav()},
        {"LIST before the data", wav(endless_list())},
        {"LIST after the data", wav("", endless_list())},
        {"short cue", wav(short_cue(), short_cue())},
        {"smpl, acid and bext of junk", wav(chunk("smpl", std::string(7, '\xff')) + chunk("acid", "x") + chunk("bext", ""))},
        {"RIFX with a LIST", wav(chunk("LIST", "INFO" + std::string("ABCD") + u32(0xfffffff7u, true) + "abcdefgh", true), "", true)},
        {"RF64 with a LIST after the data", rf64(0xffffffffu, endless_list())},
        {"RF64 whose data chunk claims 2^32 - 188 bytes", rf64(0xffffff44u, endless_list())},
        // libsndfile would seek backwards by 2^64 minus this, into chunks it parses again.
        {"RF64 whose ds64 claims 0x9aabb7bcbbb2a423 bytes of data", rf64(0xffffffffu, "", 0x9aabb7bcbbb2a423u)},
        // libsndfile takes a ds64 chunk to end where the next 4 bytes read "fmt ", and parses
        // the rest of it as chunks.
        {"RF64 whose ds64 chunk holds chunks", rf64(0xffffffffu, "", 0, "junk" + fmt_chunk() + endless_list())},
        {"AIFF", aiff()},
        {"AIFF with MARK and INST of junk", aiff(chunk("MARK", u16(0xffff, true), true) + chunk("INST", "", true))},
    };
    for (const auto& [name, bytes] : files) {
        const Recording r = decode_recording(bytes, name);
        EXPECT_EQ(r.rate_hz, 8000.0) << name;
        EXPECT_EQ(r.samples, want) << name;
    }
}

TEST(RecordingReader, ARecordingCutShortIsReadToItsEnd) {
    std::string bytes = wav();
    bytes.resize(bytes.size() - 100);  // the last 50 samples lost
    const Recording r = decode_recording(bytes, "cut.wav");
    std::vector<double> want = expected();
    want.resize(want.size() - 50);
    EXPECT_EQ(r.samples, want);
}

TEST(RecordingReader, ChunksLibsndfileReadsAreCheckedFirst) {
    const auto refusal = [](const std::string& bytes) {
        try {
            decode_recording(bytes, "bad.wav");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    // A format chunk too short to hold a format.
    std::string body = "WAVE" + chunk("fmt ", std::string(8, '\1')) + chunk("data", pcm(false));
    EXPECT_NE(refusal("RIFF" + u32(static_cast<std::uint32_t>(body.size())) + body)
                  .find("bad.wav: its 'fmt ' chunk at byte 12 holds 8 bytes, fewer than the 16 it must"),
              std::string::npos);
    // An AIFF COMM chunk of a size its parser does not read whole.
    const std::string rate80("\x40\x0b\xfa\x00\x00\x00\x00\x00\x00\x00", 10);
    body = "AIFF" + chunk("COMM", u16(1, true) + u32(200, true) + u16(16, true) + rate80 + "xy", true) +
           chunk("SSND", u32(0, true) + u32(0, true) + pcm(true), true);
    EXPECT_NE(refusal("FORM" + u32(static_cast<std::uint32_t>(body.size()), true) + body)
                  .find("its 'COMM' chunk at byte 12 holds 20 bytes: a COMM chunk holds 18, 22, or 24 to 280"),
              std::string::npos);
    // Metadata past the end of the file is refused as damage, before anything is decoded.
    const std::string list = "LIST" + u32(4000) + "INFO";
    body = "WAVE" + fmt_chunk() + list;
    EXPECT_NE(refusal("RIFF" + u32(static_cast<std::uint32_t>(body.size())) + body)
                  .find("its 'LIST' chunk at byte 36 claims 4000 bytes, past the end of the file"),
              std::string::npos);
}

// An AIFF's rate is an 80-bit float; libsndfile gives an int, 0x4000000 for any past 2^258.
TEST(RecordingReader, AnAiffWhoseRateIsInfiniteIsReportedAsInfinite) {
    const std::string inf80("\x7f\xff\x80\x00\x00\x00\x00\x00\x00\x00", 10);
    const std::string body = "AIFF" + chunk("COMM", u16(1, true) + u32(200, true) + u16(16, true) + inf80, true) +
                             chunk("SSND", u32(0, true) + u32(0, true) + pcm(true), true);
    try {
        decode_recording("FORM" + u32(static_cast<std::uint32_t>(body.size()), true) + body, "inf.aiff");
        ADD_FAILURE() << "an infinite rate was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("inf.aiff: sample rate inf Hz"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace fretbuzz
