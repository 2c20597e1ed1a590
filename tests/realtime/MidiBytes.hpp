#pragma once
// Standard MIDI files built byte by byte for the tests: well-formed ones, and ones broken on
// purpose (a chunk length past the end, running status after a sysex, no End of Track...).
#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fretbuzz::testing {

using Bytes = std::vector<unsigned char>;

inline void append_big_endian(Bytes& out, std::uint32_t v, int count) {
    for (int k = count - 1; k >= 0; --k) out.push_back(static_cast<unsigned char>(v >> (8 * k)));
}

// A variable-length number: 7 bits a byte, most significant first, the high bit set on all
// but the last.
inline Bytes midi_number(std::uint32_t v) {
    Bytes out;
    for (int shift = 21; shift > 0; shift -= 7)
        if ((v >> shift) != 0) out.push_back(static_cast<unsigned char>(0x80 | ((v >> shift) & 0x7F)));
    out.push_back(static_cast<unsigned char>(v & 0x7F));
    return out;
}

// A chunk: its 4-letter id, its length (the events' size unless given) and the events.
inline Bytes midi_chunk(const char* id, const Bytes& body, std::uint32_t length) {
    Bytes out(id, id + 4);
    append_big_endian(out, length, 4);
    out.insert(out.end(), body.begin(), body.end());
    return out;
}
inline Bytes midi_chunk(const char* id, const Bytes& body) {
    return midi_chunk(id, body, static_cast<std::uint32_t>(body.size()));
}

// A file of the given tracks (their event bytes, End of Track included by the caller).
inline Bytes midi_file(const std::vector<Bytes>& tracks, int format = 1, int division = 480) {
    Bytes out = midi_chunk("MThd", {});
    out.resize(8);
    out[7] = 6;
    append_big_endian(out, static_cast<std::uint32_t>(format), 2);
    append_big_endian(out, static_cast<std::uint32_t>(tracks.size()), 2);
    append_big_endian(out, static_cast<std::uint32_t>(division), 2);
    for (const Bytes& t : tracks) {
        const Bytes chunk = midi_chunk("MTrk", t);
        out.insert(out.end(), chunk.begin(), chunk.end());
    }
    return out;
}

inline const Bytes kEndOfTrack = {0x00, 0xFF, 0x2F, 0x00};

// Events of one track: each note (key, on tick, off tick, velocity) as note-on and note-off,
// then End of Track.
inline Bytes midi_notes(const std::vector<std::array<std::uint32_t, 4>>& notes) {
    struct Event {
        std::uint32_t tick;
        unsigned char status, key, velocity;
    };
    std::vector<Event> events;
    for (const auto& n : notes) {
        events.push_back({n[1], 0x90, static_cast<unsigned char>(n[0]), static_cast<unsigned char>(n[3])});
        events.push_back({n[2], 0x80, static_cast<unsigned char>(n[0]), 0});
    }
    std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.tick < b.tick; });
    Bytes track;
    std::uint32_t last = 0;
    for (const Event& e : events) {
        const Bytes delta = midi_number(e.tick - last);
        last = e.tick;
        track.insert(track.end(), delta.begin(), delta.end());
        track.insert(track.end(), {e.status, e.key, e.velocity});
    }
    track.insert(track.end(), kEndOfTrack.begin(), kEndOfTrack.end());
    return track;
}

inline void write_bytes(const std::filesystem::path& path, const Bytes& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace fretbuzz::testing
